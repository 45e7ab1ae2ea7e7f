"""
Estimates from sampled, possibly irregular, gappy or reordered data.

Inputs are arrays over samples: stamps ``t`` (s, header stamps, not arrival
times), omega (N, 3) rad/s body frame, q (N, 4) x-y-z-w body -> world,
torque (N, 3) N m body frame. :func:`sort_samples` orders the samples and
drops duplicated stamps; every estimator calls it, so arrival order does not
matter. Angles are unwrapped, so the sampling (and any gap) must resolve the
motion: |rate| * (largest step between samples) < pi.
"""

from dataclasses import dataclass
import math

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import CubicSpline

from .. import quaternions
from ..dynamics import equations


def sort_samples(t, *arrays):
    """Sort samples by stamp and keep the first of any duplicated stamp; returns (t, *arrays)."""
    t = np.asarray(t, dtype=float)
    order = np.argsort(t, kind='stable')
    t_sorted = t[order]
    keep = np.ones(t_sorted.shape, dtype=bool)
    keep[1:] = np.diff(t_sorted) > 0.0
    idx = order[keep]
    return (t[idx],) + tuple(np.asarray(a)[idx] for a in arrays)


@dataclass(frozen=True)
class RateEstimate:
    """A least-squares rate (rad/s) with its standard error, sample count and time span (s)."""

    rate: float
    stderr: float
    samples: int
    span: float


def angle_rate(t, angle):
    """
    Rate (rad/s) of an angle (rad) from unwrap + least-squares slope on centred stamps.

    On noisy, irregular samples this beats endpoint differences and FFT peaks
    (the fit uses every sample). Needs at least 3 samples.
    """
    t, angle = sort_samples(t, angle)
    if t.size < 3:
        raise ValueError('need at least 3 samples to estimate a rate')
    phi = np.unwrap(angle)
    tc = t - t.mean()
    design = np.stack([tc, np.ones_like(tc)], axis=1)
    coef, _, _, _ = np.linalg.lstsq(design, phi, rcond=None)
    resid = phi - design @ coef
    dof = max(t.size - 2, 1)
    stderr = math.sqrt(float(resid @ resid) / dof / float(tc @ tc))
    return RateEstimate(float(coef[0]), stderr, int(t.size), float(t[-1] - t[0]))


def _perp_axes(axis):
    return (axis + 1) % 3, (axis + 2) % 3


def body_precession_rate(t, omega, axis=2):
    """
    Rate (rad/s) at which omega's perpendicular part turns about body axis ``axis``.

    Positive for a right-handed turn about +axis; compare with
    theory.body_precession_rate (Shapiro's Omega).
    """
    w = np.asarray(omega, dtype=float)
    a, b = _perp_axes(axis)
    return angle_rate(t, np.arctan2(w[:, b], w[:, a]))


def basis_perpendicular(n):
    """Return unit vectors u, v with (u, v, n) right-handed."""
    n = np.asarray(n, dtype=float)
    n = n / np.linalg.norm(n)
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    u = np.cross(n, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u), n


def lab_precession_rate(t, q, omega, moments, axis=2):
    """
    Rate (rad/s) at which body axis ``axis`` precesses about the world angular momentum.

    The axis' world direction R(q) e_axis is projected on a fixed basis
    perpendicular to the mean of L_w = R(q) I omega; its azimuth is unwrapped
    and fitted. Positive for a right-handed turn about +L. ``moments`` are
    the principal moments in the body-axis order (kg m^2).
    """
    t, q, w = sort_samples(t, q, omega)
    return angle_rate(t, lab_precession_angle(q, w, moments, axis))


def lab_precession_angle(q, omega, moments, axis=2):
    """
    Azimuth (rad, wrapped) of body axis ``axis`` about the mean world angular momentum.

    R(q) e_axis projected on a fixed basis perpendicular to the mean of
    L_w = R(q) I omega, per sample (in the given order; unwrap it yourself).
    """
    lw = equations.angular_momentum_world(moments, q, omega)
    u, v, _ = basis_perpendicular(lw.mean(axis=0))
    e = quaternions.rotate(q, np.eye(3)[axis])
    return np.arctan2(e @ v, e @ u)


def mean_rate_over_periods(t, angle, period):
    """
    Mean rate (rad/s) of an angle over the largest whole number of ``period`` s that fits.

    Over a whole number n of periods a periodic modulation of the rate cancels
    (a least-squares slope over a window that is not would keep part of it);
    the angle n periods before the last sample comes from a cubic spline of
    the unwrapped samples. ``t`` sorted (s). Returns (rate, n); n >= 1 needed.
    """
    n = int(math.floor((t[-1] - t[0]) / period))
    if n < 1:
        raise ValueError('the samples span less than one period')
    phi = np.unwrap(angle)
    start = t[-1] - n * period
    return float((phi[-1] - CubicSpline(t, phi)(start)) / (n * period)), n


@dataclass(frozen=True)
class Conservation:
    """
    Drift since the first sample: largest relative |T - T0| / T0, ||L| - |L0|| / |L0|.

    ``direction`` is the largest angle (rad) between L_w and L_w0.
    """

    energy: float
    momentum: float
    direction: float


def vector_angle(a, b):
    """Angle (rad) between vectors (..., 3) by atan2(|a x b|, a . b)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def drift_series(moments, q, omega, q0, omega0):
    """
    Free-motion drift of each sample from the baseline (q0, omega0), principal frame.

    Returns arrays (N,): |T/T0 - 1|, ||L|/|L0| - 1| and the angle (rad)
    between L_w and L_w0 (zeros where the baseline has no energy or momentum).
    """
    e0 = float(equations.kinetic_energy(moments, omega0))
    l0 = equations.angular_momentum_world(moments, q0, omega0)
    lw = equations.angular_momentum_world(moments, q, omega)
    g0 = float(np.linalg.norm(l0))
    zeros = np.zeros(len(omega))
    energy = np.abs(equations.kinetic_energy(moments, omega) / e0 - 1.0) if e0 else zeros
    norm = np.abs(np.linalg.norm(lw, axis=-1) / g0 - 1.0) if g0 else zeros
    direction = vector_angle(lw, l0) if g0 else zeros
    return energy, norm, direction


def conservation(t, q, omega, moments):
    """Measure the drift of T, |L| and the direction of L_w from the first sample by stamp."""
    t, q, w = sort_samples(t, q, omega)
    energy, norm, direction = drift_series(moments, q, w, q[0], w[0])
    return Conservation(energy=float(energy.max()), momentum=float(norm.max()),
                        direction=float(direction.max()))


@dataclass(frozen=True)
class Balance:
    """
    Residuals of the balance laws under torque, largest over the samples.

    ``energy``: |T - T0 - W| / max(T0, |W|) with W = int omega . tau dt;
    ``momentum``: |L_w - L_w0 - H| / max(|L_w0|, |H|) with H = int R tau dt;
    ``work`` (J) and ``impulse`` (N m s, world) are the final integrals.
    """

    energy: float
    momentum: float
    work: float
    impulse: tuple


def balance(t, q, omega, torque, moments):
    """
    Work-energy and impulse-momentum residuals from sampled torque (trapezoid rule).

    Torque is body-frame. The trapezoid residual is O(dt^2) for smooth
    torque; a step in the torque between samples costs O(dt) once.
    """
    t, q, w, tau = sort_samples(t, q, omega, torque)
    energy = equations.kinetic_energy(moments, w)
    work = cumulative_trapezoid(np.sum(w * tau, axis=-1), t, initial=0.0)
    lw = equations.angular_momentum_world(moments, q, w)
    impulse = cumulative_trapezoid(quaternions.rotate(q, tau), t, axis=0, initial=0.0)
    e_scale = max(energy[0], float(np.max(np.abs(work))))
    l_scale = max(float(np.linalg.norm(lw[0])), float(np.max(np.linalg.norm(impulse, axis=-1))))
    e_res = np.abs(energy - energy[0] - work) / e_scale
    l_res = np.linalg.norm(lw - lw[0] - impulse, axis=-1) / l_scale
    return Balance(float(e_res.max()), float(l_res.max()), float(work[-1]),
                   tuple(float(c) for c in impulse[-1]))


def _crossings(t, x, direction):
    """
    Every zero crossing of x in stamp order: (times, brackets), s.

    ``times`` by linear interpolation between the two samples that bracket each crossing,
    ``brackets`` the time between those samples.
    """
    t, x = sort_samples(t, x)
    s = np.sign(x)
    i = np.nonzero(s[:-1] * s[1:] < 0)[0]
    if direction:
        i = i[np.sign(x[i + 1] - x[i]) == direction]
    return t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i]), t[i + 1] - t[i]


def crossing_times(t, x, direction=1, max_bracket=math.inf):
    """
    Stamps (s) where x crosses zero upward (direction 1), downward (-1) or either (0).

    Linear interpolation between the samples that bracket each crossing; a crossing
    whose samples are more than ``max_bracket`` s apart (a gap) is left out.
    """
    times, brackets = _crossings(t, x, direction)
    return times[brackets <= max_bracket]


def _crossing_spacing(t, x, direction, max_bracket):
    """
    Return the least-squares spacing (s) of consecutive zero crossings.

    Each crossing keeps its number in the sequence, and one bracketed by samples more than
    ``max_bracket`` s apart (default: 3 times the median interval between samples) is left
    out of the fit: linear interpolation across a gap misplaces it (a 0.9 s gap at one of
    the first two crossings of the tennis_racket preset, sampled at 100 Hz, put its period
    off by 2.6e-3). Raises ValueError with fewer than two fitted.
    """
    times, brackets = _crossings(t, x, direction)
    if max_bracket is None:
        steps = np.diff(sort_samples(t)[0])
        max_bracket = 3.0 * float(np.median(steps)) if steps.size else math.inf
    k = np.flatnonzero(brackets <= max_bracket)
    if times.size < 2:
        raise ValueError('fewer than two zero crossings: the window is too short')
    if k.size < 2:
        raise ValueError(f'{times.size} zero crossings, {times.size - k.size} of them across a '
                         'gap in the samples: fewer than two to fit')
    return float(np.polyfit(k, times[k], 1)[0])


def crossing_period(t, x, direction=1, max_bracket=None):
    """
    Period (s) of an oscillating signal from its zero crossings (least-squares on their times).

    With direction 0 (both crossings), returns the half-period spacing times 2. A crossing
    across a gap in the samples is left out (``max_bracket``: see :func:`_crossing_spacing`).
    Raises ValueError with fewer than two crossings.
    """
    spacing = _crossing_spacing(t, x, direction, max_bracket)
    return spacing * (2.0 if direction == 0 else 1.0)


def growth_rate(t, amplitude):
    """Exponential growth rate (1/s): least-squares slope of log|amplitude| against t."""
    t, a = sort_samples(t, amplitude)
    return float(np.polyfit(t - t.mean(), np.log(np.abs(a)), 1)[0])


def separatrix_growth_rate(t, omega, moments, fraction=0.1):
    """
    Growth rate (1/s) of departures from a spin about the intermediate axis.

    Near the saddle the perpendicular components (eps_1, eps_3) about the
    min- and max-moment axes obey eps_1' = -W a eps_3, eps_3' = -W b eps_1
    with a = (I3 - I2)/I1, b = (I2 - I1)/I3 (linearised (4.26)). The mode
    coordinates u = eps_3 -/+ sqrt(b/a) eps_1 grow and decay as exp(+/-lambda t)
    exactly; |eps| itself does not (the modes are not orthogonal, so it rises
    up to 15 % faster for a while). Each passage with |eps| < ``fraction``
    |omega| is fitted in log|u| for both signs; the larger slope is the
    growth rate, and the median over passages is returned. ``moments`` are
    the principal moments in body-axis order (kg m^2). ValueError when no
    passage has at least 5 samples.
    """
    t, w = sort_samples(t, omega)
    order = np.argsort(np.asarray(moments, dtype=float))
    i1, i2, i3 = (float(moments[k]) for k in order)
    e1, e3 = w[:, order[0]], w[:, order[2]]
    c = math.sqrt((i2 - i1) / i3 / ((i3 - i2) / i1))
    near = np.hypot(e1, e3) < fraction * np.linalg.norm(w, axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], near.astype(int), [0]])))
    slopes = []
    for start, stop in zip(edges[::2], edges[1::2]):
        if stop - start < 5:
            continue
        ts, a1, a3 = t[start:stop], e1[start:stop], e3[start:stop]
        slopes.append(max(np.polyfit(ts, np.log(np.abs(a3 + sign * c * a1)), 1)[0]
                          for sign in (1.0, -1.0)))
    if not slopes:
        raise ValueError('no passage near the intermediate axis in the window')
    return float(np.median(slopes))


def flip_interval(t, omega, axis, max_bracket=None):
    """
    Time (s) between sign changes of omega about the intermediate ``axis``.

    The least-squares spacing of the sign changes, those across a gap in the samples left
    out (``max_bracket``: see :func:`_crossing_spacing`).
    """
    try:
        return _crossing_spacing(t, np.asarray(omega, dtype=float)[:, axis], 0, max_bracket)
    except ValueError as err:
        raise ValueError(str(err).replace('zero crossings', 'flips')) from None
