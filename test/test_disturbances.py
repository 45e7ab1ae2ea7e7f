"""
Disturbance torques (physics/disturbances.py) against formula, DOP853 and libration theory.

The gravity gradient against its formula, integrated at the RK stages against
DOP853, and the pitch libration of its stable attitude.
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics import estimators, quaternions
from rigid_body_dynamics.physics.disturbances import GravityGradient
from rigid_body_dynamics.physics.equations import state_rhs
from rigid_body_dynamics.physics.integrators import make_integrator
from scipy.integrate import solve_ivp

MOMENTS = (2.0, 3.0, 1.0)      # x along track, y orbit normal (largest), z nadir (least)


def test_gravity_gradient_is_3_n2_r_cross_i_r_and_zero_on_a_principal_axis(rng):
    gg = GravityGradient(MOMENTS, 1e-3, orbit_normal=(0.0, 0.0, 2.0), nadir0=(1.0, 0.0, 0.5))
    assert gg.nadir0 == pytest.approx((1.0, 0.0, 0.0)) and gg.normal == (0.0, 0.0, 1.0)
    for _ in range(20):
        q = rng.normal(size=4)
        t = rng.uniform(0.0, 1e4)
        r = quaternions.rotate_inverse(q / np.linalg.norm(q), np.array(gg.nadir_world(t)))
        expected = 3e-6 * np.cross(r, np.array(MOMENTS) * r)
        np.testing.assert_allclose(gg(t, *(1.7 * q)), expected, rtol=1e-12, atol=1e-20)
    # nadir along a principal axis: no torque; after a quarter orbit nadir is along y
    assert gg(0.0, 0.0, 0.0, 0.0, 1.0) == pytest.approx((0.0, 0.0, 0.0), abs=1e-22)
    np.testing.assert_allclose(gg.nadir_world(0.25 * 2 * math.pi / 1e-3), (0.0, 1.0, 0.0),
                               atol=1e-12)
    with pytest.raises(ValueError, match='orbit_rate'):
        GravityGradient(MOMENTS, 0.0)
    with pytest.raises(ValueError, match='parallel'):
        GravityGradient(MOMENTS, 1e-3, orbit_normal=(0.0, 0.0, 1.0), nadir0=(0.0, 0.0, 3.0))


GG = GravityGradient(MOMENTS, 0.5, orbit_normal=(0.3, 1.0, 0.1), nadir0=(0.0, 0.0, 1.0))
W0, Q0 = (0.4, -0.7, 1.1), quaternions.normalize(np.array([0.1, 0.2, -0.3, 0.9]))


def _gg_run(integrator, dt, duration=20.0):
    """Integrate the tumbling body under GG; returns (integrator, attitude error vs DOP853)."""
    steps = int(round(duration / dt))
    body = make_integrator(integrator, MOMENTS, dt, Q0, W0)
    for _ in range(steps):
        body.step((0.0, 0.0, 0.0), None, GG)
    sol = solve_ivp(lambda t, y: state_rhs(MOMENTS, y, GG(t, *y[3:])), (0.0, steps * dt),
                    np.r_[W0, Q0], method='DOP853', rtol=2.5e-14, atol=1e-16)
    q_ref = sol.y[3:, -1] / np.linalg.norm(sol.y[3:, -1])
    return body, quaternions.angle_between(np.array(body.q), q_ref), sol.y[:3, -1]


@pytest.mark.parametrize('integrator, dt, tol', [('exact', 0.01, 1e-12), ('exact', 0.05, 1e-12),
                                                 ('rk4', 0.01, 1e-8)])
def test_tumbling_body_under_gravity_gradient_matches_dop853(integrator, dt, tol):
    """A fast orbit (n = 0.5 rad/s) and a tumbling body: the field is integrated at the stages."""
    w0 = W0
    body, error, w_ref = _gg_run(integrator, dt)
    assert error < tol
    np.testing.assert_allclose(body.omega, w_ref, rtol=0, atol=tol)
    # the work booked is the energy change (the field does work on a tumbling body)
    energy = 0.5 * sum(i * w * w for i, w in zip(MOMENTS, body.omega))
    energy0 = 0.5 * sum(i * w * w for i, w in zip(MOMENTS, w0))
    assert abs(energy - energy0) > 1e-3
    assert body.work == pytest.approx(energy - energy0, abs=tol)


def test_rk4_under_the_field_is_fourth_order():
    """Halving the step divides rk4's error by 16 (14-18): the field is not held per step."""
    ratio = _gg_run('rk4', 0.02)[1] / _gg_run('rk4', 0.01)[1]
    assert 14.0 < ratio < 18.0


def test_pitch_libration_frequency_is_n_sqrt_3_ix_minus_iz_over_iy():
    """
    Principal axes on the orbit frame (z nadir, y normal), turning at n, pitched by 0.01 rad.

    The pitch angle about the orbit normal oscillates at omega_p = n sqrt(3 (Ix - Iz) / Iy)
    (derivation in physics/disturbances.py); the amplitude correction at 0.01 rad is about
    theta0^2 / 4 = 2.5e-5, so the measured period is within 1e-4 of the small-angle one.
    """
    n = 1e-3
    gg = GravityGradient(MOMENTS, n, orbit_normal=(0.0, 1.0, 0.0), nadir0=(0.0, 0.0, 1.0))
    body = make_integrator('exact', MOMENTS, 1.0, quaternions.from_axis_angle(
        np.array([0.0, 1.0, 0.0]), 0.01), (0.0, n, 0.0))
    omega_p = n * math.sqrt(3.0 * (MOMENTS[0] - MOMENTS[2]) / MOMENTS[1])
    steps = int(3.2 * 2 * math.pi / omega_p)
    t, pitch = np.empty(steps + 1), np.empty(steps + 1)
    for k in range(steps + 1):
        z_body = quaternions.rotate(np.array(body.q), np.array([0.0, 0.0, 1.0]))
        nadir = np.array(gg.nadir_world(body.time))
        t[k] = body.time
        pitch[k] = math.atan2(np.cross(nadir, z_body) @ gg.normal, nadir @ z_body)
        body.step((0.0, 0.0, 0.0), None, gg)
    assert np.max(np.abs(pitch)) == pytest.approx(0.01, rel=1e-3)     # stays librating
    crossings = estimators.crossing_times(t, pitch, direction=0)
    period = 2.0 * np.mean(np.diff(crossings))
    assert period == pytest.approx(2 * math.pi / omega_p, rel=1e-4)
