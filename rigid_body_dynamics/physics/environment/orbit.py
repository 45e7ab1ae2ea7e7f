"""
A two-body (Kepler) orbit, exact at any time, and its local-vertical local-horizontal frame.

Frames and units. The world frame is inertial with z along the planet's rotation
axis (which equator and equinox is the user's: with a TLE it is TEME of date,
:mod:`.tle_orbit`); positions in m, velocities in m/s, angles in rad, time in s
from simulated time 0.

Elements ``[a, e, i, RAAN, argp, nu0]``: semi-major axis a (m), eccentricity e
(0 <= e < 1), inclination i, right ascension of the ascending node RAAN,
argument of perigee argp and the true anomaly nu0 at t = 0. The position is
found from Kepler's equation M = E - e sin E, M = M0 + n t, n = sqrt(mu / a^3),
solved by Newton's method to round-off at any t (the mean anomaly is reduced
modulo 2 pi first), then

    r_pf = a (cos E - e, sqrt(1 - e^2) sin E, 0)
    v_pf = sqrt(mu a) / norm(r) (-sin E, sqrt(1 - e^2) cos E, 0)

in the perifocal frame, turned to the world frame by R3(-RAAN) R1(-i) R3(-argp)
(Vallado, Fundamentals of Astrodynamics and Applications, section 2.6).

LVLH (local vertical, local horizontal) frame of a position r and velocity v:
z = -r / norm(r) (nadir), y = -(r x v) / norm(r x v) (minus the orbit normal),
x = y x z (along the velocity for a circular orbit). LVLH axes are roll (x),
pitch (y) and yaw (z) in the libration theory (Wie, Space Vehicle Dynamics and
Control, section 6.3).
"""

import math

import numpy as np

#: Earth's gravitational parameter (m^3/s^2, EGM96 / WGS-84).
MU_EARTH = 3.986004418e14
#: Earth's equatorial radius (m, WGS-84): the default ``planet_radius``.
R_EARTH = 6378137.0

_TWO_PI = 2.0 * math.pi


class KeplerOrbit:
    """
    The two-body orbit of ``elements`` [a m, e, i, RAAN, argp, nu0 rad] about ``mu`` (m^3/s^2).

    Refuses (ValueError, naming ``orbit_elements``, ``orbit_mu`` or
    ``planet_radius``) anything but six finite numbers, a <= 0, e outside
    [0, 1) and a perigee radius a (1 - e) at or below ``planet_radius`` (m).
    :meth:`state` gives (r, v) in the world frame at any t (s).
    """

    def __init__(self, elements, mu=MU_EARTH, planet_radius=R_EARTH):
        try:
            values = [float(v) for v in elements]
        except (TypeError, ValueError):
            raise ValueError(f'orbit_elements must be six numbers [a, e, i, RAAN, argp, '
                             f'true anomaly], got {elements!r}') from None
        if len(values) != 6 or not all(math.isfinite(v) for v in values):
            raise ValueError('orbit_elements must be six finite numbers [a (m), e, i, RAAN, '
                             f'argp, true anomaly (rad)], got {list(elements)!r}')
        if not (math.isfinite(mu) and mu > 0.0):
            raise ValueError(f'orbit_mu must be positive and finite (m^3/s^2), got {mu!r}')
        if not (math.isfinite(planet_radius) and planet_radius >= 0.0):
            raise ValueError(f'planet_radius must be finite and >= 0 (m), got {planet_radius!r}')
        a, e, inc, raan, argp, nu0 = values
        if a <= 0.0:
            raise ValueError(f'orbit_elements: the semi-major axis a must be positive (an '
                             f'ellipse), got {a!r} m')
        if not 0.0 <= e < 1.0:
            raise ValueError(f'orbit_elements: the eccentricity must be in [0, 1) (an ellipse; '
                             f'e >= 1 does not return), got {e!r}')
        if a * (1.0 - e) <= planet_radius:
            raise ValueError(f'orbit_elements: the perigee radius a (1 - e) = '
                             f'{a * (1.0 - e):.6g} m is not above planet_radius = '
                             f'{planet_radius:.6g} m')
        self.elements = tuple(values)
        self.a, self.e, self.mu = a, e, float(mu)
        self.n = math.sqrt(mu / (a * a * a))          # mean motion (rad/s)
        self._b = math.sqrt((1.0 - e) * (1.0 + e))    # sqrt(1 - e^2)
        self._vscale = math.sqrt(mu * a)
        # the perifocal axes P (to perigee) and Q in the world frame: R3(-RAAN) R1(-i) R3(-argp)
        cO, sO = math.cos(raan), math.sin(raan)
        ci, si = math.cos(inc), math.sin(inc)
        cw, sw = math.cos(argp), math.sin(argp)
        self.p_axis = (cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si)
        self.q_axis = (-cO * sw - sO * cw * ci, -sO * sw + cO * cw * ci, cw * si)
        self.normal = (sO * si, -cO * si, ci)
        e_anomaly = 2.0 * math.atan2(math.sqrt(1.0 - e) * math.sin(0.5 * nu0),
                                     math.sqrt(1.0 + e) * math.cos(0.5 * nu0))
        self.m0 = e_anomaly - e * math.sin(e_anomaly)
        self._last = (0.0, e_anomaly)                 # (M, E) of the last solve: Newton's start

    @property
    def period(self):
        """Return the orbital period 2 pi / n (s)."""
        return _TWO_PI / self.n

    def summary(self):
        """Return a line that says which orbit this is (for the node's log)."""
        a, e, inc = self.elements[:3]
        return f'Kepler: a = {a:.6g} m, e = {e:g}, i = {inc:g} rad, period {self.period:.6g} s'

    def eccentric_anomaly(self, t):
        """Return E (rad, in [0, 2 pi)) at time t (s): Kepler's equation solved to round-off."""
        m = math.fmod(self.m0 + self.n * t, _TWO_PI)
        if m < 0.0:
            m += _TWO_PI
        e = self.e
        if e == 0.0:
            return m
        last_m, last_e = self._last
        # start from the last solution moved by the change of M (RK stages are close in t)
        big = last_e + (m - last_m) if abs(m - last_m) < 0.1 else (
            m + e * math.sin(m) if e < 0.8 else math.pi)
        for _ in range(50):
            s, c = math.sin(big), math.cos(big)
            step = (big - e * s - m) / (1.0 - e * c)
            big -= step
            if abs(step) <= 4e-16 * (1.0 + abs(big)):
                break
        self._last = (m, big)
        return big

    def state(self, t):
        """Return (r m, v m/s), tuples in the world frame, at time t (s)."""
        big = self.eccentric_anomaly(t)
        c, s = math.cos(big), math.sin(big)
        a, e, b = self.a, self.e, self._b
        x, y = a * (c - e), a * b * s
        k = self._vscale / (a * (1.0 - e * c))        # sqrt(mu a) / |r|
        vx, vy = -k * s, k * b * c
        p, q = self.p_axis, self.q_axis
        return ((x * p[0] + y * q[0], x * p[1] + y * q[1], x * p[2] + y * q[2]),
                (vx * p[0] + vy * q[0], vx * p[1] + vy * q[1], vx * p[2] + vy * q[2]))

    def position(self, t):
        """Return r (m, world frame) at time t (s)."""
        big = self.eccentric_anomaly(t)
        c, s = math.cos(big), math.sin(big)
        x, y = self.a * (c - self.e), self.a * self._b * s
        p, q = self.p_axis, self.q_axis
        return (x * p[0] + y * q[0], x * p[1] + y * q[1], x * p[2] + y * q[2])

    def eccentric_anomalies(self, times):
        """Return E (rad, in [0, 2 pi)) at ``times`` (s, an array): Newton to round-off."""
        m = np.fmod(self.m0 + self.n * np.asarray(times, float), _TWO_PI)
        m = np.where(m < 0.0, m + _TWO_PI, m)
        e = self.e
        if e == 0.0:
            return m
        big = m + e * np.sin(m) if e < 0.8 else np.full_like(m, math.pi)
        for _ in range(50):
            step = (big - e * np.sin(big) - m) / (1.0 - e * np.cos(big))
            big = big - step
            if np.all(np.abs(step) <= 4e-16 * (1.0 + np.abs(big))):
                break
        return big

    def positions(self, times):
        """Return r (m, world frame, (N, 3)) at ``times`` (s): :meth:`position` over an array."""
        big = self.eccentric_anomalies(times)
        x, y = self.a * (np.cos(big) - self.e), self.a * self._b * np.sin(big)
        return np.outer(x, self.p_axis) + np.outer(y, self.q_axis)

    def states(self, times):
        """Return (r m, v m/s), (N, 3) arrays in the world frame, at ``times`` (s)."""
        big = self.eccentric_anomalies(times)
        c, s = np.cos(big), np.sin(big)
        a, b = self.a, self._b
        k = self._vscale / (a * (1.0 - self.e * c))
        return (np.outer(a * (c - self.e), self.p_axis) + np.outer(a * b * s, self.q_axis),
                np.outer(-k * s, self.p_axis) + np.outer(k * b * c, self.q_axis))


def lvlh_axes(r, v):
    """
    Return the LVLH axes (x, y, z) in the world frame of position r (m) and velocity v (m/s).

    z = -r / norm(r) (nadir), y = -(r x v) / norm(r x v), x = y x z; each a 3-tuple.
    """
    rn = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    z = (-r[0] / rn, -r[1] / rn, -r[2] / rn)
    h = (r[1] * v[2] - r[2] * v[1], r[2] * v[0] - r[0] * v[2], r[0] * v[1] - r[1] * v[0])
    hn = math.sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2])
    y = (-h[0] / hn, -h[1] / hn, -h[2] / hn)
    x = (y[1] * z[2] - y[2] * z[1], y[2] * z[0] - y[0] * z[2], y[0] * z[1] - y[1] * z[0])
    return x, y, z


def lvlh_quaternion(r, v):
    """
    Return the attitude (x, y, z, w) of the LVLH frame (LVLH -> world) at r (m), v (m/s).

    From the rotation matrix whose columns are the LVLH axes in the world
    frame (Shepperd's method; tested against scipy's Rotation.from_matrix).
    """
    (m00, m10, m20), (m01, m11, m21), (m02, m12, m22) = lvlh_axes(r, v)
    trace = m00 + m11 + m22
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = ((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s)
    elif m00 > m11 and m00 > m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = (0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
    elif m11 > m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = ((m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = ((m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s)
    return q if q[3] >= 0.0 else (-q[0], -q[1], -q[2], -q[3])


def circular_elements(altitude, inclination=0.0, raan=0.0, anomaly=0.0,
                      planet_radius=R_EARTH):
    """Return the elements [a, 0, i, RAAN, 0, nu0] of a circular orbit ``altitude`` m up."""
    return [planet_radius + altitude, 0.0, inclination, raan, 0.0, anomaly]
