"""
The space environment (physics/environment) against closed forms and an independent DOP853.

The Kepler orbit against the two-body ODE and the conic's invariants, the LVLH
frame, the dipole field against its formula in the Earth-fixed frame, the
torque models against numpy, the whole model (orbit, gravity gradient, field,
residual dipole, magnetorquer commands held) through the engine against
physics.dynamics.reference's DOP853 of the same physics written apart, and the
gravity-gradient pitch libration against its theory.
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.engine import BodySimulation, Disturbances
from rigid_body_dynamics.engine.commands import DipoleCommands
from rigid_body_dynamics.physics import Inertia, make_integrator, quaternions
from rigid_body_dynamics.physics.analysis import estimators
from rigid_body_dynamics.physics.dynamics.reference import space_zoh_reference
from rigid_body_dynamics.physics.environment import (
    circular_elements, DipoleField, GravityGradient, KeplerOrbit, lvlh_axes, lvlh_quaternion,
    MagneticDipole, MU_EARTH, SpaceEnvironment)
from rigid_body_dynamics.physics.sensors import Magnetometer
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

ELEMENTS = (7.5e6, 0.1, 1.0, 0.5, 0.3, 0.2)       # a 1.8 h orbit, perigee 373 km up


def test_kepler_orbit_against_the_two_body_ode_over_ten_orbits():
    """
    Position within 3e-11 of |r| of a DOP853 of r'' = -mu r / |r|^3 over ten orbits.

    Delivered 9e-12 (the reference's own error at rtol 1e-13); after ten whole periods the
    orbit is back within 3e-14 of its radius (delivered 6e-15).
    """
    orbit = KeplerOrbit(ELEMENTS)
    r0, v0 = orbit.state(0.0)
    times = np.linspace(0.0, 10 * orbit.period, 41)
    sol = solve_ivp(lambda _t, y: np.r_[y[3:], -MU_EARTH * y[:3] / np.linalg.norm(y[:3]) ** 3],
                    (0.0, times[-1]), np.r_[r0, v0], method='DOP853', t_eval=times,
                    rtol=1e-13, atol=1e-7)
    worst = max(np.linalg.norm(np.subtract(orbit.position(t), sol.y[:3, k])) / np.linalg.norm(
        sol.y[:3, k]) for k, t in enumerate(times))
    assert worst < 3e-11, worst
    # after a whole number of periods the orbit is back, to round-off
    np.testing.assert_allclose(orbit.state(10 * orbit.period)[0], r0, rtol=0, atol=3e-14 * 7.5e6)


def test_kepler_orbit_keeps_the_conic_and_its_invariants_at_any_time(rng):
    """|r| = p / (1 + e cos nu), energy -mu / 2a, h = sqrt(mu p) along the normal, to 1e-14."""
    orbit = KeplerOrbit(ELEMENTS)
    a, e = ELEMENTS[:2]
    p = a * (1 - e * e)
    normal = Rotation.from_euler('ZXZ', [ELEMENTS[3], ELEMENTS[2], ELEMENTS[4]]).apply(
        [0.0, 0.0, 1.0])
    for t in rng.uniform(0.0, 1e7, 50):
        r, v = np.array(orbit.state(t)[0]), np.array(orbit.state(t)[1])
        rn = np.linalg.norm(r)
        assert (0.5 * v @ v - MU_EARTH / rn) == pytest.approx(-MU_EARTH / (2 * a), rel=1e-13)
        np.testing.assert_allclose(np.cross(r, v), math.sqrt(MU_EARTH * p) * normal, rtol=0,
                                   atol=1e-13 * math.sqrt(MU_EARTH * p))
        big = orbit.eccentric_anomaly(t)
        nu = 2 * math.atan2(math.sqrt(1 + e) * math.sin(big / 2),
                            math.sqrt(1 - e) * math.cos(big / 2))
        assert rn == pytest.approx(p / (1 + e * math.cos(nu)), rel=1e-14)
    # the elements at t = 0: the true anomaly nu0 in the perifocal frame, turned by scipy
    nu0 = ELEMENTS[5]
    perifocal = p / (1 + e * math.cos(nu0)) * np.array([math.cos(nu0), math.sin(nu0), 0.0])
    turn = Rotation.from_euler('ZXZ', [ELEMENTS[3], ELEMENTS[2], ELEMENTS[4]])
    np.testing.assert_allclose(orbit.position(0.0), turn.apply(perifocal), rtol=0, atol=1e-8)


def test_a_circular_orbit_turns_at_its_mean_motion():
    orbit = KeplerOrbit(circular_elements(500e3, inclination=math.pi / 2))
    n = math.sqrt(MU_EARTH / orbit.a ** 3)
    r0 = np.array(orbit.position(0.0))
    r1 = np.array(orbit.position(0.25 * 2 * math.pi / n))
    assert r0 @ r1 == pytest.approx(0.0, abs=1e-8 * orbit.a ** 2)
    assert np.linalg.norm(r1) == pytest.approx(orbit.a, rel=1e-15)
    assert r1[2] == pytest.approx(orbit.a, rel=1e-14)        # polar: over the pole


@pytest.mark.parametrize('elements, mu, match', [
    ((7e6, 1.0, 0, 0, 0, 0), MU_EARTH, 'eccentricity'),
    ((7e6, -0.1, 0, 0, 0, 0), MU_EARTH, 'eccentricity'),
    ((-7e6, 0.1, 0, 0, 0, 0), MU_EARTH, 'semi-major axis'),
    ((6.5e6, 0.1, 0, 0, 0, 0), MU_EARTH, 'perigee radius'),
    ((7e6, 0.0, float('nan'), 0, 0, 0), MU_EARTH, 'six finite numbers'),
    ((7e6, 0.0, 0, 0, 0), MU_EARTH, 'six finite numbers'),
    ((7e6, 0.0, 0, 0, 0, 0), 0.0, 'orbit_mu'),
])
def test_bad_orbits_are_refused_naming_the_parameter(elements, mu, match):
    with pytest.raises(ValueError, match=match):
        KeplerOrbit(elements, mu=mu)


def test_lvlh_axes_and_quaternion(rng):
    orbit = KeplerOrbit(ELEMENTS)
    for t in rng.uniform(0.0, 1e5, 20):
        r, v = orbit.state(t)
        x, y, z = (np.array(a) for a in lvlh_axes(r, v))
        np.testing.assert_allclose(np.c_[x, y, z].T @ np.c_[x, y, z], np.eye(3), atol=1e-15)
        np.testing.assert_allclose(z, -np.array(r) / np.linalg.norm(r), atol=1e-15)
        np.testing.assert_allclose(np.cross(x, y), z, atol=1e-15)
        assert np.dot(y, orbit.normal) == pytest.approx(-1.0, abs=1e-14)
        q = lvlh_quaternion(r, v)
        expected = Rotation.from_matrix(np.c_[x, y, z]).as_quat()
        assert quaternions.angle_between(np.array(q), expected) < 1e-14


def test_the_dipole_field_against_its_formula_in_the_earth_fixed_frame(rng):
    field = DipoleField(rotation_angle=0.7)
    g10, g11, h11 = -29404.8e-9, -1450.9e-9, 4652.5e-9
    d = np.array([g11, h11, g10])
    for _ in range(20):
        t = rng.uniform(0.0, 1e5)
        r = rng.normal(size=3) * 7e6
        to_fixed = Rotation.from_euler('z', -(0.7 + 7.2921150e-5 * t))
        r_f = to_fixed.apply(r)
        rn = np.linalg.norm(r_f)
        b_f = (6371.2e3 / rn) ** 3 * (3 * (d @ r_f) / rn * r_f / rn - d)
        np.testing.assert_allclose(field.world(t, r), to_fixed.inv().apply(b_f), rtol=0,
                                   atol=1e-14 * np.linalg.norm(b_f))
    # on the dipole's axis at the reference radius: B = 2 d; on its equator: -d
    axis = d / np.linalg.norm(d) * 6371.2e3
    np.testing.assert_allclose(DipoleField(rotation_angle=0.0).world(0.0, axis), 2 * d,
                               rtol=1e-14)
    with pytest.raises(ValueError, match='magnetic_dipole_coefficients'):
        DipoleField((1.0, float('inf'), 0.0))


def test_the_torque_models_against_numpy(rng):
    moments = (2.0, 3.0, 1.0)
    orbit, field = KeplerOrbit(ELEMENTS), DipoleField()
    m = (0.3, -0.1, 0.2)
    env = SpaceEnvironment(orbit, field, [GravityGradient(moments, MU_EARTH), MagneticDipole(m)])
    for _ in range(20):
        q, w, t = rng.normal(size=4), rng.normal(size=3), rng.uniform(0.0, 1e4)
        rot = Rotation.from_quat(q)
        r = np.array(orbit.position(t))
        r_b, b_b = rot.inv().apply(r), rot.inv().apply(field.world(t, r))
        expected = 3 * MU_EARTH / np.linalg.norm(r) ** 5 * np.cross(r_b, np.diag(moments) @ r_b) \
            + np.cross(m, b_b)
        np.testing.assert_allclose(env(t, *(1.3 * q), *w), expected, rtol=0,
                                   atol=1e-13 * np.linalg.norm(expected))
    with pytest.raises(ValueError, match='orbit'):
        SpaceEnvironment(None, None, [GravityGradient(moments, MU_EARTH)])
    with pytest.raises(ValueError, match='magnetic field'):
        SpaceEnvironment(orbit, None, [MagneticDipole(m)])


class _Drag:
    """A torque model without stage statements: a damping torque -c omega (N m)."""

    needs = frozenset()

    def __init__(self, c):
        self.c = c

    def torque(self, t, r, q, omega, env):
        """Return -c omega (N m, principal frame)."""
        return tuple(-self.c * w for w in omega)


def _environments():
    """(name, the environment, a state) cases: the models alone and together, two orbits."""
    moments = (2.0, 3.0, 1.0)
    eccentric, circular = KeplerOrbit(ELEMENTS), KeplerOrbit(circular_elements(5e5, 0.9))
    gravity = GravityGradient(moments, MU_EARTH)
    dipole = MagneticDipole((0.3, -0.1, 0.2))
    # a box with its centre of mass off its centre, in sunlight and the conical shadow; in
    # the air at 300 km (drag 30 times the light's torque), without a field
    from rigid_body_dynamics.physics.environment import (DragTorque, ExponentialAtmosphere,
                                                         SolarPressureTorque, Sun)
    from rigid_body_dynamics.physics.environment.facets import box, Facets
    surface = Facets(box((0.1, 0.2, 0.3), (0.01, -0.02, 0.005), 0.3, 0.2))
    srp, drag = SolarPressureTorque(surface), DragTorque(surface)
    return [('gravity gradient', SpaceEnvironment(eccentric, None, [gravity], epoch=30.0)),
            ('dipole', SpaceEnvironment(circular, DipoleField(), [dipole])),
            ('both', SpaceEnvironment(eccentric, DipoleField(rotation_angle=0.4),
                                      [gravity, dipole], epoch=1e4)),
            ('solar pressure', SpaceEnvironment(
                circular, DipoleField(), [gravity, srp, dipole], epoch=2e3,
                sun=Sun('2026-03-20T12:00:00Z'), shadow='conical')),
            ('drag', SpaceEnvironment(
                KeplerOrbit(circular_elements(3e5, 0.9)), None, [drag, srp], epoch=5e3,
                sun=Sun('2026-03-20T12:00:00Z'), atmosphere=ExponentialAtmosphere(7.29e-5)))]


@pytest.mark.parametrize('case', range(5))
def test_the_stage_statements_give_each_models_own_torque(rng, case):
    """
    The statements the integrators put into their stages give what the models' torque() does.

    SpaceEnvironment's call (the compiled statements) against torque_of_models (each
    model's torque(), the definition) at 50 random states, the attitude not unit (as
    inside a step), within 4e-15 of the torque's size.
    """
    name, env = _environments()[case]
    assert env.stage_code is not None, name
    for _ in range(50):
        q, w, t = 1.3 * rng.normal(size=4), rng.normal(size=3), rng.uniform(0.0, 1e4)
        expected = np.array(env.torque_of_models(t, *q, *w))
        np.testing.assert_allclose(env(t, *q, *w), expected, rtol=0,
                                   atol=4e-15 * np.linalg.norm(expected))


@pytest.mark.parametrize('case', range(5))
@pytest.mark.parametrize('integrator', ['exact', 'rk4', 'wheels exact', 'wheels rk4'])
def test_a_step_with_the_environment_in_its_stages_is_the_step_that_calls_the_models(
        case, integrator):
    """
    The generated stages with the environment in them against the stages that call it.

    The same environment twice, once with its stage statements and once made to call the
    models at each stage (stages=False), 2000 steps of 1 ms under a held body torque
    (the body alone and with four friction wheels spinning and driven): attitude and
    angular velocity agree within 1e-13 (the torques agree to round-off, see above; the
    exact integrator switches to order 8 with the wheels' momentum).
    """
    from rigid_body_dynamics.physics.dynamics.gyrostat import GyrostatIntegrator, Wheels
    name, inlined = _environments()[case]
    called = SpaceEnvironment(inlined.orbit, inlined.field, inlined.models, inlined.epoch,
                              stages=False, sun=inlined.sun, shadow=inlined.shadow,
                              atmosphere=inlined.atmosphere)
    q0, w0 = quaternions.normalize(np.array([0.1, 0.2, -0.3, 0.9])), (0.3, -0.5, 0.8)
    wheels = Wheels([c / math.sqrt(3.0) for g in ((1, 1, 1), (-1, 1, 1), (-1, -1, 1), (1, -1, 1))
                     for c in g], (0.01,) * 4, coulomb=(1e-4,) * 4, viscous=(1e-6,) * 4)
    states = []
    for env in (inlined, called):
        if integrator.startswith('wheels'):
            body = GyrostatIntegrator((2.0, 3.0, 1.0), wheels, 1e-3, q0, w0, (40.0, -25.0, 10.0,
                                      0.5), method=integrator.split()[1])
            body.command_motors((0.01, -0.02, 0.005, 0.0))
        else:
            body = make_integrator(integrator, (2.0, 3.0, 1.0), 1e-3, q0, w0)
        for _ in range(2000):
            body.step((1e-3, 0.0, -2e-3), None, env)
        states.append(np.r_[body.q, body.omega])
    np.testing.assert_allclose(states[0], states[1], rtol=0, atol=1e-13)
    # the body moved, and the environment acted: without it the state is far off
    plain = make_integrator('rk4', (2.0, 3.0, 1.0), 1e-3, q0, w0)
    for _ in range(2000 if not integrator.startswith('wheels') else 0):
        plain.step((1e-3, 0.0, -2e-3))
    if not integrator.startswith('wheels'):
        assert np.abs(np.r_[plain.q, plain.omega] - states[0]).max() > 1e-9


def test_a_model_without_stage_statements_is_called_at_every_stage():
    """
    A torque model with torque() alone is still integrated, to the method's order.

    A damping torque -c omega (no stage_source) beside the gravity gradient: the
    environment has no stage statements and the integrators call it at each stage. On a
    body with I1 = I2 = I3 the damping alone decays omega as exp(-c t / I) (the gradient
    off: no orbit needed). Also: a stage_source whose constants do not carry its prefix is
    refused.
    """
    env = SpaceEnvironment(None, None, [_Drag(0.2)])
    assert env.stage_code is None
    body = make_integrator('exact', (1.5, 1.5, 1.5), 1e-2, (0.0, 0.0, 0.0, 1.0), (0.3, -0.2, 0.1))
    for _ in range(300):
        body.step((0.0, 0.0, 0.0), None, env)
    np.testing.assert_allclose(body.omega, np.array([0.3, -0.2, 0.1]) * math.exp(-0.2 * 3.0 / 1.5),
                               rtol=1e-13)

    class Bad(MagneticDipole):
        def stage_source(self, p):
            return {'x': 1.0}, [], ('0.0', '0.0', '0.0')
    with pytest.raises(ValueError, match='does not start with'):
        SpaceEnvironment(KeplerOrbit(ELEMENTS), DipoleField(), [Bad((1.0, 0.0, 0.0))])


MOMENTS = (2.0, 3.0, 1.0)
#: The references' constants, written here from their sources, not read from the package:
#: IGRF-13's 2020 dipole g10, g11, h11 (nT) and reference radius 6371.2 km (Alken et al.,
#: Earth, Planets and Space 73, 2021), the Earth's rotation rate (IERS, rad/s), the field's
#: angle at t = 0 the runs give DipoleField (0.4 rad), and the Earth's GM (IERS 2010, m^3/s^2).
REFERENCE_FIELD = (-29404.8, -1450.9, 4652.5, 6371.2e3, 7.2921150e-5, 0.4)
EARTH_MU = 3.986004418e14
BOX = (0.05, 0.02, 0.03)    # magnetorquer limits (A m^2 per body axis) of the whole-model run


def _dipole_schedule(k):
    """Return a magnetorquer command per 0.1 s (A m^2, body), some over the limits of BOX."""
    return (0.08 * math.sin(0.7 * k), 0.015 * math.cos(0.3 * k), -0.04 + 0.01 * (k % 5))


def _whole_model_run(dt, seconds):
    """Run the engine under the whole model and a dipole schedule: (body, states, ref)."""
    orbit, field = KeplerOrbit(ELEMENTS), DipoleField(rotation_angle=0.4)
    residual = (0.002, -0.001, 0.003)
    q0, w0 = quaternions.normalize(np.array([0.1, 0.2, -0.3, 0.9])), (0.4, -0.7, 1.1)
    body = BodySimulation(Inertia(MOMENTS), 'exact', 1.0 / dt, (q0, w0), torque_timeout=0.0,
                          publish_every=round(0.1 / dt),
                          disturbances=Disturbances(orbit=orbit, field=field,
                                                    gravity_gradient=True,
                                                    residual_dipole=residual),
                          magnetorquers=BOX)
    holds, per = round(seconds / 0.1), round(0.1 / dt)
    outbox = []
    with body.lock:
        for k in range(holds):
            body.hold(body.check(DipoleCommands.one(_dipole_schedule(k), 0)), 0, 1)
            for _ in range(per):
                body.advance(0, outbox)

    def clipped(k, _q, _w):
        return tuple(max(-b, min(b, c)) for c, b in zip(_dipole_schedule(k), BOX))
    r0, v0 = orbit.state(0.0)
    ref = space_zoh_reference(MOMENTS, EARTH_MU, r0, v0, q0, w0, 0.1, holds, clipped,
                              field=REFERENCE_FIELD, residual=residual)
    return body, outbox, ref


@pytest.mark.parametrize('dt, seconds, tol', [(0.001, 5.0, 1e-13), (0.01, 50.0, 5e-13)])
def test_the_whole_model_through_the_engine_against_an_independent_dop853(dt, seconds, tol):
    """
    Orbit, gravity gradient, dipole field, residual dipole and held magnetorquer commands.

    A tumbling body (|omega| 1.4 rad/s) for 500 commands of 0.1 s: attitude and omega at
    every 0.1 s within ``tol`` (rad, and relative) of DOP853 at rtol 2.5e-14, the position
    within 1e-14 relative (the reference integrates the orbit as an ODE). Delivered at 1 ms
    steps 2.6e-14 rad and 3.0e-14 relative, at 10 ms 1.9e-13 and 4.7e-14; the position
    7e-16 and 2.4e-15.
    """
    body, outbox, (q_ref, w_ref, r_ref) = _whole_model_run(dt, seconds)
    states = outbox
    assert len(states) == len(q_ref) - 1
    worst_q = max(quaternions.angle_between(np.array(s.q_principal), q)
                  for s, q in zip(states, q_ref[1:]))
    worst_w = max(np.linalg.norm(np.subtract(s.omega_principal, w)) / np.linalg.norm(w)
                  for s, w in zip(states, w_ref[1:]))
    worst_r = max(np.linalg.norm(np.subtract(s.position[0], r)) / np.linalg.norm(r)
                  for s, r in zip(states, r_ref[1:]))
    assert worst_q < tol and worst_w < tol and worst_r < 1e-14, (worst_q, worst_w, worst_r)
    # the magnetic torque is not negligible: omega moved by far more than the tolerance
    assert np.linalg.norm(np.subtract(w_ref[-1], w_ref[0])) > 1e-6
    # the commands over the limits were clipped per axis and counted, the dipole applied
    assert body.dipole_counts['clipped'] > 0 and body.dipole_counts['accepted'] == len(q_ref) - 1
    assert states[-1].dipole == tuple(max(-b, min(b, c)) for c, b in
                                      zip(_dipole_schedule(len(q_ref) - 2), BOX))


def test_magnetorquer_commands_refused_held_and_timed_out():
    orbit, field = KeplerOrbit(ELEMENTS), DipoleField()
    body = BodySimulation(Inertia(MOMENTS), 'exact', 1000.0, ((0, 0, 0, 1), (0.1, 0.0, 0.0)),
                          torque_timeout=0.05, publish_every=10,
                          disturbances=Disturbances(orbit=orbit, field=field),
                          magnetorquers=(0.0, 0.0, 0.0))
    with body.lock:
        events = body.hold(body.check(DipoleCommands.one((float('nan'), 0.0, 0.0), 0)), 0, 1)
        assert events == {'dipole_rejected_non_finite'} and body.dipole_held is None
        body.hold(body.check(DipoleCommands.one((1e3, 0.0, 0.0), 0)), 0, 1)   # 0 = no limit
        assert body.dipole_held[0] == (1e3, 0.0, 0.0)
        outbox = []
        body.advance(10 ** 6, outbox)                  # within the timeout: held
        assert body.plant.field is not None and body.snapshot().dipole == (1e3, 0.0, 0.0)
        body.advance(60 * 10 ** 6, outbox)             # 60 ms later: timed out, zero, free
        assert body.snapshot().dipole == (0.0, 0.0, 0.0) and body.plant.field is None
        assert any('magnetorquer command timed out' in n for n in body.take_notes())
    assert body.dipole_counts == {'accepted': 1, 'rejected_non_finite': 1, 'rejected_frame': 0,
                                  'clipped': 0, 'stale': 0}


def test_pitch_libration_frequency_is_n_sqrt_3_ix_minus_iz_over_iy():
    """
    Principal axes on LVLH (z nadir, y minus the orbit normal), turning at n, pitched 0.01 rad.

    The pitch angle oscillates at omega_p = n sqrt(3 (Ix - Iz) / Iy) (Wie, section 6.3);
    the amplitude correction at 0.01 rad is about theta0^2 / 4 = 2.5e-5, so the measured
    period is within 1e-4 of the small-angle one. Moments (2, 3, 0.5) (the Lagrange region)
    put omega_p at 1.22 n, away from the orbit rate, so that no motion at the orbit's own
    period passes for the libration (at (2, 3, 1) omega_p would be n itself).
    """
    moments = (2.0, 3.0, 0.5)
    orbit = KeplerOrbit(circular_elements(500e3))
    n = orbit.n
    env = SpaceEnvironment(orbit, None, [GravityGradient(moments, MU_EARTH)])
    r, v = orbit.state(0.0)
    lvlh = Rotation.from_quat(lvlh_quaternion(r, v))
    start = lvlh * Rotation.from_rotvec([0.0, 0.01, 0.0])
    body = make_integrator('exact', moments, 1.0, start.as_quat(), (0.0, -n, 0.0))
    omega_p = n * math.sqrt(3.0 * (moments[0] - moments[2]) / moments[1])
    steps = int(3.2 * 2 * math.pi / omega_p)
    t, pitch = np.empty(steps + 1), np.empty(steps + 1)
    for k in range(steps + 1):
        r, v = orbit.state(body.time)
        rel = Rotation.from_quat(lvlh_quaternion(r, v)).inv() * Rotation.from_quat(body.q)
        t[k], pitch[k] = body.time, rel.as_rotvec()[1]
        body.step((0.0, 0.0, 0.0), None, env)
    assert np.max(np.abs(pitch)) == pytest.approx(0.01, rel=1e-3)     # stays librating
    crossings = estimators.crossing_times(t, pitch, direction=0)
    period = 2.0 * np.mean(np.diff(crossings))
    assert period == pytest.approx(2 * math.pi / omega_p, rel=1e-4)


def test_rk4_under_the_environment_is_fourth_order():
    """Halving the step divides rk4's error by 16 (14-18): the torques are not held per step."""
    orbit = KeplerOrbit((1.0, 0.0, 0.3, 0.0, 0.0, 0.0), mu=0.25, planet_radius=0.0)  # n 0.5
    env = SpaceEnvironment(orbit, None, [GravityGradient(MOMENTS, 0.25)])
    q0, w0 = quaternions.normalize(np.array([0.1, 0.2, -0.3, 0.9])), (0.4, -0.7, 1.1)

    def error(dt):
        exact, rk4 = (make_integrator(name, MOMENTS, dt, q0, w0) for name in ('exact', 'rk4'))
        for _ in range(round(4.0 / dt)):
            exact.step((0.0, 0.0, 0.0), None, env)
            rk4.step((0.0, 0.0, 0.0), None, env)
        return quaternions.angle_between(np.array(rk4.q), np.array(exact.q))
    assert 14.0 < error(0.02) / error(0.01) < 18.0


def test_bdot_detumbles_a_3u_cubesat_in_a_polar_orbit_within_an_orbit():
    """
    Detumble a 3U CubeSat with B-dot from 10 deg/s within an orbit.

    I = (0.033, 0.033, 0.007) kg m^2 at 10 deg/s, 500 km polar orbit, 0.2 A m^2 rods, B-dot
    k = 1e5 A m^2 s / T at 1 Hz: below 0.5 deg/s within one orbit (5677 s),
    the dipole saturates at the rods' limit while the rate is high, and |omega| falls over
    every 100 s while it is above 3 deg/s (B-dot's power is -k |omega x B|^2 <= 0 up to the
    field's own turn along the orbit, which matters more as the rate falls: below about
    1 deg/s the rate wobbles on its way down).
    """
    from rigid_body_dynamics.engine.offline import detumble
    from rigid_body_dynamics.physics.control import BDot
    orbit = KeplerOrbit(circular_elements(500e3, inclination=math.pi / 2))
    moments = (0.033, 0.033, 0.007)
    w0 = tuple(math.radians(10.0 / math.sqrt(3.0)) for _ in range(3))
    body = BodySimulation(Inertia(moments), 'exact', 10.0, ((0.0, 0.0, 0.0, 1.0), w0),
                          torque_timeout=0.0, publish_every=10,
                          disturbances=Disturbances(orbit=orbit, field=DipoleField(),
                                                    gravity_gradient=True),
                          magnetorquers=(0.2, 0.2, 0.2), sensors=[Magnetometer(1.0)])
    run = detumble(body, BDot(1e5, (0.2, 0.2, 0.2)), orbit.period)
    assert run['reached'] is not None and run['reached'] < orbit.period
    rates = np.array(run['rates'])
    assert rates[0] == pytest.approx(math.radians(10.0), rel=1e-12)
    fast = rates[:np.argmax(rates < math.radians(3.0))]
    assert len(fast) > 300 and np.all(np.diff(fast[::100]) < 0.0)
    assert max(max(abs(c) for c in m) for m in run['dipoles']) == pytest.approx(0.2)


def test_a_body_with_reaction_wheels_in_orbit_against_an_independent_dop853():
    """
    Four pyramid wheels (spinning, motors driven) on a body in orbit under the whole model.

    The engine's gyrostat with the gravity gradient, the field and magnetorquer commands,
    against scipy's DOP853 of reference.gyrostat_rhs (the wheels' equations in matrix form)
    with the torques of reference.space_rhs (numpy, the orbit as an ODE) added: q, omega and
    the wheel speeds within 1e-12 over 20 s at 10 ms.
    """
    from rigid_body_dynamics.physics.dynamics.gyrostat import Wheels
    from rigid_body_dynamics.physics.dynamics.reference import gyrostat_rhs, space_rhs
    axes = [c / math.sqrt(3.0) for g in ((1, 1, 1), (-1, 1, 1), (-1, -1, 1), (1, -1, 1))
            for c in g]
    wheels = Wheels(axes, (0.02,) * 4)
    motors = (0.01, -0.005, 0.0, 0.002)
    orbit, field = KeplerOrbit(ELEMENTS), DipoleField(rotation_angle=0.4)
    q0, w0 = quaternions.normalize(np.array([0.1, 0.2, -0.3, 0.9])), (0.4, -0.7, 1.1)
    speeds0 = (100.0, -50.0, 0.0, 20.0)
    body = BodySimulation(Inertia(MOMENTS), 'exact', 100.0, (q0, w0), torque_timeout=0.0,
                          publish_every=10, wheels=wheels, wheel_speeds=speeds0,
                          disturbances=Disturbances(orbit=orbit, field=field,
                                                    gravity_gradient=True),
                          magnetorquers=BOX)
    from rigid_body_dynamics.engine import WheelCommands
    outbox = []
    with body.lock:
        body.hold(body.check(WheelCommands.one(motors, 0)), 0, 1)
        for k in range(200):
            body.hold(body.check(DipoleCommands.one(_dipole_schedule(k), 0)), 0, 1)
            for _ in range(10):
                body.advance(0, outbox)
    r0, v0 = orbit.state(0.0)
    y = np.concatenate([w0, q0, speeds0, np.zeros(4), r0, v0])
    worst = [0.0, 0.0, 0.0]
    for k, snap in enumerate(outbox):
        dipole = tuple(max(-b, min(b, c)) for c, b in zip(_dipole_schedule(k), BOX))
        env = space_rhs(MOMENTS, EARTH_MU, REFERENCE_FIELD, True, dipole)

        def rhs(t, s, env=env):
            orbit_part = env(t, np.concatenate([s[:7], s[15:21]]))
            tau = MOMENTS * orbit_part[:3] + np.cross(s[:3], MOMENTS * s[:3])   # I w' + w x Iw
            inner = gyrostat_rhs(MOMENTS, wheels, motors, torque=tau)(t, s[:15])
            return np.concatenate([inner, orbit_part[7:]])
        scale = np.array([1e-16] * 7 + [1e-14] * 8 + [1e-9] * 3 + [1e-12] * 3)
        sol = solve_ivp(rhs, (k * 0.1, (k + 1) * 0.1), y, method='DOP853', rtol=2.5e-14,
                        atol=scale)
        y = sol.y[:, -1].copy()
        y[3:7] /= np.linalg.norm(y[3:7])
        worst[0] = max(worst[0], quaternions.angle_between(np.array(snap.q_principal), y[3:7]))
        worst[1] = max(worst[1], np.linalg.norm(np.subtract(snap.omega_principal, y[:3])))
        worst[2] = max(worst[2], np.max(np.abs(np.subtract(snap.wheels.speeds, y[7:11]))) / 100)
    assert max(worst) < 1e-12, worst
