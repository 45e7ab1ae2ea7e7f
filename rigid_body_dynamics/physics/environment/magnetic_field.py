"""
Earth's magnetic field as the centred tilted dipole of degree 1 (no ROS).

In the Earth-fixed frame (z the rotation axis, x through the prime meridian)
the field at position r (m) is

    B(r) = (R_ref / norm(r))^3 [3 (d . r_hat) r_hat - d],   d = (g11, h11, g10)

with the Gauss coefficients of degree 1 (nT; B comes out in tesla here),
R_ref = 6371.2 km the reference radius of the IGRF (International
Geomagnetic Reference Field; Basilisk's magneticFieldCenteredDipole uses the
same form). The Earth-fixed frame is the world frame turned about z by
theta(t) = theta0 + ``earth_rotation_rate`` t (theta0: ``earth_rotation_angle``,
or the Greenwich mean sidereal time of the epoch, see
:func:`~.tle_orbit.greenwich_mean_sidereal_time`); since the
formula is the same in every frame, d is turned into the world frame and B is
evaluated there. Defaults: IGRF-13 at epoch 2020.0 (g10 = -29404.8, g11 =
-1450.9, h11 = 4652.5 nT) and Earth's sidereal rate 7.2921150e-5 rad/s.
About 30 uT at the equator on the surface, pointing north, and twice that,
pointing down, at the dipole's poles.
"""

import math

import numpy as np

#: IGRF-13 degree-1 Gauss coefficients at epoch 2020.0, [g10, g11, h11] (nT).
IGRF13_2020 = (-29404.8, -1450.9, 4652.5)
#: The IGRF reference radius (m).
R_REF = 6371200.0
#: Earth's sidereal rotation rate (rad/s).
EARTH_RATE = 7.2921150e-5


class DipoleField:
    """
    The centred tilted dipole: ``coefficients`` [g10, g11, h11] (nT), Earth's rotation.

    ``rotation_angle`` theta0 (rad) and ``rotation_rate`` (rad/s) turn the
    Earth-fixed frame about the world z axis; ``reference_radius`` (m).
    Bad values raise ValueError naming the parameter.
    """

    def __init__(self, coefficients=IGRF13_2020, rotation_angle=0.0, rotation_rate=EARTH_RATE,
                 reference_radius=R_REF):
        try:
            g10, g11, h11 = (float(c) for c in coefficients)
        except (TypeError, ValueError):
            raise ValueError('magnetic_dipole_coefficients must be three numbers [g10, g11, '
                             f'h11] (nT), got {coefficients!r}') from None
        if not all(math.isfinite(c) for c in (g10, g11, h11)):
            raise ValueError('magnetic_dipole_coefficients must be finite, got '
                             f'{list(coefficients)!r}')
        for name, value in (('earth_rotation_angle', rotation_angle),
                            ('earth_rotation_rate', rotation_rate)):
            if not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value!r}')
        if not (math.isfinite(reference_radius) and reference_radius > 0.0):
            raise ValueError(f'reference_radius must be positive, got {reference_radius!r}')
        self.coefficients = (g10, g11, h11)
        self.dipole_fixed = (g11 * 1e-9, h11 * 1e-9, g10 * 1e-9)     # d (T), Earth-fixed
        self.theta0, self.rate = float(rotation_angle), float(rotation_rate)
        self._r3 = float(reference_radius) ** 3

    def dipole_world(self, t):
        """Return d (T) in the world frame at time t (s)."""
        theta = self.theta0 + self.rate * t
        c, s = math.cos(theta), math.sin(theta)
        dx, dy, dz = self.dipole_fixed
        return (c * dx - s * dy, s * dx + c * dy, dz)

    def world(self, t, r):
        """Return B (T) in the world frame at time t (s) and position r (m, world frame)."""
        dx, dy, dz = self.dipole_world(t)
        rx, ry, rz = r
        r2 = rx * rx + ry * ry + rz * rz
        rn = math.sqrt(r2)
        k = self._r3 / (r2 * rn)
        three = 3.0 * (dx * rx + dy * ry + dz * rz) / r2
        return (k * (three * rx - dx), k * (three * ry - dy), k * (three * rz - dz))

    def world_many(self, times, r):
        """Return B (T, world frame, (N, 3)) at ``times`` (s) and positions ``r`` (m, (N, 3))."""
        theta = self.theta0 + self.rate * np.asarray(times, float)
        c, s = np.cos(theta), np.sin(theta)
        fx, fy, dz = self.dipole_fixed
        dx, dy = c * fx - s * fy, s * fx + c * fy
        rx, ry, rz = r[:, 0], r[:, 1], r[:, 2]
        r2 = rx * rx + ry * ry + rz * rz
        k = self._r3 / (r2 * np.sqrt(r2))
        three = 3.0 * (dx * rx + dy * ry + dz * rz) / r2
        return np.column_stack((k * (three * rx - dx), k * (three * ry - dy),
                                k * (three * rz - dz)))
