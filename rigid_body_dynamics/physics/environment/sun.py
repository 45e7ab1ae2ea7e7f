"""
The Sun's direction and the Earth's shadow (no ROS).

With an orbit the Sun is where the low-precision solar coordinates of the
Astronomical Almanac put it (about 0.01 deg, good 1950-2050), at the Julian
date of ``epoch`` plus the simulated time:

    d = JD - 2451545.0
    L = 280.460 + 0.9856474 d          (mean longitude, deg)
    g = 357.528 + 0.9856003 d          (mean anomaly, deg)
    lambda = L + 1.915 sin g + 0.020 sin 2g
    eps = 23.439 - 4e-7 d              (obliquity of the ecliptic, deg)
    s = (cos lambda, cos eps sin lambda, sin eps sin lambda)

a unit vector in the world frame (equatorial, z along the Earth's rotation
axis, x towards the equinox), seen from the Earth's centre: the parallax of a
low orbit (under 5e-5 rad) is neglected. The epoch is UTC, and TT is taken as
UTC (they differ by about 69 s, 0.0007 deg of the Sun's motion). The same
almanac gives the Sun's distance, which the conical shadow needs:

    R = 1.00014 - 0.01671 cos g - 0.00014 cos 2g   (au)

and without an epoch the fixed Sun is 1 au away.

The Earth's shadow is, with ``shadow_model`` cylindrical, a cylinder of the
planet's radius behind the Earth (no penumbra): a body at r is in eclipse when
r . s < 0 and its distance from the Earth-Sun line is under the radius. With
``shadow_model`` conical it is the Montenbruck-Gill cone with its penumbra
(:mod:`.shadow`).
"""

from datetime import datetime, timezone
import math

import numpy as np

#: The astronomical unit (m; IAU 2012 Resolution B2).
AU = 149597870700.0
#: The Julian date of the Unix epoch, 1970-01-01T00:00:00Z.
JD_UNIX = 2440587.5
#: The Julian date of J2000.0, 2000-01-01T12:00:00 (TT).
JD_J2000 = 2451545.0
_DAY = 86400.0


def julian_date(epoch):
    """
    Return the Julian date (days) of an ISO 8601 UTC time, e.g. '2026-03-20T12:00:00Z'.

    A time without an offset is taken as UTC; one with an offset is converted.
    Refuses (ValueError naming ``epoch``) what ``datetime.fromisoformat`` cannot read.
    (A Julian date near 2.46e6 resolves 40 us; :func:`unix_time` keeps the microseconds.)
    """
    return JD_UNIX + unix_time(epoch) / _DAY


def unix_time(epoch):
    """Return the Unix time (s, UTC) of an ISO 8601 UTC time; refusals as :func:`julian_date`."""
    text = str(epoch).strip()
    if text.endswith(('Z', 'z')):          # (fromisoformat reads Z from Python 3.11 only)
        text = text[:-1] + '+00:00'
    try:
        when = datetime.fromisoformat(text)
    except ValueError:
        raise ValueError(f'epoch must be an ISO 8601 UTC time such as 2026-03-20T12:00:00Z, '
                         f'got {epoch!r}') from None
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    return when.timestamp()


def sun_direction_almanac(jd):
    """
    Return the unit vector to the Sun (world frame) at Julian date ``jd`` (days, TT ~ UTC).

    The Astronomical Almanac's low-precision formula (module docstring), seen from
    the Earth's centre.
    """
    return sun_direction_days(jd - JD_J2000)


def sun_direction_days(d):
    """
    Return :func:`sun_direction_almanac` ``d`` days (TT ~ UTC) from J2000.0.

    The days themselves: a Julian date near 2.46e6 resolves 40 us, in which the Sun
    turns 8e-12 rad; the days from J2000.0 resolve 1e-12 days (0.1 us).
    """
    g = math.radians((357.528 + 0.9856003 * d) % 360.0)
    lam = math.radians((280.460 + 0.9856474 * d) % 360.0
                       + 1.915 * math.sin(g) + 0.020 * math.sin(2.0 * g))
    eps = math.radians(23.439 - 4e-7 * d)
    s = math.sin(lam)
    return (math.cos(lam), math.cos(eps) * s, math.sin(eps) * s)


def sun_distance_almanac(jd):
    """
    Return the distance (m) from the Earth's centre to the Sun's at Julian date ``jd`` (days).

    The Astronomical Almanac's low-precision formula (module docstring; about 1e-4 au).
    """
    g = math.radians((357.528 + 0.9856003 * (jd - JD_J2000)) % 360.0)
    return AU * (1.00014 - 0.01671 * math.cos(g) - 0.00014 * math.cos(2.0 * g))


def sun_position_almanac(jd):
    """
    Return the Sun's position (m, world frame, from the Earth's centre) at Julian date ``jd``.

    :func:`sun_direction_almanac` times :func:`sun_distance_almanac`, their mean
    anomaly computed once (the stages ask for it at every distinct time).
    """
    return sun_position_days(jd - JD_J2000)


def sun_position_days(d):
    """Return :func:`sun_position_almanac` ``d`` days from J2000.0 (the days as there)."""
    g = math.radians((357.528 + 0.9856003 * d) % 360.0)
    sin_g, cos_g = math.sin(g), math.cos(g)
    lam = math.radians((280.460 + 0.9856474 * d) % 360.0
                       + 1.915 * sin_g + 0.040 * sin_g * cos_g)
    eps = math.radians(23.439 - 4e-7 * d)
    r = AU * (1.00014 - 0.01671 * cos_g - 0.00014 * (2.0 * cos_g * cos_g - 1.0))
    s = r * math.sin(lam)
    return (r * math.cos(lam), math.cos(eps) * s, math.sin(eps) * s)


def sun_positions_days(d):
    """Return :func:`sun_position_days` at ``d`` (days from J2000.0, an array): (N, 3) m."""
    d = np.asarray(d, float)
    g = np.radians(np.remainder(357.528 + 0.9856003 * d, 360.0))
    sin_g, cos_g = np.sin(g), np.cos(g)
    lam = np.radians(np.remainder(280.460 + 0.9856474 * d, 360.0)
                     + 1.915 * sin_g + 0.040 * sin_g * cos_g)
    eps = np.radians(23.439 - 4e-7 * d)
    r = AU * (1.00014 - 0.01671 * cos_g - 0.00014 * (2.0 * cos_g * cos_g - 1.0))
    s = r * np.sin(lam)
    return np.column_stack((r * np.cos(lam), np.cos(eps) * s, np.sin(eps) * s))


class Sun:
    """
    The Sun's direction over simulated time: from ``epoch`` (ISO 8601 UTC), or ``fixed``.

    ``fixed`` (a world unit vector; normalised here) is used when there is no
    epoch (a body without an orbit). Refuses a zero or non-finite direction and
    an unreadable epoch, naming the parameter.
    """

    def __init__(self, epoch=None, fixed=(1.0, 0.0, 0.0)):
        self.epoch = epoch
        self.jd0 = None if epoch is None else julian_date(epoch)
        if self.jd0 is None:
            try:
                v = tuple(float(c) for c in fixed)
            except (TypeError, ValueError):
                v = ()
            n = math.sqrt(sum(c * c for c in v)) if len(v) == 3 else 0.0
            if not (math.isfinite(n) and n > 0.0):
                raise ValueError('sun_direction must be three finite numbers, not all zero, '
                                 f'got {fixed!r}')
            self.fixed = (v[0] / n, v[1] / n, v[2] / n)
        else:
            self.fixed = None
        self._interpolant = None
        #: days from J2000.0 at t = 0 (None without an epoch)
        self.days0 = None if self.jd0 is None else self.jd0 - JD_J2000

    def direction(self, t):
        """Return the unit vector to the Sun (world frame) at simulated time t (s)."""
        if self.fixed is not None:
            return self.fixed
        return sun_direction_days(self.days0 + t / _DAY)

    def position(self, t):
        """Return where the Sun is (m, world, from the Earth's centre) at time t (s)."""
        if self.fixed is not None:
            return (AU * self.fixed[0], AU * self.fixed[1], AU * self.fixed[2])
        return sun_position_days(self.days0 + t / _DAY)

    def positions(self, times):
        """
        Return where the Sun is (m, world, (N, 3)) at ``times`` (s, an array).

        The almanac's position (:func:`sun_positions_days`) interpolated on
        day-long segments by Chebyshev polynomials of degree 10 (:mod:`.chebyshev`):
        the Sun turns 0.017 rad in a day, and the interpolant is :meth:`position` to
        round-off (``test_world_table``), at a third of the formula's cost over an
        array.
        """
        times = np.asarray(times, float)
        if self.fixed is not None:
            return np.tile(self.position(0.0), (times.size, 1))
        if self._interpolant is None:
            from .chebyshev import ChebyshevSegments
            self._interpolant = ChebyshevSegments(
                lambda middle, nodes: sun_positions_days(self.days0 + nodes / _DAY), _DAY, 10,
                keep=4, name='sun')
        return self._interpolant.values(times)


def in_shadow(r, sun, radius):
    """
    Tell whether position ``r`` (m, world) is in the cylindrical shadow of a planet.

    ``sun`` is the unit vector to the Sun (world), ``radius`` (m) the planet's.
    """
    along = r[0] * sun[0] + r[1] * sun[1] + r[2] * sun[2]
    if along >= 0.0:
        return False
    across2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] - along * along
    return across2 < radius * radius
