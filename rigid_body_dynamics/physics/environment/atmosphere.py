"""
The Earth's atmosphere for drag: the density by altitude, and the air turning with the Earth.

:class:`ExponentialAtmosphere` is the exponential model of Vallado,
*Fundamentals of Astrodynamics and Applications* (4th ed., 2013), table 8-4
(from the US Standard Atmosphere 1976 below 25 km and CIRA-72 above): in each
band of altitude h from its base h0 the density is rho0 exp(-(h - h0) / H),
the last band's (1000 km) going on above. It holds no solar or geomagnetic
activity: the real density at 400 km moves by a factor of 5 to 10 over the
solar cycle, which is why a drag torque is a disturbance to size margins with,
not a prediction.

The altitude is the height above the WGS-84 ellipsoid (geodetic; at the poles a
sphere of the equatorial radius would put the body 21 km too high, 30 % too
little density at 400 km). The air turns with the Earth, so the body meets it
at v - omega_E x r (world frame, z the rotation axis).
"""

from bisect import bisect_right
import math

import numpy as np

#: Vallado's table 8-4: (base altitude h0 (km), density there rho0 (kg/m^3), scale height H
#: (km)) per band, from the band's base to the next one's.
EXPONENTIAL_TABLE = (
    (0.0, 1.225, 7.249), (25.0, 3.899e-2, 6.349), (30.0, 1.774e-2, 6.682),
    (40.0, 3.972e-3, 7.554), (50.0, 1.057e-3, 8.382), (60.0, 3.206e-4, 7.714),
    (70.0, 8.770e-5, 6.549), (80.0, 1.905e-5, 5.799), (90.0, 3.396e-6, 5.382),
    (100.0, 5.297e-7, 5.877), (110.0, 9.661e-8, 7.263), (120.0, 2.438e-8, 9.473),
    (130.0, 8.484e-9, 12.636), (140.0, 3.845e-9, 16.149), (150.0, 2.070e-9, 22.523),
    (180.0, 5.464e-10, 29.740), (200.0, 2.789e-10, 37.105), (250.0, 7.248e-11, 45.546),
    (300.0, 2.418e-11, 53.628), (350.0, 9.518e-12, 53.298), (400.0, 3.725e-12, 58.515),
    (450.0, 1.585e-12, 60.828), (500.0, 6.967e-13, 63.822), (600.0, 1.454e-13, 71.835),
    (700.0, 3.614e-14, 88.667), (800.0, 1.170e-14, 124.64), (900.0, 5.245e-15, 181.05),
    (1000.0, 3.019e-15, 268.00))

#: WGS-84's equatorial radius (m) and flattening.
WGS84_A, WGS84_F = 6378137.0, 1.0 / 298.257223563
#: The atmosphere models the nodes offer.
ATMOSPHERE_MODELS = ('exponential', 'nrlmsis')


def geodetic_altitude(r, a=WGS84_A, f=WGS84_F):
    """
    Return the height (m) of ``r`` above the ellipsoid (a m, flattening f; WGS-84's).

    ``r`` (m) from the Earth's centre in a frame whose z is the rotation axis (the world
    frame, or the Earth-fixed one: the height does not depend on the longitude).
    Bowring's formula for the geodetic latitude (Bowring, Survey Review 23, 1976), one
    round from his initial guess: within 1e-6 m from the surface to the Moon's distance
    (a second round changes nothing there).
    """
    return geodetic_latitude_height(r, a, f)[1]


def geodetic_latitude_height(r, a=WGS84_A, f=WGS84_F):
    """
    Return (geodetic latitude (rad), height (m)) of ``r`` over the ellipsoid (a m, flattening f).

    ``r`` (m) from the Earth's centre, z the rotation axis; Bowring's one round, as
    :func:`geodetic_altitude`.
    """
    x, y, z = r
    p = math.hypot(x, y)
    e2 = f * (2.0 - f)
    b = a * (1.0 - f)
    ep2 = e2 / (1.0 - e2)
    beta = math.atan2(a * z, b * p) if p else math.copysign(0.5 * math.pi, z)
    sb, cb = math.sin(beta), math.cos(beta)
    lat = math.atan2(z + ep2 * b * sb * sb * sb, p - e2 * a * cb * cb * cb)
    s, c = math.sin(lat), math.cos(lat)
    return lat, p * c + z * s - a * math.sqrt(1.0 - e2 * s * s)


def geodetic_heights(r, a=WGS84_A, f=WGS84_F):
    """
    Return :func:`geodetic_altitude` (m, an (N,) array) of positions ``r`` (m, (N, 3)).

    Bowring's same round, with the sines and cosines of his two angles taken from
    their tangents' sides (square roots, no trigonometry).
    """
    x, y, z = r[:, 0], r[:, 1], r[:, 2]
    p = np.hypot(x, y)
    e2 = f * (2.0 - f)
    b = a * (1.0 - f)
    ep2 = e2 / (1.0 - e2)
    u, w = a * z, b * p                         # tan(beta) = u / w
    n = np.hypot(u, w)
    sb, cb = u / n, w / n
    u, w = z + ep2 * b * sb * sb * sb, p - e2 * a * cb * cb * cb     # tan(latitude)
    n = np.hypot(u, w)
    s, c = u / n, w / n
    return p * c + z * s - a * np.sqrt(1.0 - e2 * s * s)


def air_flow(earth_rate, r, v):
    """
    Return the velocity (m/s, world frame) relative to the air turning with the Earth.

    That is v - omega x r, omega ``earth_rate`` (rad/s) about the world z axis, ``r``
    (m) and ``v`` (m/s) in the world frame.
    """
    return (v[0] + earth_rate * r[1], v[1] - earth_rate * r[0], v[2])


def air_flows(earth_rate, r, v):
    """Return :func:`air_flow` at many places: ``r`` (m) and ``v`` (m/s), (N, 3) arrays."""
    return np.column_stack((v[:, 0] + earth_rate * r[:, 1], v[:, 1] - earth_rate * r[:, 0],
                            v[:, 2]))


class ExponentialAtmosphere:
    """
    Vallado's exponential density (see the module) on a rotating Earth.

    ``earth_rate`` (rad/s about the world z axis): the air turns with it. Refuses
    (ValueError) a non-finite rate.
    """

    name = 'exponential'

    def __init__(self, earth_rate):
        self.earth_rate = float(earth_rate)
        if not math.isfinite(self.earth_rate):
            raise ValueError(f'the Earth rotation rate must be finite, got {earth_rate!r}')
        self._bases = [1e3 * h0 for h0, _, _ in EXPONENTIAL_TABLE]
        self._table = np.array(EXPONENTIAL_TABLE).T          # (h0, rho0, H) by band

    def density(self, t, r):
        """
        Return rho, the air's density in kg/m^3, at the position ``r`` (m, world frame).

        ``t`` (s, orbit time) is not used: the table holds no time.
        """
        h = geodetic_altitude(r)
        h0, rho0, scale = EXPONENTIAL_TABLE[max(0, bisect_right(self._bases, h) - 1)]
        return rho0 * math.exp(-(h - 1e3 * h0) / (1e3 * scale))

    def densities(self, times, r):
        """Return :meth:`density` (kg/m^3, an (N,) array) at positions ``r`` (m, (N, 3))."""
        h = geodetic_heights(r)
        band = np.maximum(0, np.searchsorted(self._bases, h, side='right') - 1)
        h0, rho0, scale = self._table[:, band]
        return rho0 * np.exp(-(h - 1e3 * h0) / (1e3 * scale))

    def flow(self, r, v):
        """
        Return the body's velocity relative to the air (m/s, world frame): v - omega_E x r.

        ``r`` (m) and ``v`` (m/s), world frame.
        """
        return air_flow(self.earth_rate, r, v)

    def flows(self, r, v):
        """Return :meth:`flow` at many places: ``r`` (m) and ``v`` (m/s), (N, 3) arrays."""
        return air_flows(self.earth_rate, r, v)

    def __str__(self):
        return 'exponential atmosphere (Vallado table 8-4)'
