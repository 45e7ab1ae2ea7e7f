"""Closed-form predictions against simulation and against each other."""

import math

import numpy as np
import pytest

from rigid_body_dynamics.physics import (estimators, FreeRigidBody, presets, quaternions,
                                         simulate, theory)
from rigid_body_dynamics.physics.dynamics import equations


def test_symmetric_top_rates_match_simulation():
    i1, i3, w0 = 1.0, 1.5, np.array([0.3, 0.0, 2.0])
    run = simulate((i1, i1, i3), w0, duration=20.0, dt=1e-2)
    g = float(np.linalg.norm(np.array([i1, i1, i3]) * w0))
    body = estimators.body_precession_rate(run.t, run.omega, axis=2).rate
    lab = estimators.lab_precession_rate(run.t, run.q, run.omega, (i1, i1, i3), axis=2).rate
    assert body == pytest.approx(theory.body_precession_rate(i1, i3, w0[2]), rel=1e-12)
    assert lab == pytest.approx(theory.lab_precession_rate(i1, g), rel=1e-12)


@pytest.mark.parametrize('i_axis, w_perp, w_axis', [(1.5, 0.3, 2.0), (0.6, 0.2, -1.0),
                                                    (1.9, 1.0, 0.5)])
def test_herpolhode_rate_equals_lab_rate(i_axis, w_perp, w_axis):
    """Seed: Omega_L = Omega sin(phi_b) / sin(phi_L) equals |L| / I1 (rolling without slipping)."""
    i_perp = 1.0
    g = math.hypot(i_perp * w_perp, i_axis * w_axis)
    assert theory.herpolhode_rate(i_perp, i_axis, w_perp, w_axis) == pytest.approx(
        theory.lab_precession_rate(i_perp, g), rel=1e-13)


def test_cone_angles_match_the_simulated_geometry():
    moments, w0 = (1.0, 1.0, 1.5), np.array([0.3, 0.0, 2.0])
    run = simulate(moments, w0, duration=5.0, dt=1e-2)
    cones = theory.cone_angles(1.0, 1.5, 0.3, 2.0)
    lw = run.angular_momentum_world
    w_world = quaternions.rotate(run.q, run.omega)
    e3_world = quaternions.rotate(run.q, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(estimators.vector_angle(run.omega, [0, 0, 1]), cones.body,
                               atol=1e-14)
    np.testing.assert_allclose(estimators.vector_angle(w_world, lw), cones.lab, atol=1e-13)
    np.testing.assert_allclose(estimators.vector_angle(e3_world, lw), cones.nutation, atol=1e-13)
    # seed: cos(phi_L) = 2T / (|omega| |L|)
    t = equations.kinetic_energy(np.array(moments), w0)
    assert math.cos(cones.lab) == pytest.approx(
        2.0 * t / (np.linalg.norm(w0) * np.linalg.norm(lw[0])), rel=1e-14)


def test_invariant_plane_distance_is_omega_along_l():
    run = simulate((1.0, 2.0, 3.0), (0.4, 0.6, 1.5), duration=10.0, dt=1e-2)
    lw = run.angular_momentum_world
    lhat = lw[0] / np.linalg.norm(lw[0])
    along = quaternions.rotate(run.q, run.omega) @ lhat
    t = run.kinetic_energy[0]
    np.testing.assert_allclose(along, theory.invariant_plane_distance(t, np.linalg.norm(lw[0])),
                               rtol=1e-13)


@pytest.mark.parametrize('axis, kind', [(0, 'stable'), (1, 'unstable'), (2, 'stable')])
def test_stability_classification_and_rates_measured(axis, kind):
    moments, spin, eps = (1.0, 2.0, 3.0), 2.0, 1e-7
    result = theory.axis_stability(moments, axis, spin)
    assert result.kind == kind
    w0 = np.full(3, eps)
    w0[axis] = spin
    other = (axis + 1) % 3
    if kind == 'unstable':
        run = simulate(moments, w0, duration=8.0, dt=1e-3, integrator='rk4')
        # exponential growth over the linear regime (amplitude 1e-7 -> 1e-3)
        amp = np.hypot(run.omega[:, 0], run.omega[:, 2])
        keep = (run.t > 2.0) & (amp < 1e-3)
        rate = estimators.growth_rate(run.t[keep], amp[keep])
        assert rate == pytest.approx(result.rate, rel=0.01)
        assert result.rate == pytest.approx(theory.separatrix_growth_rate(moments, w0), rel=1e-12)
    else:
        run = simulate(moments, w0, duration=30.0, dt=1e-2)
        period = estimators.crossing_period(run.t, run.omega[:, other])
        assert 2.0 * math.pi / period == pytest.approx(result.rate, rel=1e-4)


def test_equal_moments_are_marginal_or_stable():
    assert theory.axis_stability((1.0, 1.0, 1.5), 0, 2.0).kind == 'marginal'
    assert theory.axis_stability((1.0, 1.0, 1.5), 2, 2.0).kind == 'stable'
    assert theory.axis_stability((1.0, 1.0, 1.0), 1, 2.0).kind == 'stable'
    assert theory.axis_stability((1.0, 2.0, 3.0), 1, 0.0).kind == 'rest'


def test_symmetric_wobble_frequency_is_the_body_precession_rate():
    assert theory.axis_stability((1.0, 1.0, 1.5), 2, 2.0).rate == pytest.approx(
        abs(theory.body_precession_rate(1.0, 1.5, 2.0)), rel=1e-15)


def test_tennis_racket_flip_interval_measured():
    body = presets.get('tennis_racket')
    run = simulate(body.moments, body.omega0, duration=100.0, dt=1e-3, every=10)
    flips = estimators.crossing_times(run.t, run.omega[:, 1], direction=0)
    assert flips.size >= 8
    measured = np.diff(flips).mean()
    assert measured == pytest.approx(theory.flip_interval(body.moments, body.omega0), rel=1e-6)
    assert theory.polhode(body.moments, body.omega0).family == 'max-axis'
    assert 0.0 < theory.polhode(body.moments, body.omega0).separatrix_distance < 1e-4


@pytest.mark.parametrize('moments, omega0', [
    ((1.0, 2.0, 3.0), (0.1, 0.1, 2.0)), ((1.0, 2.0, 3.0), (-2.0, 0.1, 0.1)),
    ((3.0, 1.0, 2.0), (0.1, 0.3, 2.0)), ((1.0, 3.0, 2.0), (0.4, 2.5, -0.3)),
])
def test_period_and_mean_precession_against_exact_motion(moments, omega0):
    period = theory.omega_period(moments, omega0)
    body = FreeRigidBody(moments, omega0)
    t = np.linspace(0.0, 4.0 * period, 16001)
    q, w = body.state_at(t)
    np.testing.assert_allclose(w[-1], w[0], atol=1e-11)       # periodic in the body
    lw = equations.angular_momentum_world(np.array(moments), q, w)
    for axis in range(3):
        u, v, _ = estimators.basis_perpendicular(lw[0])
        e = quaternions.rotate(q, np.eye(3)[axis])
        turned = np.unwrap(np.arctan2(e @ v, e @ u))
        assert (turned[-1] - turned[0]) / t[-1] == pytest.approx(
            theory.mean_precession_rate(moments, omega0, axis), rel=1e-10)


def test_chandler_period_is_about_300_sidereal_days():
    period = theory.chandler_wobble_period()
    assert period / theory.SIDEREAL_DAY == pytest.approx(300.0, rel=1e-12)
    assert 9.5 < period / (30.4375 * 86400.0) < 10.0       # Shapiro's "10 months"


def test_earth_preset_wobble_period_from_simulation():
    earth = presets.get('earth_chandler')
    dt = 1.0 / earth.integration_rate
    run = simulate(earth.moments, earth.omega0, duration=400.0 * theory.SIDEREAL_DAY,
                   dt=dt, every=600)
    rate = estimators.body_precession_rate(run.t, run.omega, axis=2).rate
    assert 2.0 * math.pi / rate / theory.SIDEREAL_DAY == pytest.approx(300.0, rel=1e-6)


def test_separatrix_detection():
    assert theory.is_near_separatrix((1.0, 2.0, 3.0), (0.0, 2.0, 1e-6))
    assert not theory.is_near_separatrix((1.0, 2.0, 3.0), (0.01, 2.0, 0.01))
    assert theory.omega_period((1.0, 2.0, 3.0), (0.0, 2.0, 0.0)) == math.inf


def test_poinsot_construction_tangency():
    """Tangency: omega's tip is on the ellipsoid and on the invariant plane (normal L)."""
    from rigid_body_dynamics.physics.analysis import poinsot
    run = simulate((1.0, 2.0, 3.0), (0.4, 0.6, 1.5), (0.1, 0.2, 0.3, 0.9), duration=5.0,
                   dt=1e-2)
    for q, w in zip(run.q[::50], run.omega[::50]):
        c = poinsot.construction((1.0, 2.0, 3.0), q, w)
        body_tip = quaternions.rotate_inverse(c.orientation, c.omega)
        assert np.sum((body_tip / c.semi_axes) ** 2) == pytest.approx(1.0, rel=1e-13)
        assert float(c.omega @ c.normal) == pytest.approx(c.distance, rel=1e-13)
        # the ellipsoid's normal at the tip, I omega, is the plane's normal
        grad = quaternions.rotate(c.orientation, np.array([1.0, 2.0, 3.0]) * body_tip)
        assert float(estimators.vector_angle(grad, c.normal)) < 1e-14
    np.testing.assert_allclose(c.semi_axes * np.sqrt([1.0, 2.0, 3.0]),
                               c.semi_axes[0] * np.ones(3), rtol=1e-14)
    normal = np.array([0.3, -0.4, 0.5]) / np.linalg.norm([0.3, -0.4, 0.5])
    np.testing.assert_allclose(quaternions.rotate(poinsot.plane_orientation(normal), [0, 0, 1]),
                               normal, atol=1e-15)
    with pytest.raises(ValueError, match='rest'):
        poinsot.construction((1.0, 2.0, 3.0), (0, 0, 0, 1), (0.0, 0.0, 0.0))
