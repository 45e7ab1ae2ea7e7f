"""
The IGRF-14 field along an orbit against the ppigrf library's own evaluation.

Reference: ``ppigrf.igrf_gc`` (its IGRF14.shc, its sum), at each point's own
date and Earth-fixed position. Checked: the sum itself (round-off), the
interpolant the simulator runs (0.003 nT, 600 times over 2025-2030, 300 to 2000
km), degree 1 against the dipole of the same coefficients, and the refusals.
"""

from datetime import datetime, timezone
import math

import numpy as np
import pytest
from rigid_body_dynamics.physics.environment import (DipoleField, EARTH_RATE, igrf_coefficients,
                                                     igrf_fixed, IgrfField, KeplerOrbit, R_EARTH)

ppigrf = pytest.importorskip('ppigrf', reason='magnetic_field_model igrf needs ppigrf')

START = datetime(2025, 1, 1, tzinfo=timezone.utc).timestamp()
YEARS = 5 * 365.25 * 86400.0


def library_field(when, r_fixed):
    """Return B (nT, Earth-fixed x, y, z) of ppigrf.igrf_gc at Unix times and positions (m)."""
    r_fixed = np.atleast_2d(r_fixed)
    rn = np.linalg.norm(r_fixed, axis=1)
    colat = np.degrees(np.arccos(r_fixed[:, 2] / rn))
    lon = np.degrees(np.arctan2(r_fixed[:, 1], r_fixed[:, 0]))
    dates = [datetime.fromtimestamp(w, timezone.utc).replace(tzinfo=None) for w in when]
    b_r, b_t, b_p = (np.diagonal(np.reshape(b, (len(dates), -1)))
                     for b in ppigrf.igrf_gc(rn / 1e3, colat, lon, dates))
    th, ph = np.radians(colat), np.radians(lon)
    horizontal = b_r * np.sin(th) + b_t * np.cos(th)
    return np.column_stack((horizontal * np.cos(ph) - b_p * np.sin(ph),
                            horizontal * np.sin(ph) + b_p * np.cos(ph),
                            b_r * np.cos(th) - b_t * np.sin(th)))


def test_the_sum_is_ppigrfs_to_round_off(rng):
    """600 points: 2025-2030, 300-2000 km up, every latitude and longitude: 2e-9 nT."""
    when = START + rng.uniform(0.0, YEARS, 600)
    direction = rng.normal(size=(600, 3))
    r = direction / np.linalg.norm(direction, axis=1)[:, None] * (
        R_EARTH + rng.uniform(300e3, 2000e3, 600))[:, None]
    mine = np.array([igrf_fixed(ri, *igrf_coefficients(w))[0] for w, ri in zip(when, r)])
    assert np.max(np.abs(mine - library_field(when, r))) < 2e-9


ORBITS = [  # [a, e, i, RAAN, argp, nu0]: circular 300, 800 and 2000 km, 300 x 2000 km
    [R_EARTH + 300e3, 0.0, 1.70, 0.3, 0.0, 0.1],
    [R_EARTH + 800e3, 0.001, 0.9, 2.0, 1.0, 4.0],
    [R_EARTH + 2000e3, 0.0, 0.1, 5.0, 0.0, 2.0],
    [R_EARTH + 1150e3, 850e3 / (R_EARTH + 1150e3), 1.2, 1.0, 0.5, 0.0],
]


@pytest.mark.parametrize('elements', ORBITS)
def test_the_interpolant_along_the_orbit_is_within_0_003_nt(rng, elements):
    """150 times over three orbits, the orbit's start anywhere in 2025-2030, degree 13."""
    orbit = KeplerOrbit(elements)
    start = START + rng.uniform(0.0, YEARS - 86400.0)
    theta0 = rng.uniform(0.0, 2.0 * math.pi)
    field = IgrfField(orbit, start, 13, theta0, EARTH_RATE)
    times = rng.uniform(0.0, 3.0 * orbit.period, 150)
    mine = np.array([field.world(t, orbit.position(t)) for t in times]) * 1e9
    theta = theta0 + EARTH_RATE * times
    c, s = np.cos(theta), np.sin(theta)
    r = np.array([orbit.position(t) for t in times])
    fixed = np.column_stack((c * r[:, 0] + s * r[:, 1], -s * r[:, 0] + c * r[:, 1], r[:, 2]))
    b = library_field(start + times, fixed)
    world = np.column_stack((c * b[:, 0] - s * b[:, 1], s * b[:, 0] + c * b[:, 1], b[:, 2]))
    assert np.max(np.abs(mine - world)) < 0.003      # (measured: 3.7e-4 to 8.7e-4 nT)


def test_degree_1_is_the_dipole_of_the_same_coefficients(rng):
    """
    The sum to degree 1 = DipoleField of (g10, g11, h11) at the date, to round-off of |B|.

    The two sum the same three terms in different orders: measured 4.5e-16 to 1.0e-15 of
    |B| (numpy 2.4 / 1.26), so the bound is 20 ulps (4.4e-15), not a knife edge at 1e-15.
    """
    orbit = KeplerOrbit(ORBITS[1])
    when = datetime(2027, 3, 20, tzinfo=timezone.utc).timestamp()
    field = IgrfField(orbit, when, 1, 0.7, EARTH_RATE)
    keys, g, h = igrf_coefficients(when, 1)
    assert keys == [(1, 0), (1, 1)]
    dipole = DipoleField((g[0], g[1], h[1]), 0.7, EARTH_RATE)
    worst = 0.0
    for t in rng.uniform(0.0, 60.0, 50):           # (a minute: the secular change < 1e-5 nT)
        r = orbit.position(t)
        exact, reference = np.array(field.exact(0.0, r)), np.array(dipole.world(0.0, r))
        worst = max(worst, np.linalg.norm(exact - reference) / np.linalg.norm(reference))
    assert worst < 20 * np.finfo(float).eps


@pytest.mark.parametrize('kwargs, match', [
    ({'degree': 0}, 'magnetic_field_degree must be an integer 1..13'),
    ({'degree': 14}, 'magnetic_field_degree must be an integer 1..13'),
    ({'start': datetime(2031, 1, 1, tzinfo=timezone.utc).timestamp()}, 'IGRF-14 covers'),
    ({'rotation_angle': math.nan}, 'earth_rotation_angle must be finite'),
])
def test_bad_igrf_settings_are_refused_naming_them(kwargs, match):
    settings = {'orbit': KeplerOrbit(ORBITS[0]), 'start': START, **kwargs}
    with pytest.raises(ValueError, match=match):
        IgrfField(**settings)
