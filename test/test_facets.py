"""
Solar radiation pressure and drag on flat facets, against closed forms.

A flat plate: the force in the plate's own frame, written from the angle of
incidence (a component along the normal and one along the surface), then turned
with the plate to random attitudes. A box: summed over its six faces, the force is
the projected area's (plus the reflected parts, face by face) and, because each
face's lever arm times its area is half the box's volume, the faces' torques about the
box's centre cancel: the torque about a centre of mass delta away is -delta x F.
Both to 1e-12 of the force (times the lever arm, for the torque), at 500 random
attitudes each; delivered under 1e-15 (8.9e-16 worst, the plate).
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics import quaternions
from rigid_body_dynamics.physics.environment.facets import (box, Facets, SOLAR_PRESSURE_1AU,
                                                            solar_pressure_at)
from scipy.spatial.transform import Rotation

P = 4.5e-6                 # N/m^2
SPECULAR, DIFFUSE = 0.3, 0.2


def _plate(theta, phi, area, specular, diffuse):
    """Return the SRP force on a plate (normal z) with the Sun at polar theta, azimuth phi."""
    cos = math.cos(theta)
    if cos <= 0.0:
        return np.zeros(3)
    normal = -P * area * cos * ((1.0 - specular) * cos + 2.0 * (specular * cos + diffuse / 3.0))
    surface = -P * area * cos * (1.0 - specular) * math.sin(theta)
    return np.array([surface * math.cos(phi), surface * math.sin(phi), normal])


def test_solar_pressure_on_a_flat_plate_at_random_attitudes():
    rng = np.random.default_rng(3)
    area, centre = 1.7, np.array([0.3, -0.2, 0.1])
    worst = 0.0
    for turn in Rotation.random(500, random_state=4):
        theta, phi = rng.uniform(0.0, math.pi), rng.uniform(-math.pi, math.pi)
        s = np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                      math.cos(theta)])
        plate = Facets([area, *turn.apply([0.0, 0.0, 1.0]), *turn.apply(centre),
                        SPECULAR, DIFFUSE, 2.2])
        force, torque = plate.solar_pressure(turn.apply(s), P)
        expected = turn.apply(_plate(theta, phi, area, SPECULAR, DIFFUSE))
        scale = P * area
        worst = max(worst, np.max(np.abs(force - expected)) / scale,
                    np.max(np.abs(torque - np.cross(turn.apply(centre), expected))) / scale)
    assert worst < 1e-12, worst


def test_solar_pressure_on_a_box_is_its_projected_area_and_minus_delta_cross_f():
    rng = np.random.default_rng(5)
    size, delta = np.array([0.1, 0.2, 0.3]), np.array([0.01, -0.02, 0.005])
    areas = np.array([size[1] * size[2], size[2] * size[0], size[0] * size[1]])
    body = Facets(box(size, delta, SPECULAR, DIFFUSE))
    assert len(body) == 6
    worst = 0.0
    for _ in range(500):
        s = rng.normal(size=3)
        s /= np.linalg.norm(s)
        force, torque = body.solar_pressure(s, P)
        expected = -P * ((1.0 - SPECULAR) * np.sum(areas * np.abs(s)) * s
                         + 2.0 * areas * (SPECULAR * s * np.abs(s) + DIFFUSE * s / 3.0))
        scale = P * areas.sum()
        worst = max(worst, np.max(np.abs(force - expected)) / scale,
                    np.max(np.abs(torque + np.cross(delta, expected)))
                    / (scale * np.linalg.norm(delta)))
    assert worst < 1e-12, worst


def test_drag_on_a_plate_and_a_box():
    rng = np.random.default_rng(6)
    density, cd = 3e-12, 2.2
    size, delta = np.array([0.1, 0.2, 0.3]), np.array([0.01, -0.02, 0.005])
    areas = np.array([size[1] * size[2], size[2] * size[0], size[0] * size[1]])
    body = Facets(box(size, delta, drag=cd))
    plate = Facets([0.5, 0.0, 0.0, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, cd])
    worst = 0.0
    for _ in range(500):
        v = rng.normal(size=3) * 7600.0
        speed = np.linalg.norm(v)
        q = 0.5 * density * speed ** 2
        u = v / speed
        force, torque = body.drag_force(v, density)
        expected = -q * cd * np.sum(areas * np.abs(u)) * u
        worst = max(worst, np.max(np.abs(force - expected)) / (q * cd * areas.sum()),
                    np.max(np.abs(torque + np.cross(delta, expected)))
                    / (q * cd * areas.sum() * np.linalg.norm(delta)))
        force, torque = plate.drag_force(v, density)
        expected = -q * cd * 0.5 * max(u[2], 0.0) * u
        worst = max(worst, np.max(np.abs(force - expected)) / (q * cd * 0.5),
                    np.max(np.abs(torque - np.cross([0.1, 0.0, 0.0], expected)))
                    / (q * cd * 0.5 * 0.1))
    assert worst < 1e-12, worst
    assert not np.any(body.drag_force((0.0, 0.0, 0.0), density)[0])


def test_the_pressure_at_1_au_and_its_inverse_square():
    assert SOLAR_PRESSURE_1AU == pytest.approx(1361.0 / 299792458.0, rel=1e-15)
    assert solar_pressure_at(149597870700.0 * 2.0, 0.5) == pytest.approx(
        SOLAR_PRESSURE_1AU / 8.0, rel=1e-15)


@pytest.mark.parametrize('values, reason', [
    ([1.0] * 9, '10 numbers per facet'),
    ([0.0, 0, 0, 1, 0, 0, 0, 0, 0, 2], 'facet 0 needs an area > 0'),
    ([1.0, 0, 0, 0, 0, 0, 0, 0, 0, 2], 'facet 0 needs a non-zero normal'),
    ([1.0, 0, 0, 1, 0, 0, 0, 0.7, 0.4, 2], 'specular, diffuse >= 0 with a sum <= 1'),
    ([1.0, 0, 0, 1, 0, 0, 0, 0, 0, -1], 'a drag coefficient >= 0'),
    ([1.0, 0, 0, 1, 0, 0, 0, 0, 0, 2, 1.0, 0, 0, 1, 0, math.nan, 0, 0, 0, 2],
     'facet 1 has a non-finite number'),
    (['a'] * 10, 'facets must be numbers'),
])
def test_bad_facets_are_refused_naming_the_facet(values, reason):
    with pytest.raises(ValueError, match=reason):
        Facets(values)


def test_the_solar_pressure_torque_is_zero_in_umbra_and_scaled_in_the_penumbra():
    """
    The SolarPressureTorque in a SpaceEnvironment (its stage statements) at three places.

    A 400 km circular orbit with the Sun 1 au along x: in sunlight, half-way through the
    penumbra (the conical fraction there) and in umbra. Against the facets' own force with
    the pressure 1361 W/m^2 / c (au / d)^2 times the fraction, d and the direction to the
    Sun taken from the body (not the Earth's centre), to 1e-14; exactly zero in umbra.
    """
    from rigid_body_dynamics.physics.environment import (circular_elements, KeplerOrbit,
                                                         R_EARTH, SolarPressureTorque,
                                                         SpaceEnvironment, Sun)
    from rigid_body_dynamics.physics.environment.shadow import conical_shadow_fraction
    from scipy.optimize import brentq
    surface = Facets(box((0.1, 0.2, 0.3), (0.01, -0.02, 0.005), SPECULAR, DIFFUSE))
    orbit = KeplerOrbit(circular_elements(400e3))
    env = SpaceEnvironment(orbit, None, [SolarPressureTorque(surface)],
                           sun=Sun(fixed=(1.0, 0.0, 0.0)), shadow='conical')
    assert env.stage_code is not None and env.stage_code.sun
    sun = np.array([149597870700.0, 0.0, 0.0])
    light = lambda t: conical_shadow_fraction(orbit.position(t), sun, R_EARTH)  # noqa: E731
    half = brentq(lambda t: light(t) - 0.5, 0.2 * orbit.period, 0.5 * orbit.period)
    q = Rotation.from_euler('xyz', [0.3, -0.4, 1.1])
    for t, fraction in ((0.0, 1.0), (half, 0.5), (0.5 * orbit.period, 0.0)):
        r = np.array(orbit.position(t))
        to_sun = sun - r
        d = np.linalg.norm(to_sun)
        pressure = 1361.0 / 299792458.0 * (149597870700.0 / d) ** 2 * light(t)
        assert light(t) == pytest.approx(fraction, abs=1e-12)
        _, expected = surface.solar_pressure(q.inv().apply(to_sun / d), pressure)
        got = np.array(env(t, *q.as_quat()))
        if fraction == 0.0:
            assert not np.any(got)
        else:
            assert np.max(np.abs(got - expected)) < 1e-14 * np.linalg.norm(expected), t
            assert np.linalg.norm(expected) > 1e-10


#: The engine runs under one torque each: (name, tolerance (rad, and relative), the least
#: change of omega the torque makes (rad/s)).
ENGINE_CASES = [('solar pressure', 1.5e-12, 1e-7), ('drag', 2e-12, 1e-4),
                ('drag nrlmsis', 2e-12, 1e-4)]


@pytest.mark.parametrize('case, tol, moved', ENGINE_CASES)
def test_a_body_under_the_surface_torques_through_the_engine_against_an_independent_dop853(
        case, tol, moved):
    """
    A slow tumble into the Earth's shadow, its inertia off the body axes, through BodySimulation.

    A 1 x 2 x 0.5 m box, its centre of mass 0.2 m off centre, on a 420 km equatorial
    circular orbit half-way through the conical shadow's penumbra at 15 s, 30 s in all
    (sunlight, penumbra, umbra) at 1 ms steps. The reference integrates Euler's
    equations with the full body-frame tensor (no principal axes) by DOP853 at rtol
    2.5e-14 from kink to kink (``reference.dop853_through_kinks``: a facet pair turning to the
    Sun or the flow, the penumbra's two edges; stepping across them, the reference
    itself was off by up to 2e-12, by where its steps fell), with the torque from the
    facets' own force: the Sun's light at the Sun's direction from the body, the
    pressure written here (1361 W/m^2 / c (au / d)^2 times
    the conical fraction; about 2e-6 N m); or the air at v - omega_E x r, the density
    written here from Vallado's 400 km band (3.725e-12 kg/m^3, H = 58.515 km; about
    1e-4 N m), or with atmosphere nrlmsis NRLMSIS 2.1's density along the orbit (its
    interpolant, the density the stages are given: test_msis_atmosphere holds it to the
    model). Attitude and omega every 0.1 s within ``tol`` (rad, and relative):
    delivered 8.8e-13 and 8.4e-13 under the light, 5.8e-13 and 8.7e-13 under drag
    (5.2e-13 and 6.7e-13 with NRLMSIS). The engine's
    error is made where a facet turns into the light or the flow: a kink in the torque
    which the fixed step does not stop at, of order dt^2 times the jump in the torque's
    rate. (At 400 km, the base of one of Vallado's bands, the altitude's round-off
    switched bands, the density by 3.6e-6 of itself: 3e-9 of omega over 30 s.) The
    torque moved omega by far more than the tolerance.
    """
    from rigid_body_dynamics.engine import BodySimulation, Disturbances
    from rigid_body_dynamics.physics.environment import (circular_elements,
                                                         ExponentialAtmosphere, KeplerOrbit,
                                                         R_EARTH, Sun)
    from rigid_body_dynamics.physics.environment.shadow import conical_shadow_fraction
    from rigid_body_dynamics.physics.inertia import Inertia
    from rigid_body_dynamics.physics.dynamics.reference import dop853_through_kinks
    from scipy.optimize import brentq
    au, sun = 149597870700.0, np.array([149597870700.0, 0.0, 0.0])
    earth_rate = 7.2921150e-5
    probe = KeplerOrbit(circular_elements(420e3))
    half = brentq(lambda t: conical_shadow_fraction(probe.position(t), sun, R_EARTH) - 0.5,
                  0.2 * probe.period, 0.5 * probe.period)
    orbit = KeplerOrbit(circular_elements(420e3, anomaly=probe.n * (half - 15.0)))
    if case == 'drag nrlmsis':
        pytest.importorskip('pymsis', reason='atmosphere_model nrlmsis needs pymsis')
        from rigid_body_dynamics.physics.environment import MsisAtmosphere
        air = MsisAtmosphere(orbit, 1.80e9, 180.0, 160.0, 12.0, 1.1, earth_rate)
    else:
        air = ExponentialAtmosphere(earth_rate)
    tensor = np.array([[2.0, 0.1, -0.05], [0.1, 2.5, 0.2], [-0.05, 0.2, 1.5]])
    surface = box((1.0, 2.0, 0.5), (0.2, -0.1, 0.05), SPECULAR, DIFFUSE)
    facets = Facets(surface)
    q0 = np.array(Rotation.from_euler('xyz', [0.4, -0.3, 0.8]).as_quat())
    w0 = np.array([0.02, -0.03, 0.05])
    seconds, dt = 30.0, 1e-3

    def run(on):
        acting = {'solar_pressure': on} if case == 'solar pressure' else {'drag': on}
        body = BodySimulation(Inertia.from_tensor(tensor), 'exact', 1.0 / dt, (q0, w0),
                              torque_timeout=0.0, publish_every=100,
                              disturbances=Disturbances(
                                  orbit=orbit, sun=Sun(fixed=(1, 0, 0)), shadow_model='conical',
                                  facets=facets, atmosphere=air,
                                  **acting))
        outbox = []
        with body.lock:
            for _ in range(round(seconds / dt)):
                body.advance(0, outbox)
        inertia = body.inertia
        return ([inertia.attitude_to_body(np.array(s.q_principal)) for s in outbox],
                [inertia.to_body(np.array(s.omega_principal)) for s in outbox])

    inverse = np.linalg.inv(tensor)

    def torque(t, turn):
        r, v = (np.array(x) for x in orbit.state(t))
        if case == 'drag nrlmsis':
            density = air.density(t, r)
        if case == 'drag':
            density = 3.725e-12 * math.exp(-(np.linalg.norm(r) - 6378137.0 - 400e3) / 58515.0)
        if case.startswith('drag'):
            flow = v - np.cross([0.0, 0.0, earth_rate], r)
            return facets.drag_force(turn.inv().apply(flow), density)[1]
        to_sun = sun - r
        d = np.linalg.norm(to_sun)
        light = conical_shadow_fraction(r, sun, R_EARTH)
        pressure = 1361.0 / 299792458.0 * (au / d) ** 2 * light
        return facets.solar_pressure(turn.inv().apply(to_sun / d), pressure)[1]

    def rate(t, y):
        q, w = y[:4] / np.linalg.norm(y[:4]), y[4:]
        x, y_, z, s = q
        dq = 0.5 * np.array([s * w[0] + y_ * w[2] - z * w[1], s * w[1] + z * w[0] - x * w[2],
                             s * w[2] + x * w[1] - y_ * w[0], -x * w[0] - y_ * w[1] - z * w[2]])
        tau = torque(t, Rotation.from_quat(q))
        return np.r_[dq, inverse @ (tau - np.cross(w, tensor @ w))]

    def facing(axis):
        """Return the event of a box's facet pair turning to the Sun or the flow."""
        def event(t, y):
            r, v = (np.array(x) for x in orbit.state(t))
            along = v - np.cross([0.0, 0.0, earth_rate], r) if case.startswith('drag') \
                else sun - r
            return Rotation.from_quat(y[:4] / np.linalg.norm(y[:4])).inv().apply(along)[axis]
        return event

    def contact(edge):
        """Return the event of the body at the penumbra's outer (0) or inner (1) edge."""
        def event(t, y):
            r = np.array(orbit.position(t))
            c = math.acos(np.dot(-r, sun - r) / (np.linalg.norm(r) * np.linalg.norm(sun - r)))
            a = math.asin(6.957e8 / np.linalg.norm(sun - r))
            b = math.asin(R_EARTH / np.linalg.norm(r))
            return c - (a + b if edge == 0 else b - a)
        return event

    times = np.arange(1, round(seconds / 0.1) + 1) * 0.1
    kinks = [facing(k) for k in range(3)] + ([contact(0), contact(1)] if case == 'solar pressure'
                                             else [])
    ref = dop853_through_kinks(rate, np.r_[q0, w0], seconds, times, kinks)
    qs, ws = run(True)
    assert len(qs) == len(times)
    worst_q = max(quaternions.angle_between(q, r / np.linalg.norm(r))
                  for q, r in zip(qs, ref[:, :4]))
    worst_w = max(np.linalg.norm(w - r) / np.linalg.norm(r) for w, r in zip(ws, ref[:, 4:]))
    assert worst_q < tol and worst_w < tol, (worst_q, worst_w)
    _, free = run(False)
    assert np.linalg.norm(free[-1] - ws[-1]) > moved
