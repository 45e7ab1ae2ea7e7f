"""
Gravity-gradient libration and the Jacobi integral (physics/environment/libration.py, analysis).

The body simulated in a circular orbit under the gravity gradient alone near LVLH: the
one analysis measures the libration frequencies against the small-angle theory (Wie,
section 6.3), finds which principal axes are along LVLH, gives the stability verdict,
and reports the Jacobi integral's drift; an unstable arrangement, a far attitude and an
eccentric orbit are said to be so, never measured against the wrong theory.
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics import Inertia, make_integrator
from rigid_body_dynamics.physics.analysis import analyse, Trajectory
from rigid_body_dynamics.physics.environment import (circular_elements, GravityGradient,
                                                     KeplerOrbit, lvlh_quaternion, MU_EARTH,
                                                     SpaceEnvironment)
from rigid_body_dynamics.physics.environment.libration import (jacobi_integral, libration_modes,
                                                               oscillation_frequencies)
from scipy.spatial.transform import Rotation

MOMENTS = (2.0, 3.0, 1.2)           # I_y > I_x > I_z: the Lagrange region


def _fly(moments, turn, tilt, elements=None, steps=8000, dt=10.0, torque=(0.0, 0.0, 0.0)):
    """Integrate under the gravity gradient (and a held torque, N m) from LVLH * tilt * turn."""
    orbit = KeplerOrbit(elements or circular_elements(500e3, inclination=1.0, raan=0.3))
    env = SpaceEnvironment(orbit, None, [GravityGradient(moments, MU_EARTH)])
    r, v = orbit.state(0.0)
    lvlh = Rotation.from_quat(lvlh_quaternion(r, v))
    start = lvlh * Rotation.from_rotvec(tilt) * turn
    n = np.linalg.norm(np.cross(r, v)) / np.dot(r, r)
    body = make_integrator('exact', moments, dt, start.as_quat(),
                           start.inv().apply(lvlh.apply([0.0, -n, 0.0])))
    rows = []
    for _ in range(steps):
        r, v = orbit.state(body.time)
        rows.append((round(body.time * 1e9), body.q, body.omega, r, v))
        body.step(torque, None, env)
    t, q, w, r, v = (np.array(c) for c in zip(*rows))
    return Trajectory.from_samples(t, q, w, Inertia(moments), origin_ns=0, position=r,
                                   velocity=v), n


def test_the_theory_of_the_modes():
    n = 1e-3
    modes = libration_modes(MOMENTS, n)
    assert modes.pitch == pytest.approx(n * math.sqrt(3 * (2.0 - 1.2) / 3.0), rel=1e-15)
    k1, k3 = (3.0 - 1.2) / 2.0, (3.0 - 2.0) / 1.2
    for w in modes.roll_yaw:        # roots of s^4 + b n^2 s^2 + 4 k1 k3 n^4 at s = i w
        x = w / n
        residual = x ** 4 - (1 + 3 * k1 + k1 * k3) * x * x + 4 * k1 * k3
        assert residual == pytest.approx(0.0, abs=1e-13)
    assert modes.region == 'Lagrange' and modes.stable
    assert libration_modes((3.0, 2.0, 1.2), n).region == 'unstable'      # I_x > I_y
    # I_x > I_z > I_y: k1 = -0.02, k3 = -0.96, and both roots in s^2 real and negative (from
    # numpy's roots of the characteristic polynomial, not the module's formula)
    debra = libration_modes((1.0, 0.5, 0.52), n)
    assert debra.k1 < 0 and debra.k3 < 0 and debra.region == 'DeBra-Delp' and debra.stable
    b = 1.0 + 3.0 * debra.k1 + debra.k1 * debra.k3
    s2 = np.roots([1.0, b * n * n, 4.0 * debra.k1 * debra.k3 * n ** 4])
    assert np.all(np.abs(s2.imag) == 0.0) and np.all(s2.real < 0.0)
    np.testing.assert_allclose(sorted(np.sqrt(-s2.real)), debra.roll_yaw, rtol=1e-12)
    # k1 < 0 and k3 < 0 but I_z > I_x: the pitch is unstable, so the region is not DeBra-Delp
    assert libration_modes((1.0, 0.5, 1.4), n).region == 'unstable'
    assert libration_modes((1.0, 0.5, 1.4), n).pitch is None


def test_esprit_finds_two_frequencies_in_a_short_window(rng):
    t = np.arange(500) * 0.7
    w = (0.31, 0.47)
    signals = [a * np.cos(w[0] * t + p) + b * np.cos(w[1] * t + s)
               for a, b, p, s in rng.uniform(0.5, 2.0, (2, 4))]
    np.testing.assert_allclose(oscillation_frequencies(t, signals, 2), w, rtol=1e-12)
    assert oscillation_frequencies(t[:10], signals[0][:10], 2) is None


@pytest.mark.parametrize('turn', [Rotation.identity(),
                                  Rotation.from_euler('x', 180, degrees=True)],
                         ids=['axes on LVLH', 'flipped about roll'])
def test_libration_measured_against_theory_in_the_lagrange_region(turn):
    """Amplitudes of 1-2 mrad over 8000 s (1.4 orbits): frequencies within 1e-4 of theory."""
    trajectory, n = _fly(MOMENTS, turn, [0.001, 0.002, -0.0015])
    orbit = analyse(trajectory, gravity_gradient=True).orbit
    theory = libration_modes(MOMENTS, n)
    assert orbit.status == 'OK' and orbit.region == 'Lagrange' and orbit.moments == MOMENTS
    assert 'stable (Lagrange region)' in orbit.message
    for qty, expected in ((orbit.pitch, theory.pitch), (orbit.roll_yaw_slow, theory.roll_yaw[0]),
                          (orbit.roll_yaw_fast, theory.roll_yaw[1])):
        assert qty.theory == pytest.approx(expected, rel=1e-12)
        assert qty.relative_error < 1e-4
    assert orbit.jacobi_drift < 1e-13
    assert orbit.orbit_rate == pytest.approx(n, rel=1e-12)


def test_the_principal_axes_along_lvlh_are_found_and_an_unstable_one_said_so():
    """Body x along LVLH pitch: I_pitch = 2 < I_roll = 3, unstable: it tumbles away."""
    trajectory, _ = _fly(MOMENTS, Rotation.from_euler('z', 90, degrees=True), [0.0, 0.0, 0.001])
    orbit = analyse(trajectory, gravity_gradient=True).orbit
    assert orbit.moments == (3.0, 2.0, 1.2) and orbit.region == 'unstable'
    assert 'unstable (unstable region)' in orbit.message
    assert orbit.pitch.measured is None and 'from LVLH' in orbit.pitch.why
    assert orbit.jacobi_drift < 1e-12              # the integral holds at any attitude


def _jacobi(moments, n, trajectory):
    """Return the Jacobi integral (J) at each sample and omega - n h_B (rad/s, body)."""
    _, q, w, _ = trajectory.principal()
    r, v = trajectory.position, trajectory.velocity
    h = np.cross(r, v)
    body = Rotation.from_quat(q)
    normal = body.inv().apply(h / np.linalg.norm(h, axis=1)[:, None])
    return jacobi_integral(moments, n, w, normal, body.inv().apply(
        r / np.linalg.norm(r, axis=1)[:, None])), w - n * normal


def test_the_jacobi_integral_is_kept_and_a_torque_breaks_it():
    """
    Free of other torques the integral holds to 1e-12; a held body torque of 1e-7 N m changes it.

    Under a torque tau the integral changes at dE/dt = (omega - n h_B) . tau (the torque's
    power in the frame turning with the orbit): the analysis' drift equals that power's
    integral (trapezoid over the 10 s samples, within 1e-3 of it) and is far above 1e-12.
    """
    trajectory, n = _fly(MOMENTS, Rotation.identity(), [0.3, -0.2, 0.5], steps=3000)
    assert analyse(trajectory, gravity_gradient=True).orbit.jacobi_drift < 1e-12
    tau = np.array([1e-7, -2e-7, 1.5e-7])
    trajectory, n = _fly(MOMENTS, Rotation.identity(), [0.3, -0.2, 0.5], steps=3000,
                         torque=tuple(tau))
    found = analyse(trajectory, gravity_gradient=True).orbit
    e, w_rel = _jacobi(MOMENTS, n, trajectory)
    t = trajectory.t
    power = w_rel @ tau
    worked = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    np.testing.assert_allclose(e - e[0], worked, rtol=0, atol=1e-3 * np.max(np.abs(worked)))
    expected = np.max(np.abs(worked)) / abs(e[0])
    assert found.jacobi_drift == pytest.approx(expected, rel=1e-3) and expected > 1e-6


def test_an_eccentric_orbit_is_not_judged_by_the_circular_theory():
    trajectory, _ = _fly(MOMENTS, Rotation.identity(), [0.001, 0.0, 0.0],
                         elements=[7.5e6, 0.01, 1.0, 0.0, 0.0, 0.0], steps=300)
    orbit = analyse(trajectory, gravity_gradient=True).orbit
    assert orbit.status == 'unavailable' and 'not circular' in orbit.message
    assert analyse(trajectory).orbit is None          # only when asked (gravity_gradient)
