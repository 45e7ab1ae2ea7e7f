"""
The Earth's conical shadow with its penumbra: the fraction of the Sun's light a body receives.

Montenbruck and Gill, Satellite Orbits (Springer, 2000), section 3.4.2. Seen
from the body at r (m, world, from the planet's centre), the Sun's disc has the
angular radius a = asin(R_sun / |r_sun - r|), the planet's b = asin(R / |r|),
and their centres are c apart. Both are taken as flat discs of uniform
brightness (no limb darkening, no atmosphere) and the fraction of the Sun's
disc left uncovered is

    c >= a + b              1                      (full sunlight)
    c <= b - a              0                      (umbra)
    c <= a - b              1 - b^2 / a^2          (annular: the planet inside the Sun's disc)
    otherwise               1 - A / (pi a^2)       (penumbra),
    x = (c^2 + a^2 - b^2) / (2 c),  y = sqrt(a^2 - x^2),
    A = a^2 acos(x / a) + b^2 acos((c - x) / b) - c y   (the discs' overlap).

The two angles are computed as atan2(y, x) and atan2(y, c - x), the same angles
(x^2 + y^2 = a^2 and (c - x)^2 + y^2 = b^2): for a low orbit (c - x) / b is within
1e-5 of 1, where acos loses seven digits (a last-place change of its argument moved
the fraction by 6e-9), and atan2 loses none.

For a low orbit the penumbra lasts seconds at each shadow crossing (8.2 s on a
400 km circular orbit with the Sun in its plane, longer where the orbit crosses
the shadow's edge at a slant), which the cylindrical shadow of
:func:`.sun.in_shadow` (1 or 0) cannot show. The sensors see it through
:meth:`..sensors.base.Sky.light` with ``shadow_model`` conical.
"""

import math

import numpy as np

from .sun import in_shadow

#: The Sun's nominal radius (m; IAU 2015 Resolution B3).
R_SUN = 6.957e8


def conical_shadow_fraction(r, sun_position, planet_radius, sun_radius=R_SUN):
    """
    Return the fraction of the Sun's disc seen from ``r`` (0 = umbra, 1 = full sunlight).

    ``r`` (m, world) is the body's position from the planet's centre,
    ``sun_position`` (m, world) the Sun's, ``planet_radius`` and ``sun_radius``
    (m) their radii. The Montenbruck-Gill flat-disc overlap (module docstring).
    Refuses (ValueError) a body inside the planet or the Sun.
    """
    rx, ry, rz = r
    dx, dy, dz = sun_position[0] - rx, sun_position[1] - ry, sun_position[2] - rz
    body = math.sqrt(rx * rx + ry * ry + rz * rz)
    sun = math.sqrt(dx * dx + dy * dy + dz * dz)
    if not (body > planet_radius and sun > sun_radius):
        raise ValueError(f'a shadow needs a body outside the planet and the Sun: '
                         f'|r| = {body:g} m, the Sun {sun:g} m away')
    towards = rx * dx + ry * dy + rz * dz
    if towards >= 0.0 and planet_radius < 0.9999 * body and sun_radius < 0.01 * sun:
        # the Sun 90 deg or more from the planet's centre: their discs (together under
        # 89 deg across) cannot meet; the same answer as below, without the inverse sines
        return 1.0
    a = math.asin(sun_radius / sun)
    b = math.asin(planet_radius / body)
    cos_c = -towards / (body * sun)
    c = math.acos(max(-1.0, min(1.0, cos_c)))
    if c >= a + b:
        return 1.0
    if c <= b - a:
        return 0.0
    if c <= a - b:
        return 1.0 - (b * b) / (a * a)
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = math.sqrt(max(0.0, a * a - x * x))
    overlap = a * a * math.atan2(y, x) + b * b * math.atan2(y, c - x) - c * y
    return min(1.0, max(0.0, 1.0 - overlap / (math.pi * a * a)))


#: The Earth's shadow models: cylindrical (0 or 1), conical (with a penumbra).
SHADOW_MODELS = ('cylindrical', 'conical')


def sunlit_fraction(r, sun_position, planet_radius, model='cylindrical'):
    """
    Return the fraction of the Sun's light that reaches ``r`` (0 = umbra, 1 = full sunlight).

    ``r`` and ``sun_position`` (m, world, from the planet's centre), ``planet_radius``
    (m); ``model`` one of :data:`SHADOW_MODELS`: the cylinder of the planet's radius
    behind it (0 or 1, :func:`.sun.in_shadow`) or the cone with its penumbra
    (:func:`conical_shadow_fraction`).
    """
    if model == 'conical':
        return conical_shadow_fraction(r, sun_position, planet_radius)
    d = math.sqrt(sun_position[0] ** 2 + sun_position[1] ** 2 + sun_position[2] ** 2)
    sun = (sun_position[0] / d, sun_position[1] / d, sun_position[2] / d)
    return 0.0 if in_shadow(r, sun, planet_radius) else 1.0


def sunlit_fractions(r, sun_position, planet_radius, model='cylindrical'):
    """
    Return :func:`sunlit_fraction` at many places: ``r`` and ``sun_position`` (m, (N, 3)).

    The same formulas with numpy (an (N,) array); a body inside the planet or the Sun is
    refused as there (ValueError).
    """
    rx, ry, rz = r[:, 0], r[:, 1], r[:, 2]
    dx, dy, dz = sun_position[:, 0] - rx, sun_position[:, 1] - ry, sun_position[:, 2] - rz
    body2 = rx * rx + ry * ry + rz * rz
    sun = np.sqrt(dx * dx + dy * dy + dz * dz)
    if model != 'conical':
        d = np.sqrt(sun_position[:, 0] ** 2 + sun_position[:, 1] ** 2 + sun_position[:, 2] ** 2)
        along = (rx * (sun_position[:, 0] / d) + ry * (sun_position[:, 1] / d)
                 + rz * (sun_position[:, 2] / d))
        dark = (along < 0.0) & (body2 - along * along < planet_radius * planet_radius)
        return np.where(dark, 0.0, 1.0)
    body = np.sqrt(body2)
    if not (np.all(body > planet_radius) and np.all(sun > R_SUN)):
        raise ValueError('a shadow needs a body outside the planet and the Sun')
    a = np.arcsin(R_SUN / sun)
    b = np.arcsin(planet_radius / body)
    c = np.arccos(np.clip(-(rx * dx + ry * dy + rz * dz) / (body * sun), -1.0, 1.0))
    light = np.ones_like(c)
    edge = (c < a + b)
    light[edge & (c <= b - a)] = 0.0
    annular = edge & (c > b - a) & (c <= a - b)
    light[annular] = (1.0 - (b * b) / (a * a))[annular]
    part = edge & (c > b - a) & (c > a - b)
    if np.any(part):
        a, b, c = a[part], b[part], c[part]
        x = (c * c + a * a - b * b) / (2.0 * c)
        y = np.sqrt(np.maximum(0.0, a * a - x * x))
        overlap = a * a * np.arctan2(y, x) + b * b * np.arctan2(y, c - x) - c * y
        light[part] = np.clip(1.0 - overlap / (math.pi * a * a), 0.0, 1.0)
    return light
