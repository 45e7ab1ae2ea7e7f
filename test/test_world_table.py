"""
The world table: the environment's time-only quantities over arrays, against their scalars.

The generated stages take a step's world quantities (position, field, the Sun, the
air) from :meth:`SpaceEnvironment.world_nodes`, a table computed 500 steps at a time by
:meth:`SpaceEnvironment.world_many` with numpy. Its definition is
:meth:`SpaceEnvironment.world_at`, one time at a time in pure Python. The Chebyshev sums
(the integrated orbit, IGRF, NRLMSIS) are the same operations in the same order and
must agree to the bit; the rest differs by numpy's trigonometry against the C
library's, a few units in the last place, and by the Sun, which the table interpolates
on day-long segments (5e-14 of its distance). The tolerances are those figures with a
margin of two; each test says what it measured.
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics.environment import (
    DipoleField, DragTorque, EARTH_RATE, ExponentialAtmosphere, Facets, GravityGradient,
    IgrfField, KeplerOrbit, MagneticDipole, MU_EARTH, SolarPressureTorque, SpaceEnvironment,
    Sun, TleOrbit, unix_time, ZonalOrbit)
from rigid_body_dynamics.physics.environment.atmosphere import geodetic_altitude, geodetic_heights
from rigid_body_dynamics.physics.environment.facets import box
from rigid_body_dynamics.physics.environment.shadow import sunlit_fraction, sunlit_fractions
from rigid_body_dynamics.physics.environment.space import WORLD_BLOCK
from test_environment import _environments

EPOCH = '2025-06-01T00:00:00Z'
#: The ISS on 2019-12-09 (the sgp4 library's README).
ISS = ('1 25544U 98067A   19343.69339541  .00001764  00000-0  38792-4 0  9991',
       '2 25544  51.6439 211.2001 0007417  17.6667  85.6398 15.50103472202482')
#: The order-6 step's distinct nodes, in the order the generated stages meet them.
NODES = (0.0, 1.0 / 3.0, 2.0 / 3.0, 0.5, 1.0)
#: Largest difference, relative to the column's largest value, of the table against
#: world_at: position and |r|^2 (measured 1.1e-15: the Kepler orbit's Newton iteration
#: ends a unit apart), field (3.3e-15: the dipole's turn by numpy's cosine), the Sun's
#: direction (5.2e-14: the interpolated Sun), its pressure (5.9e-11: in the penumbra the
#: fraction's slope turns the Sun's 5e-14 into that, at its edges), the flow (exact) and
#: the density (5.2e-14: numpy's exponential and the geodetic height without
#: trigonometry).
BOUNDS = {'r': 2e-15, 'rr': 2e-15, 'B': 7e-15, 's': 1.5e-13, 'P': 1.5e-10, 'f': 2e-15,
          'rho': 1.5e-13}
#: With a TLE, SGP4 over an array takes its time as a day and a fraction, rounded to
#: 1e-11 s: the position 9.5e-15 apart, the dipole field there 2.1e-14.
BOUNDS_TLE = dict(BOUNDS, r=2e-14, B=4e-14)


def _cases():
    """(name, environment): the five of test_environment, the mission model, a TLE."""
    cases = _environments()
    zonal = ZonalOrbit([6878137.0, 0.001, 1.7, 0.3, 0.0, 0.0], 2)
    surface = Facets(box((0.1, 0.1, 0.34), (0.0, 0.0, 0.02), 0.3, 0.1))
    light, air = SolarPressureTorque(surface), DragTorque(surface)
    cases.append(('mission', SpaceEnvironment(
        zonal, IgrfField(zonal, unix_time(EPOCH), 13, 0.2, EARTH_RATE),
        [GravityGradient((2.0, 3.0, 1.0), MU_EARTH), MagneticDipole((0.01, 0.0, 0.0)), light,
         air], epoch=100.0, sun=Sun(EPOCH), shadow='conical',
        atmosphere=ExponentialAtmosphere(EARTH_RATE))))
    tle = TleOrbit(*ISS)
    cases.append(('tle', SpaceEnvironment(
        tle, DipoleField(), [GravityGradient((2.0, 3.0, 1.0), tle.mu), light], sun=Sun(
            tle.start_text), shadow='cylindrical')))
    return cases


def _columns(env):
    """Return (name, first, end) of each quantity in world_at's tuple."""
    groups, at = [('r', 0, 3), ('rr', 3, 4)], 4
    for on, names in ((env._field, ('B',)), (env._sun, ('s', 'P')), (env._flow, ('f', 'rho'))):
        if on:
            groups.append((names[0], at, at + 3))
            if len(names) > 1:
                groups.append((names[1], at + 3, at + 4))
            at += 3 + (len(names) > 1)
    return groups


@pytest.mark.parametrize('case', range(7))
def test_the_table_is_world_at_over_an_orbit(case):
    """
    world_many against world_at every 0.25 s over an orbit, quantity by quantity (BOUNDS).

    The samples cross the shadow where there is a Sun (its penumbra with the conical
    model: the test checks that some fall inside it).
    """
    name, env = _cases()[case]
    times = np.arange(0.0, env.orbit.period, 0.25)
    many = env.world_many(times)
    one = np.array([env.world_at(t) for t in times])
    assert many.shape == one.shape == (times.size, env.width)
    for group, first, end in _columns(env):
        scale = np.abs(one[:, first:end]).max()
        worst = np.abs(many[:, first:end] - one[:, first:end]).max() / scale
        assert worst <= (BOUNDS_TLE if name == 'tle' else BOUNDS)[group], (name, group, worst)
    if env._sun:
        pressure = one[:, _columns(env)[-1 if not env._flow else -3][1]]
        assert (pressure == 0.0).any(), name                     # the umbra
        if env.shadow == 'conical':
            assert ((pressure > 0.0) & (pressure < 0.99 * pressure.max())).any(), name


def test_the_chebyshev_sums_over_arrays_are_the_scalar_ones_to_the_bit():
    """The integrated orbit's r and v and the IGRF field, over three segments' boundaries."""
    zonal = ZonalOrbit([6878137.0, 0.001, 1.7, 0.3, 0.0, 0.0], 2)
    field = IgrfField(zonal, unix_time(EPOCH), 13, 0.2, EARTH_RATE)
    times = np.linspace(-10.0, 3.2 * zonal.period / 16, 2001)
    r, v = zonal.states(times)
    np.testing.assert_array_equal(r, [zonal.position(t) for t in times])
    np.testing.assert_array_equal(v, [zonal.velocity(t) for t in times])
    np.testing.assert_array_equal(zonal.positions(times), r)
    np.testing.assert_array_equal(field.world_many(times), [field.world(t) for t in times])


def test_the_kepler_orbit_over_arrays_is_its_scalar_orbit(rng):
    """KeplerOrbit.positions and states of an eccentric orbit (e = 0.1) within 2e-15 of scale."""
    orbit = KeplerOrbit((7.5e6, 0.1, 1.0, 0.5, 0.3, 0.2))
    times = rng.uniform(-1e5, 1e5, 2000)
    r, v = orbit.states(times)
    one = [orbit.state(t) for t in times]
    np.testing.assert_allclose(r, [s[0] for s in one], rtol=0, atol=2e-15 * 8.25e6)
    np.testing.assert_allclose(v, [s[1] for s in one], rtol=0, atol=2e-15 * 8e3)
    np.testing.assert_allclose(orbit.positions(times), r, rtol=0, atol=2e-15 * 8.25e6)


def test_the_suns_interpolant_is_its_formula(rng):
    """Sun.positions against Sun.position over eleven days, within 1.5e-13 of the distance."""
    sun = Sun(EPOCH)
    times = rng.uniform(-1e5, 1e6, 3000)
    one = np.array([sun.position(t) for t in times])
    worst = np.max(np.linalg.norm(sun.positions(times) - one, axis=1)
                   / np.linalg.norm(one, axis=1))
    assert worst <= 1.5e-13, worst                             # measured 7.3e-14


def test_the_shadow_over_arrays_is_the_scalar_shadow(rng):
    """
    sunlit_fractions against sunlit_fraction at the same places, across the penumbra.

    Positions on a 400 km sphere around the shadow's edge (the Sun on the x axis): the
    conical fraction within 1e-13 (measured 6.3e-14), the cylinder's 0 or 1 exactly.
    """
    sun = np.tile([1.496e11, 0.0, 0.0], (4000, 1))
    angle = math.pi - math.asin(6378137.0 / 6778137.0) + rng.uniform(-0.1, 0.1, 4000)
    spin = rng.uniform(0.0, 2.0 * math.pi, 4000)
    r = 6778137.0 * np.column_stack((np.cos(angle), np.sin(angle) * np.cos(spin),
                                     np.sin(angle) * np.sin(spin)))
    for model in ('conical', 'cylindrical'):
        one = np.array([sunlit_fraction(p, s, 6378137.0, model) for p, s in zip(r, sun)])
        many = sunlit_fractions(r, sun, 6378137.0, model)
        assert ((one > 0.0) & (one < 1.0)).any() or model == 'cylindrical'
        np.testing.assert_allclose(many, one, rtol=0, atol=1e-13 if model == 'conical' else 0)


def test_the_height_and_density_over_arrays_are_the_scalar_ones(rng):
    """
    geodetic_heights within 1e-8 m from the surface to 1e7 m (measured 3.7e-9), densities.

    The densities within 2e-12 (measured 3.2e-13): the height's 3.7e-9 m over the
    lowest bands' 5.4 km scale height is 7e-13.
    """
    r = rng.normal(size=(5000, 3))
    r *= rng.uniform(6.36e6, 1e7, (5000, 1)) / np.linalg.norm(r, axis=1)[:, None]
    heights = np.array([geodetic_altitude(p) for p in r])
    assert np.abs(geodetic_heights(r) - heights).max() <= 1e-8
    air = ExponentialAtmosphere(EARTH_RATE)
    up = r[heights > 0.0]
    one = np.array([air.density(0.0, p) for p in up])
    np.testing.assert_allclose(air.densities(np.zeros(len(up)), up), one, rtol=2e-12, atol=0)


def test_world_nodes_on_the_grid_come_from_the_table_and_off_it_from_world_at():
    """
    world_nodes: a step on the grid k h reads the table; any other time is world_at's.

    On the grid its numbers are the table's (world_many of the same times: within
    BOUNDS of world_at), computed once per block of WORLD_BLOCK steps; off the grid they
    are world_at's at t + c h to the bit; world_at at a step's start reads node 0 of the
    table. A block that cannot be computed falls back to world_at node by node, so that
    its error comes at its own time.
    """
    name, env = _cases()[5]
    h = 1e-3
    calls = []
    original = env.world_many

    def counted(times):
        calls.append(len(times))
        return original(times)
    env.world_many = counted
    row = env.world_nodes(7 * h, h, NODES)
    assert calls == [WORLD_BLOCK * len(NODES)]
    one = [x for c in NODES for x in env.world_at(7 * h + c * h)]
    np.testing.assert_allclose(row, one, rtol=1e-10, atol=0)
    for k in range(8, WORLD_BLOCK):
        env.world_nodes(k * h, h, NODES)
    assert len(calls) == 1
    assert env.world_at(9 * h) == tuple(env.world_nodes(9 * h, h, NODES)[:env.width])
    off = 0.1234567
    assert tuple(env.world_nodes(off, h, NODES)) == tuple(
        x for c in NODES for x in env.world_at(off + c * h))

    def fails(times):
        raise ValueError('cannot fly there')
    env.world_many = fails
    k = 3 * WORLD_BLOCK + 1
    assert tuple(env.world_nodes(k * h, h, NODES)) == tuple(
        x for c in NODES for x in env.world_at(k * h + c * h))


def test_a_new_environment_of_the_same_world_keeps_the_table(monkeypatch):
    """
    A magnetorquer command makes the plant a new environment; its table is not computed again.

    The mission model with a dipole command every 10 steps, 1200 steps of 1 ms: the
    world is computed once per block of WORLD_BLOCK steps (three blocks), not once per
    command (120). An environment of another world (another epoch) starts its own table.
    """
    from rigid_body_dynamics.engine import BodySimulation, Disturbances
    from rigid_body_dynamics.physics import Inertia
    name, mission = _cases()[5]
    calls = []
    original = SpaceEnvironment.world_many

    def counted(self, times):
        calls.append(len(times))
        return original(self, times)
    monkeypatch.setattr(SpaceEnvironment, 'world_many', counted)
    body = BodySimulation(Inertia((2.0, 3.0, 1.2)), 'exact', 1000.0,
                          ((0.0, 0.0, 0.0, 1.0), (0.3, -0.5, 0.8)), publish_every=10,
                          disturbances=Disturbances(
                              orbit=mission.orbit, field=mission.field, gravity_gradient=True,
                              sun=mission.sun, shadow_model='conical',
                              facets=mission.models[2].facets, solar_pressure=True,
                              atmosphere=mission.atmosphere, drag=True))
    outbox = []
    with body.lock:
        for i in range(1200):
            if i % 10 == 0:
                body.plant.set_dipole((0.1 * (i % 3), 0.05, -0.02))
            body.advance(0, outbox)
    assert len(calls) == 3, calls
    other = SpaceEnvironment(mission.orbit, mission.field, mission.models, epoch=5.0,
                             sun=mission.sun, shadow='conical', atmosphere=mission.atmosphere)
    other.adopt_world(body.plant.field)
    assert other._tables == {} and other._grid is None
    again = SpaceEnvironment(mission.orbit, mission.field, mission.models,
                             epoch=body.plant.field.epoch, sun=mission.sun, shadow='conical',
                             atmosphere=mission.atmosphere)
    again.adopt_world(body.plant.field)
    assert again._tables is body.plant.field._tables
