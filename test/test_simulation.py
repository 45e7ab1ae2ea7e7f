"""The offline simulate() API: frames, torque forms, sampling."""

import numpy as np
import pytest
from rigid_body_dynamics.physics import FreeRigidBody, Inertia, quaternions, simulate
from scipy.spatial.transform import Rotation


def test_free_run_reproduces_the_exact_solution():
    run = simulate((1.0, 2.0, 3.0), (0.3, 0.5, 2.0), (0.0, 0.6, 0.0, 0.8), duration=3.0, dt=1e-2)
    q, w = FreeRigidBody((1.0, 2.0, 3.0), (0.3, 0.5, 2.0), (0.0, 0.6, 0.0, 0.8)).state_at(run.t)
    assert run.t.shape == (301,) and run.q.shape == (301, 4) and run.omega.shape == (301, 3)
    assert np.max(quaternions.angle_between(run.q, q)) < 1e-13
    np.testing.assert_allclose(run.omega, w, atol=1e-13)


def test_constant_and_callable_torque_agree():
    a = simulate((1.0, 2.0, 3.0), (0.3, 0.5, 2.0), duration=1.0, dt=1e-3, torque=(0.1, 0.2, 0.3))
    b = simulate((1.0, 2.0, 3.0), (0.3, 0.5, 2.0), duration=1.0, dt=1e-3,
                 torque=lambda t, q, w: (0.1, 0.2, 0.3))
    np.testing.assert_array_equal(a.omega, b.omega)
    np.testing.assert_array_equal(a.torque[0], [0.1, 0.2, 0.3])
    energy = a.kinetic_energy
    assert abs(energy[-1] - energy[0] - a.work[-1]) < 1e-12 * energy[0]


def test_rotated_tensor_body_with_torque_is_frame_consistent():
    """Torque and omega given in a rotated body frame act exactly as in the principal one."""
    rot = Rotation.from_euler('zyx', [0.4, 0.2, -0.9])
    moments = np.array([1.0, 2.0, 3.0])
    inertia = Inertia.from_tensor(rot.as_matrix() @ np.diag(moments) @ rot.as_matrix().T)
    w_p, tau_p = np.array([0.3, 0.5, 2.0]), np.array([0.1, -0.2, 0.05])
    principal = simulate(moments, w_p, duration=2.0, dt=1e-3, torque=tau_p)
    rotated = simulate(inertia, rot.apply(w_p), rot.inv().as_quat(), duration=2.0, dt=1e-3,
                       torque=rot.apply(tau_p))
    np.testing.assert_allclose(rotated.omega, rot.apply(principal.omega), atol=1e-12)
    np.testing.assert_allclose(rotated.angular_momentum_world, principal.angular_momentum_world,
                               atol=1e-12)


def test_every_keeps_every_nth_sample_and_zero_duration():
    run = simulate((1.0, 2.0, 3.0), (0.3, 0.5, 2.0), duration=1.0, dt=1e-3, every=100)
    np.testing.assert_allclose(run.t, np.arange(11) * 0.1, atol=1e-15)
    assert simulate((1.0, 2.0, 3.0), (0.3, 0.5, 2.0), duration=0.0).t.tolist() == [0.0]


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match='triangle'):
        simulate((1.0, 1.0, 5.0), (0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match='unknown integrator'):
        simulate((1.0, 2.0, 3.0), (0.0, 0.0, 1.0), integrator='leapfrog')


def test_the_per_step_frame_changes_match_the_inertias_array_methods():
    """Check UserFrame (plain Python, simulate()'s hot path) against Inertia's numpy methods."""
    from rigid_body_dynamics.physics.dynamics.plant import UserFrame
    rng = np.random.default_rng(11)
    rot = Rotation.from_rotvec([0.3, -0.5, 0.4])
    tensor = Inertia.from_tensor(rot.as_matrix() @ np.diag([1.0, 2.0, 3.0]) @ rot.as_matrix().T)
    for inertia in (tensor, Inertia((1.0, 2.0, 3.0))):
        frame = UserFrame(inertia)
        for _ in range(50):
            v = rng.normal(size=3)
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            np.testing.assert_allclose(frame.to_body(v), inertia.to_body(v), rtol=0, atol=1e-15)
            np.testing.assert_allclose(frame.to_principal(v), inertia.to_principal(v), rtol=0,
                                       atol=1e-15)
            np.testing.assert_allclose(frame.attitude_to_body(q), inertia.attitude_to_body(q),
                                       rtol=0, atol=1e-15)
            np.testing.assert_allclose(frame.torque_principal(np.array(v), 0.0),
                                       inertia.to_principal(v), rtol=0, atol=1e-15)
        for bad in ((1.0, 2.0), np.zeros(4), 'abc', (1.0, None, 2.0)):
            with pytest.raises(ValueError, match='must return three numbers'):
                frame.torque_principal(bad, 1.5)


@pytest.mark.parametrize('integrator', ['exact', 'rk4'])
def test_one_schedule_offline_and_in_the_node_engine_agree_bit_for_bit(integrator):
    """
    simulate() and the simulator's engine (BodySimulation) step one core: the same states.

    The hard case: a body given by a rotated tensor in an eccentric orbit with the
    gravity gradient, the dipole field, a residual dipole, constant body and world
    torques, and a commanded body torque that changes every 10 steps (a 100 Hz
    controller at 1 kHz), for 2 s. Every state of the run, compared with ==.
    """
    from rigid_body_dynamics.engine import BodySimulation
    from rigid_body_dynamics.physics.environment import DipoleField, Disturbances, KeplerOrbit
    rot = Rotation.from_rotvec([0.3, -0.5, 0.4])
    inertia = Inertia.from_tensor(rot.as_matrix() @ np.diag([10.5, 8.0, 6.75])
                                  @ rot.as_matrix().T)
    d = Disturbances(body=(1e-6, 0.0, -2e-6), world=(0.0, 3e-6, 0.0),
                     orbit=KeplerOrbit((7.0e6, 0.01, 1.7, 0.8, 0.3, 0.2)), field=DipoleField(),
                     gravity_gradient=True, residual_dipole=(0.2, -0.1, 0.05))
    q0 = (0.1, 0.2, -0.3, 0.9)
    q0 = tuple(c / np.linalg.norm(q0) for c in q0)
    w0 = (0.02, -0.05, 0.03)

    def schedule(t):
        """Body torque (N m) commanded at t (s): a new value every 10 ms."""
        k = round(t * 100.0)
        return (1e-4 * np.sin(0.7 * k), -2e-4 * np.cos(0.3 * k), 5e-5 * (k % 7 - 3))

    offline = simulate(inertia, w0, q0, duration=2.0, dt=1e-3, integrator=integrator,
                       torque=lambda t, q, w: schedule(t), torque_every=10, disturbances=d)
    body = BodySimulation(inertia, integrator, 1000.0, (q0, w0), torque_timeout=0.0,
                          disturbances=d)
    qs, ws = [], []
    with body.lock:
        for k in range(2001):
            qs.append(body.stepper.q)
            ws.append(body.stepper.omega)
            if k % 10 == 0:
                body.command(tuple(float(c) for c in schedule(k * 1e-3)), False, k * 10 ** 6)
            if k < 2000:
                body.advance(k * 10 ** 6, [])
    np.testing.assert_array_equal(offline.q, inertia.attitude_to_body(np.array(qs)))
    np.testing.assert_array_equal(offline.omega, inertia.to_body(np.array(ws)))
    # and the run is not trivially the same: the environment turned it
    free = simulate(inertia, w0, q0, duration=2.0, dt=1e-3, integrator=integrator,
                    torque=lambda t, q, w: schedule(t), torque_every=10)
    assert np.max(np.abs(free.omega[-1] - offline.omega[-1])) > 1e-7
