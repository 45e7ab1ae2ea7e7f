"""
The momentum sphere: why spin about the intermediate axis is unstable (no ROS).

In the principal (body) frame a torque-free L keeps its length and the
energy, so it lies on the sphere |L| = L0 and on the energy ellipsoid
L . I^-1 . L = 2T at once, and moves along their intersection. With
I_a > I_b > I_c (major, intermediate, minor axes) the curves are, for
L0^2 / I_a <= 2T < L0^2 / I_b, pairs of loops around the major axis; for
L0^2 / I_b < 2T <= L0^2 / I_c, pairs of loops around the minor axis; and at
2T = L0^2 / I_b (L^2 = 2 T I_b) the separatrix: two great circles through
the intermediate axis, in the planes

    L_c = +- L_a sqrt((1/I_b - 1/I_a) / (1/I_c - 1/I_b)).

A spin near the major or minor axis stays on a small loop around it (stable);
one near the intermediate axis sits next to the separatrix and is carried
to the opposite end of that axis: the tennis-racket flip.

Curves are evaluated in closed form: around axis k with the others i, j and
azimuth phi, L_i = s cos phi, L_j = s sin phi, L_k = +- sqrt(L0^2 - s^2) with
s^2 = (2T - L0^2 / I_k) / (cos^2 phi / I_i + sin^2 phi / I_j - 1 / I_k), so
every point lies on both surfaces to round-off.
"""

import math

import numpy as np


def _axes(moments):
    """Return the indices (major a, intermediate b, minor c) of the principal moments."""
    order = np.argsort(np.asarray(moments, dtype=float))
    return int(order[2]), int(order[1]), int(order[0])


def loop(moments, l0, two_t, around, points=241):
    """
    Return the two loops of energy ``two_t`` (2T, J x 2) around principal axis ``around``.

    ``moments`` (principal, kg m^2), ``l0`` = |L| (kg m^2/s). Returns two (points, 3)
    arrays of L (principal frame), one at each end of the axis (closed: first = last).
    ValueError if no loop of that energy circles that axis.
    """
    inv = 1.0 / np.asarray(moments, dtype=float)
    k = int(around)
    i, j = [m for m in range(3) if m != k]
    phi = np.linspace(0.0, 2.0 * math.pi, points)
    denominator = np.cos(phi) ** 2 * inv[i] + np.sin(phi) ** 2 * inv[j] - inv[k]
    s2 = (two_t - l0 * l0 * inv[k]) / denominator
    if not np.all(np.isfinite(s2)) or np.any(s2 < -1e-12 * l0 * l0) or \
            np.any(s2 > l0 * l0 * (1 + 1e-12)):
        raise ValueError(f'no loop of 2T = {two_t:g} around axis {k + 1} for |L| = {l0:g}')
    s = np.sqrt(np.clip(s2, 0.0, l0 * l0))
    out = []
    for sign in (1.0, -1.0):
        curve = np.empty((points, 3))
        curve[:, i], curve[:, j] = s * np.cos(phi), s * np.sin(phi)
        curve[:, k] = sign * np.sqrt(np.clip(l0 * l0 - s * s, 0.0, None))
        out.append(curve)
    return out


def separatrix(moments, l0, points=361):
    """
    Return the two great circles of L^2 = 2 T I_b, through the intermediate axis.

    Returns two (points, 3) arrays of L (principal frame, closed). ValueError
    unless the three moments differ.
    """
    m = np.asarray(moments, dtype=float)
    a, b, c = _axes(m)
    if not (m[a] > m[b] > m[c]):
        raise ValueError('a separatrix needs three different moments')
    ratio = math.sqrt((1.0 / m[b] - 1.0 / m[a]) / (1.0 / m[c] - 1.0 / m[b]))
    theta = np.linspace(0.0, 2.0 * math.pi, points)
    out = []
    for sign in (1.0, -1.0):
        u = np.zeros(3)
        u[a], u[c] = 1.0, sign * ratio
        u /= np.linalg.norm(u)
        e_b = np.zeros(3)
        e_b[b] = 1.0
        out.append(l0 * (np.outer(np.cos(theta), e_b) + np.outer(np.sin(theta), u)))
    return out


def curve_family(moments, l0, per_family=6, points=241):
    """
    Return the intersection curves for a range of energies on the sphere |L| = ``l0``.

    Returns {'major': [...], 'minor': [...], 'separatrix': [...]}: loops around
    the major and the minor axis at ``per_family`` energies each, spread evenly
    between the axis and the separatrix, and the separatrix (empty for a body
    with equal moments, whose curves are all loops around its distinct axis).
    Each entry is a list of (points, 3) arrays of L, principal frame.
    """
    m = np.asarray(moments, dtype=float)
    a, b, c = _axes(m)
    l2 = l0 * l0
    out = {'major': [], 'minor': [], 'separatrix': []}
    fractions = (np.arange(per_family) + 0.5) / per_family
    if m[a] > m[b]:                   # loops around the major axis: 2T from L^2/I_a to L^2/I_b
        for f in fractions:
            out['major'] += loop(m, l0, l2 / m[a] + f * (l2 / m[b] - l2 / m[a]), a, points)
    if m[b] > m[c]:                   # around the minor axis: 2T from L^2/I_b to L^2/I_c
        for f in fractions:
            out['minor'] += loop(m, l0, l2 / m[c] + f * (l2 / m[b] - l2 / m[c]), c, points)
    if m[a] > m[b] > m[c]:
        out['separatrix'] = separatrix(m, l0, points)
    return out


def current_curve(moments, l_body, points=241):
    """
    Return the intersection curve the angular momentum ``l_body`` (principal frame) is on.

    The loop (around the major or the minor axis, the one at the end of the
    axis where L is) of its |L| and 2T, or the separatrix circle nearer to it
    when 2T is within 1e-12 of L^2 / I_b; (points, 3) kg m^2/s. None for a
    sphere (every L is at rest on it) or L = 0.
    """
    m = np.asarray(moments, dtype=float)
    L = np.asarray(l_body, dtype=float)
    l0 = float(np.linalg.norm(L))
    a, b, c = _axes(m)
    if l0 == 0.0 or m[a] == m[c]:
        return None
    two_t = float(np.sum(L * L / m))
    middle = l0 * l0 / m[b]
    if m[a] > m[b] > m[c] and abs(two_t - middle) <= 1e-12 * middle:
        circles = separatrix(m, l0, points)
        return min(circles, key=lambda circle: np.min(np.linalg.norm(circle - L, axis=1)))
    around = a if (m[a] > m[b] and two_t <= middle) else c
    loops = loop(m, l0, two_t, around, points)
    return loops[0] if L[around] >= 0.0 else loops[1]
