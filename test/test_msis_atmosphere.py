"""
NRLMSIS 2.1's density along an orbit against the pymsis library's own evaluation.

Reference: ``pymsis.calculate`` called here on its own, at each point's date,
geodetic latitude, longitude and height (from the orbit's position turned into
the Earth-fixed frame, the latitude and height by a fixed-point iteration to
convergence, not the module's Bowring formula). Checked: the model's call
(round-off), the interpolant the simulator runs (1.5e-4 relative at 600 times,
250 to 1000 km: the model's own single-precision noise), its segments meeting at
0 h UTC where the model's day of the year steps, the activity's effect, the air
turning with the Earth, and the refusals.
"""

from datetime import datetime, timezone
import math
import sys

import numpy as np
import pytest
from rigid_body_dynamics.physics.environment import EARTH_RATE, KeplerOrbit, R_EARTH
from rigid_body_dynamics.physics.environment.atmosphere import WGS84_A, WGS84_F

pymsis = pytest.importorskip('pymsis', reason='atmosphere_model nrlmsis needs pymsis')
from rigid_body_dynamics.physics.environment.msis_atmosphere import MsisAtmosphere  # noqa: E402

START = datetime(2025, 1, 1, tzinfo=timezone.utc).timestamp()
YEARS = 5 * 365.25 * 86400.0


def geodetic(fixed):
    """Return (lat deg, lon deg, h km) of Earth-fixed positions (m), iterated to convergence."""
    e2 = WGS84_F * (2.0 - WGS84_F)
    out = []
    for x, y, z in fixed:
        p = math.hypot(x, y)
        lat = math.atan2(z, p * (1.0 - e2))
        for _ in range(50):
            n = WGS84_A / math.sqrt(1.0 - e2 * math.sin(lat) ** 2)
            h = p / math.cos(lat) - n
            lat = math.atan2(z, p * (1.0 - e2 * n / (n + h)))
        out.append((math.degrees(lat), math.degrees(math.atan2(y, x)), 1e-3 * h))
    return np.array(out)


def library_density(when, fixed, f107, f107a, ap):
    """Return pymsis's total mass density (kg/m^3) at Unix times and Earth-fixed positions (m)."""
    lat, lon, h = geodetic(fixed).T
    dates = np.array([np.datetime64(datetime.fromtimestamp(w, timezone.utc).replace(
        tzinfo=None), 'us') for w in when])
    n = len(when)
    out = pymsis.calculate(dates, lon, lat, h, np.full(n, f107), np.full(n, f107a),
                           np.full((n, 7), ap), version=2.1)
    return np.asarray(out)[:, 0]


def earth_fixed(theta, r):
    """Return world positions ``r`` (m, (N, 3)) in the frame turned by ``theta`` (rad) about z."""
    c, s = np.cos(theta), np.sin(theta)
    return np.column_stack((c * r[:, 0] + s * r[:, 1], -s * r[:, 0] + c * r[:, 1], r[:, 2]))


ORBITS = [  # [a, e, i, RAAN, argp, nu0]: circular 250, 420 and 1000 km, 250 x 800 km, polar
    [R_EARTH + 250e3, 0.0, 0.9, 0.3, 0.0, 0.1],
    [R_EARTH + 420e3, 0.0005, 0.9013, 2.0, 1.0, 4.0],
    [R_EARTH + 1000e3, 0.0, 1.71, 5.0, 0.0, 2.0],
    [R_EARTH + 525e3, 275e3 / (R_EARTH + 525e3), 1.2, 1.0, 0.5, 0.0],
]


def test_the_models_call_is_pymsis_at_the_point(rng):
    """200 points of one orbit: the module's conversion and call = the direct call, 1e-12."""
    orbit = KeplerOrbit(ORBITS[1])
    theta0 = rng.uniform(0.0, 2.0 * math.pi)
    air = MsisAtmosphere(orbit, START + 1e7, 120.0, 140.0, 9.0, theta0, EARTH_RATE)
    times = rng.uniform(0.0, 2.0 * orbit.period, 200)
    r = np.array([orbit.position(t) for t in times])
    mine = air.model(times, r)
    reference = library_density(START + 1e7 + times, earth_fixed(theta0 + EARTH_RATE * times, r),
                                120.0, 140.0, 9.0)
    assert np.max(np.abs(mine / reference - 1.0)) < 1e-12


@pytest.mark.parametrize('elements', ORBITS)
def test_the_interpolant_along_the_orbit_is_within_the_models_noise(rng, elements):
    """
    150 times over three orbits, the start anywhere in 2025-2030, the activity at random.

    pymsis computes in single precision: its density is noisy at a few 1e-5 from call to
    call (second differences 0.01 s apart: 5e-6 to 7e-6 of log rho). Measured over twelve
    draws per orbit: the worst 2.3e-5 (250 km) to 8.4e-5 (1000 km); the bound is 1.5e-4.
    """
    orbit = KeplerOrbit(elements)
    start = START + rng.uniform(0.0, YEARS - 86400.0)
    theta0 = rng.uniform(0.0, 2.0 * math.pi)
    f107, f107a, ap = rng.uniform(70.0, 250.0), rng.uniform(70.0, 250.0), rng.uniform(0.0, 50.0)
    air = MsisAtmosphere(orbit, start, f107, f107a, ap, theta0, EARTH_RATE)
    times = rng.uniform(0.0, 3.0 * orbit.period, 150)
    r = np.array([orbit.position(t) for t in times])
    mine = np.array([air.density(t, ri) for t, ri in zip(times, r)])
    reference = library_density(start + times, earth_fixed(theta0 + EARTH_RATE * times, r),
                                f107, f107a, ap)
    assert np.max(np.abs(mine / reference - 1.0)) < 1.5e-4


def test_the_segments_meet_at_midnight_where_the_models_day_steps():
    """
    Either side of 0 h UTC the interpolant follows the model of that side's day.

    The model's density steps there (its day of the year is a whole number): measured
    -0.49 % on 2027-06-30, -0.21 % on 2027-01-01, +0.40 % on 2027-03-20, +0.69 % on
    2026-09-22; a segment across the step would miss it by half of it on either side.
    """
    orbit = KeplerOrbit(ORBITS[1])
    midnight = datetime(2027, 6, 30, tzinfo=timezone.utc).timestamp()
    air = MsisAtmosphere(orbit, midnight - 1234.5, 150.0, 150.0, 4.0, 0.0, EARTH_RATE)
    span = air.interpolant.span
    assert math.remainder(1234.5 - air.interpolant.origin, span) == pytest.approx(0.0, abs=1e-9)
    before, after = (air.exact(t, orbit.position(t)) for t in (1234.5 - 1e-3, 1234.5 + 1e-3))
    assert abs(after / before - 1.0) > 3e-3                 # the step the segments avoid
    for t in (1234.5 - 1e-3, 1234.5 + 1e-3):
        r = orbit.position(t)
        assert air.density(t, r) == pytest.approx(air.exact(t, r), rel=1.5e-4)


def test_a_stronger_sun_thickens_the_air_at_400_km():
    """F10.7 70 -> 250 sfu reaches the model: the density at 400 km grows (measured 16.7x)."""
    orbit = KeplerOrbit([R_EARTH + 400e3, 0.0, 0.9, 0.0, 0.0, 0.0])
    quiet, active = (MsisAtmosphere(orbit, START, f, f, 4.0, 0.0, EARTH_RATE) for f in (70, 250))
    r = orbit.position(100.0)
    ratio = active.exact(100.0, r) / quiet.exact(100.0, r)
    assert 10.0 < ratio < 25.0


def test_the_air_turns_with_the_earth():
    """The flow is v - omega_E x r: over the equator at 400 km the air moves 494 m/s east."""
    orbit = KeplerOrbit([R_EARTH + 400e3, 0.0, 0.0, 0.0, 0.0, 0.0])
    air = MsisAtmosphere(orbit, START, rotation_rate=EARTH_RATE)
    r, v = (R_EARTH + 400e3, 0.0, 0.0), (0.0, 7668.0, 0.0)
    assert air.flow(r, v) == (0.0, 7668.0 - EARTH_RATE * (R_EARTH + 400e3), 0.0)
    assert EARTH_RATE * (R_EARTH + 400e3) == pytest.approx(494.3, abs=0.1)


@pytest.mark.parametrize('kwargs, match', [
    ({'f107': 0.0}, r'solar_flux_f107 must be in \(0, 1000\] sfu'),
    ({'f107a': math.nan}, r'solar_flux_f107a must be in \(0, 1000\] sfu'),
    ({'ap': -1.0}, r'geomagnetic_ap must be in \[0, 400\]'),
    ({'rotation_rate': math.inf}, 'earth_rotation_rate must be finite'),
])
def test_bad_activity_is_refused_naming_it(kwargs, match):
    settings = {'orbit': KeplerOrbit(ORBITS[0]), 'start': START, **kwargs}
    with pytest.raises(ValueError, match=match):
        MsisAtmosphere(**settings)


def test_without_pymsis_the_model_is_refused_saying_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, 'pymsis', None)
    with pytest.raises(ValueError, match='atmosphere_model nrlmsis needs the pymsis library: '
                       'pymsis is not installed; install with pip install pymsis'):
        MsisAtmosphere(KeplerOrbit(ORBITS[0]), START)
