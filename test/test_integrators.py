"""Integrators: conservation, accuracy order, balance laws under torque, protocol."""

import math

from conftest import dop853_reference, random_attitude
import numpy as np
import pytest
from rigid_body_dynamics.physics import equations, FreeRigidBody, INTEGRATORS, make_integrator
from rigid_body_dynamics.physics import quaternions

MOMENTS = (1.0, 2.0, 3.0)
OMEGA0 = (1.0, 1.0, 6.0)   # |omega| h = 6e-3 at 1 kHz, as in the acceptance targets


def run(name, steps, dt=1e-3, torque=(0.0, 0.0, 0.0), q0=(0.0, 0.0, 0.0, 1.0),
        moments=MOMENTS, omega0=OMEGA0):
    stepper = make_integrator(name, moments, dt, q0, omega0)
    for _ in range(steps):
        stepper.step(torque)
    return stepper


def invariants(moments, q, omega):
    m = np.array(moments)
    return (equations.kinetic_energy(m, np.array(omega)),
            equations.angular_momentum_world(m, np.array(q), np.array(omega)))


# Torque-free, 2e4 steps (20 s): stated tolerances per integrator.
# (energy rel., |L| rel., L direction rad, attitude vs exact rad)
FREE_TOLERANCES = {
    'exact': (1e-14, 1e-14, 1e-14, 1e-12),
    'exact4': (1e-14, 1e-14, 1e-14, 1e-12),
    'rk4': (1e-11, 1e-11, 1e-10, 1e-9),
    'dop853': (1e-11, 1e-11, 1e-10, 1e-9),
}


@pytest.mark.parametrize('name', sorted(INTEGRATORS))
def test_torque_free_conservation_and_accuracy(name, rng):
    q0 = random_attitude(rng)
    stepper = run(name, 20000, q0=q0)
    t0, l0 = invariants(MOMENTS, q0, OMEGA0)
    t1, l1 = invariants(MOMENTS, stepper.q, stepper.omega)
    energy, norm, direction, attitude = FREE_TOLERANCES[name]
    assert abs(t1 / t0 - 1.0) < energy
    assert abs(np.linalg.norm(l1) / np.linalg.norm(l0) - 1.0) < norm
    cos = np.dot(l0, l1) / (np.linalg.norm(l0) * np.linalg.norm(l1))
    assert math.atan2(np.linalg.norm(np.cross(l0, l1)), np.linalg.norm(l0) ** 2 * cos) < direction
    q_exact, _ = FreeRigidBody(MOMENTS, OMEGA0, q0).state_at(stepper.time)
    assert float(quaternions.angle_between(stepper.q, q_exact)) < attitude
    assert stepper.steps == 20000 and stepper.time == 20.0


@pytest.mark.parametrize('name', sorted(INTEGRATORS))
def test_quaternion_stays_unit_every_step(name):
    stepper = make_integrator(name, MOMENTS, 1e-3, (0.1, 0.2, 0.3, 0.9), OMEGA0)
    worst = 0.0
    for k in range(2000):
        stepper.step((0.0, 0.3, 0.0) if k % 500 < 250 else (0.0, 0.0, 0.0))
        worst = max(worst, abs(math.sqrt(sum(c * c for c in stepper.q)) - 1.0))
    assert worst <= 2.3e-16


@pytest.mark.parametrize('name', sorted(INTEGRATORS))
def test_constant_torque_about_symmetry_axis(name):
    """Symmetric body spinning about its axis: omega3(t) = omega3(0) + tau t / I3."""
    moments, w3, tau = (1.0, 1.0, 1.5), 2.0, 0.3
    stepper = run(name, 5000, torque=(0.0, 0.0, tau), moments=moments, omega0=(0.0, 0.0, w3))
    expected = w3 + tau * stepper.time / moments[2]
    assert stepper.omega[2] == pytest.approx(expected, rel=1e-12)
    assert abs(stepper.omega[0]) < 1e-15 and abs(stepper.omega[1]) < 1e-15


@pytest.mark.parametrize('name', ['exact', 'exact4'])
def test_balance_laws_hold_to_round_off_under_torque(name, rng):
    """T - T0 = W and L_w - L_w0 = H exactly for the kick scheme, though T changes by percent."""
    q0 = random_attitude(rng)
    stepper = make_integrator(name, MOMENTS, 1e-3, q0, OMEGA0)
    t0, l0 = invariants(MOMENTS, q0, OMEGA0)
    for k in range(4000):
        phase = 2.0 * math.pi * k / 1000.0
        stepper.step((0.5 * math.sin(phase), 0.4 * math.cos(phase), 0.8))
    t1, l1 = invariants(MOMENTS, stepper.q, stepper.omega)
    assert abs(t1 - t0) / t0 > 0.01
    assert abs(t1 - t0 - stepper.work) / t0 < 1e-12
    assert np.linalg.norm(l1 - l0 - np.array(stepper.impulse)) / np.linalg.norm(l0) < 1e-12


@pytest.mark.parametrize('name, tol', [('rk4', 3e-11), ('dop853', 1e-11)])
def test_balance_laws_to_truncation_for_other_integrators(name, tol):
    stepper = run(name, 4000, torque=(0.2, -0.1, 0.5))
    t0, l0 = invariants(MOMENTS, (0.0, 0.0, 0.0, 1.0), OMEGA0)
    t1, l1 = invariants(MOMENTS, stepper.q, stepper.omega)
    assert abs(t1 - t0 - stepper.work) / t0 < tol
    assert np.linalg.norm(l1 - l0 - np.array(stepper.impulse)) / np.linalg.norm(l0) < tol


def _error_under_torque(name, dt, duration=2.0):
    torque = (0.3, -0.2, 0.5)
    stepper = run(name, int(round(duration / dt)), dt=dt, torque=torque)
    q_ref, w_ref = dop853_reference(np.array(MOMENTS), OMEGA0, (0.0, 0.0, 0.0, 1.0),
                                    np.array([duration]), torque=torque)
    return max(float(quaternions.angle_between(stepper.q, q_ref[0])),
               float(np.max(np.abs(np.array(stepper.omega) - w_ref[0]))))


@pytest.mark.parametrize('name, order', [('exact', 2), ('exact4', 4), ('rk4', 4)])
def test_order_of_accuracy_under_torque(name, order):
    coarse = _error_under_torque(name, 0.02)
    fine = _error_under_torque(name, 0.01)
    measured = math.log2(coarse / fine)
    assert measured == pytest.approx(order, abs=0.3)


def test_exact_under_torque_is_exact_once_torque_stops(rng):
    """After a torque pulse the motion is free again: the segment restarts exactly."""
    q0 = random_attitude(rng)
    stepper = make_integrator('exact', MOMENTS, 1e-3, q0, OMEGA0)
    for _ in range(100):
        stepper.step((0.0, 1.0, 0.0))
    q1, w1 = stepper.q, stepper.omega
    for _ in range(5000):
        stepper.step()
    q_exact, w_exact = FreeRigidBody(MOMENTS, w1, q1).state_at(5.0)
    assert float(quaternions.angle_between(stepper.q, q_exact)) < 1e-13
    np.testing.assert_allclose(stepper.omega, w_exact, atol=1e-13)


def test_near_separatrix_step_falls_back_and_conserves():
    stepper = run('exact', 3000, omega0=(0.0, 2.0, 1e-6), torque=(0.0, 0.0, 0.0))
    t0, l0 = invariants(MOMENTS, (0.0, 0.0, 0.0, 1.0), (0.0, 2.0, 1e-6))
    t1, l1 = invariants(MOMENTS, stepper.q, stepper.omega)
    assert abs(t1 / t0 - 1.0) < 1e-12
    assert np.linalg.norm(l1 - l0) / np.linalg.norm(l0) < 1e-12


def test_reset_restarts_state_and_balances():
    stepper = run('exact', 100, torque=(0.1, 0.0, 0.0))
    stepper.reset((0.0, 0.0, 0.0, 2.0), (0.0, 0.0, 1.0))
    assert stepper.q == (0.0, 0.0, 0.0, 1.0)
    assert stepper.steps == 0 and stepper.work == 0.0 and stepper.impulse == (0.0, 0.0, 0.0)


def test_unknown_integrator_and_bad_state_are_refused():
    with pytest.raises(ValueError, match='unknown integrator .*exact.*rk4'):
        make_integrator('euler', MOMENTS, 1e-3)
    with pytest.raises(ValueError, match='dt'):
        make_integrator('rk4', MOMENTS, 0.0)
    with pytest.raises(ValueError, match='finite'):
        make_integrator('rk4', MOMENTS, 1e-3, (0.0, 0.0, 0.0, 1.0), (np.nan, 0.0, 0.0))


def test_dop853_restarts_when_torque_changes():
    stepper = make_integrator('dop853', MOMENTS, 1e-3, (0.0, 0.0, 0.0, 1.0), OMEGA0)
    for k in range(1000):
        stepper.step((0.0, 0.0, 0.5) if k < 500 else (0.0, 0.0, 0.0))
    fine = make_integrator('exact4', MOMENTS, 1e-4, (0.0, 0.0, 0.0, 1.0), OMEGA0)
    for k in range(10000):
        fine.step((0.0, 0.0, 0.5) if k < 5000 else (0.0, 0.0, 0.0))
    assert float(quaternions.angle_between(stepper.q, fine.q)) < 1e-10


@pytest.mark.parametrize('name, tol', [('exact', 1e-13), ('exact4', 1e-13), ('rk4', 1e-9),
                                       ('dop853', 1e-10)])
def test_world_fixed_torque_gives_exactly_its_impulse(name, tol, rng):
    """A torque held fixed in the world frame changes L_w by tau_w t, whatever the body does."""
    q0 = random_attitude(rng)
    tau_w = (0.05, -0.02, 0.04)
    stepper = make_integrator(name, MOMENTS, 1e-3, q0, OMEGA0)
    for _ in range(2000):
        stepper.step((0.0, 0.0, 0.0), tau_w)
    _, l0 = invariants(MOMENTS, q0, OMEGA0)
    t1, l1 = invariants(MOMENTS, stepper.q, stepper.omega)
    expected = l0 + np.array(tau_w) * stepper.time
    assert np.linalg.norm(l1 - expected) / np.linalg.norm(l0) < tol
    np.testing.assert_allclose(stepper.impulse, np.array(tau_w) * stepper.time, rtol=1e-9)
    t0 = invariants(MOMENTS, q0, OMEGA0)[0]
    assert abs(t1 - t0 - stepper.work) / t0 < max(tol, 1e-11)
