"""
The atmosphere for drag: the height above the ellipsoid, the exponential density, the flow.

The height is held to the forward map from geodetic latitude and height to a position
(the closed form, e.g. Vallado's eq. 3-7), the density to Vallado's table 8-4 rows as
printed (written here again, from the book), and the flow to v - omega x r by numpy.
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics.environment import ExponentialAtmosphere, geodetic_altitude

A, F = 6378137.0, 1.0 / 298.257223563          # WGS-84
E2 = F * (2.0 - F)


def _position(lat, lon, h):
    """Return the Earth-centred position (m) of geodetic latitude, longitude (rad), height."""
    n = A / math.sqrt(1.0 - E2 * math.sin(lat) ** 2)
    return ((n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1.0 - E2) + h) * math.sin(lat))


def test_the_height_above_the_ellipsoid_from_the_surface_to_the_moon():
    """2000 random places from 1 m to 400 000 km up: within 1e-6 m (delivered 1.2e-7 m)."""
    rng = np.random.default_rng(11)
    worst = 0.0
    for lat, lon, h in zip(rng.uniform(-math.pi / 2, math.pi / 2, 2000),
                           rng.uniform(-math.pi, math.pi, 2000), 10 ** rng.uniform(0, 8.6, 2000)):
        worst = max(worst, abs(geodetic_altitude(_position(lat, lon, h)) - h))
    assert worst < 1e-6, worst
    for lat in (0.0, math.pi / 2, -math.pi / 2):         # the equator and both poles exactly
        assert geodetic_altitude(_position(lat, 0.3, 4e5)) == pytest.approx(4e5, abs=1e-6)


#: Rows of Vallado's table 8-4 (h0 km, rho0 kg/m^3, H km), as printed in the book.
ROWS = {0.0: (1.225, 7.249), 150.0: (2.070e-9, 22.523), 400.0: (3.725e-12, 58.515),
        450.0: (1.585e-12, 60.828), 1000.0: (3.019e-15, 268.00)}


@pytest.mark.parametrize('h, base', [(0.0, 0.0), (10.0, 0.0), (160.0, 150.0), (400.0, 400.0),
                                     (420.0, 400.0), (449.0, 400.0), (450.0, 450.0),
                                     (1000.0, 1000.0), (2000.0, 1000.0)])
def test_the_density_is_vallados_band_at_that_height(h, base):
    """At the equator and over a pole (where a sphere would put the body 21 km higher)."""
    rho0, scale = ROWS[base]
    expected = rho0 * math.exp(-(h - base) / scale)
    air = ExponentialAtmosphere(7.292115e-5)
    for lat in (0.0, math.pi / 2):
        assert air.density(0.0, _position(lat, 1.0, 1e3 * h)) == pytest.approx(expected, rel=1e-12)


def test_the_bands_meet_within_a_ten_thousandth_above_25_km():
    """The table's bands meet within 1e-4 of the density (its printed digits) above 25 km."""
    from rigid_body_dynamics.physics.environment.atmosphere import EXPONENTIAL_TABLE
    air = ExponentialAtmosphere(0.0)
    for h0, _, _ in EXPONENTIAL_TABLE[2:]:
        below, above = (air.density(0.0, (A + 1e3 * h0 + d, 0.0, 0.0)) for d in (-1e-3, 1e-3))
        assert above == pytest.approx(below, rel=1e-4), h0


def test_the_air_turns_with_the_earth():
    rng = np.random.default_rng(5)
    air = ExponentialAtmosphere(7.292115e-5)
    for r, v in zip(rng.normal(0.0, 7e6, (20, 3)), rng.normal(0.0, 7e3, (20, 3))):
        expected = v - np.cross([0.0, 0.0, 7.292115e-5], r)
        np.testing.assert_allclose(air.flow(tuple(r), tuple(v)), expected, rtol=0,
                                   atol=1e-12 * np.linalg.norm(expected))


def test_a_bad_rate_is_refused():
    with pytest.raises(ValueError, match='rotation rate must be finite'):
        ExponentialAtmosphere(math.nan)
