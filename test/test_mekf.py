"""
The example MEKF without ROS, and the analysis that judges any estimator.

A tumbling body's true attitude (the exact flow), the simulator's own gyro and
star tracker models: the filter's steady state against the single-axis
steady state of the gyro plus attitude-sensor filter (Farrenkopf's problem,
Markley and Crassidis section 6.3: the discrete Riccati equation's fixed
point, from scipy), its consistency by the analysis' NEES verdict, and the
verdict on a filter told a 10x too small tracker noise.
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics import FreeRigidBody, quaternions
from rigid_body_dynamics.physics.analysis import autocorrelation_time, estimation
from rigid_body_dynamics.physics.mekf import MEKF
from rigid_body_dynamics.physics.sensors import (BodyTruth, GyroErrors, GyroModel, Sky,
                                                 StarTracker)
from scipy.linalg import solve_discrete_are
from scipy.signal import lfilter

N, K, SIGMA = 1e-4, 1e-6, 1e-4      # rad/s/sqrt(Hz), rad/s^2/sqrt(Hz), rad
RATE, EVERY = 100.0, 10             # gyro Hz; gyro samples per tracker reading


def _run(seconds, told_sigma=SIGMA, omega0=(0.02, -0.01, 0.015), seed=1):
    """Fly the filter on the simulator's models; return truth, estimates and covariances."""
    t = np.arange(int(seconds * RATE) + 1) / RATE
    q, w = FreeRigidBody((2.0, 3.0, 1.2), omega0, (0.0, 0.0, 0.0, 1.0)).state_at(t)
    measured, bias = GyroModel(GyroErrors(N, K, 1e-3), RATE, seed=seed).sample(w)
    tracker = StarTracker(RATE / EVERY, (SIGMA,) * 3)
    rng = np.random.default_rng(seed + 1)
    f = MEKF(N, K)
    told = np.eye(3) * told_sigma ** 2
    est, cov_world, cov_body, bias_est = [], [], [], []
    for k in range(len(t)):
        if k:
            f.propagate(measured[k - 1], t[k] - t[k - 1])
        if k % EVERY == 0:
            reading = tracker.sample(BodyTruth(tuple(q[k]), (0.0, 0.0, 0.0), None, Sky()), t[k],
                                     rng)
            if f.started:
                f.update_attitude(reading.q, told)
            else:
                f.start(reading.q, told, bias_sigma=1e-3)
        est.append(f.q)
        cov_world.append(f.attitude_covariance_world())
        cov_body.append(f.P[:3, :3].copy())
        bias_est.append(f.bias)
    return q, np.array(est), np.array(cov_world), np.array(cov_body), bias, np.array(bias_est)


def _farrenkopf():
    """Return the steady post-update (attitude, bias) sigmas of the single-axis filter."""
    dt = EVERY / RATE
    phi = np.array([[1.0, -dt], [0.0, 1.0]])
    q = np.array([[N ** 2 * dt + K ** 2 * dt ** 3 / 3.0, -K ** 2 * dt ** 2 / 2.0],
                  [-K ** 2 * dt ** 2 / 2.0, K ** 2 * dt]])
    h, r = np.array([[1.0, 0.0]]), np.array([[SIGMA ** 2]])
    prior = solve_discrete_are(phi.T, h.T, q, r)
    post = prior - prior @ h.T @ np.linalg.inv(h @ prior @ h.T + r) @ h @ prior
    return math.sqrt(post[0, 0]), math.sqrt(post[1, 1])


def test_the_filter_reaches_farrenkopfs_steady_state_and_its_errors_match_it():
    """
    Check the MEKF's steady state against the single-axis theory, over 400 s.

    The filter's post-update attitude sigma per axis within 0.5 % of the theory
    (measured 0.04 %), its bias errors inside 5 sigma of the theory's; the measured
    post-update errors' sigma within 5 % of it (400 s of readings after 100 s of
    convergence: 4000 samples).
    """
    q, est, _, cov_body, bias, bias_est = _run(500.0)
    attitude, bias_sigma = _farrenkopf()
    after = slice(int(100 * RATE), None, EVERY)       # post-update samples
    filter_sigma = np.sqrt(cov_body[after][:, [0, 1, 2], [0, 1, 2]].mean(axis=0))
    assert np.allclose(filter_sigma, attitude, rtol=5e-3), (filter_sigma, attitude)
    errors = quaternions.to_rotation_vector(quaternions.multiply(quaternions.conjugate(q), est))
    assert np.allclose(errors[after].std(axis=0), attitude, rtol=0.05), errors[after].std(axis=0)
    bias_error = (bias_est - bias)[after]
    assert np.all(np.abs(bias_error).max(axis=0) < 5.0 * bias_sigma), (bias_error, bias_sigma)


def test_the_analysis_calls_the_filter_consistent_and_a_detuned_one_overconfident():
    q, est, cov_world, _, bias, bias_est = _run(300.0)
    after = slice(int(60 * RATE), None)
    found = estimation(q[after], est[after], cov_world[after], bias[after], bias_est[after])
    assert found.verdict == 'consistent', found.message
    assert found.nees == pytest.approx(3.0, rel=0.1)
    assert found.correlation > 5.0                     # successive estimates are correlated
    assert 0.99 < found.inside_3_sigma <= 1.0
    assert found.rms_total < 3.0 * SIGMA and found.bias_rms is not None
    q, est, cov_world, *_ = _run(300.0, told_sigma=SIGMA / 10.0)
    found = estimation(q[after], est[after], cov_world[after])
    assert found.verdict == 'overconfident' and found.nees > 30.0, found.message
    assert found.status == 'WARN' and 'overconfident' in found.message


def test_a_filter_told_too_much_noise_is_pessimistic():
    q, est, cov_world, *_ = _run(300.0, told_sigma=SIGMA * 10.0)
    found = estimation(q[6000:], est[6000:], cov_world[6000:])
    assert found.verdict == 'pessimistic', found.message


def test_vector_updates_alone_converge_consistently():
    """Fix the attitude from two known directions (a sun sensor's, a magnetometer's)."""
    t = np.arange(0, 20001) / RATE
    q, w = FreeRigidBody((2.0, 3.0, 1.2), (0.02, -0.01, 0.015), (0, 0, 0, 1)).state_at(t)
    measured, _ = GyroModel(GyroErrors(N, K), RATE, seed=3).sample(w)
    rng = np.random.default_rng(4)
    refs, sigma = (np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.6, 0.8])), 1e-3
    f = MEKF(N, K)
    f.start(quaternions.multiply(q[0], quaternions.from_axis_angle([0, 0, 1], 0.01)),
            np.eye(3) * 1e-4, bias_sigma=1e-4)
    est, cov = [], []
    for k in range(len(t)):
        if k:
            f.propagate(measured[k - 1], 1.0 / RATE)
        if k % EVERY == 0:
            for r in refs:
                turn = quaternions.from_rotation_vector(rng.standard_normal(3) * sigma)
                b = quaternions.rotate(turn, quaternions.rotate_inverse(q[k], r))
                f.update_vector(b, r, sigma ** 2)
        est.append(f.q)
        cov.append(f.attitude_covariance_world())
    found = estimation(q[5000:], np.array(est[5000:]), np.array(cov[5000:]))
    assert found.verdict == 'consistent', found.message
    assert found.rms_total < 2e-3


def test_autocorrelation_time_of_white_and_of_smoothed_noise():
    rng = np.random.default_rng(0)
    white = rng.standard_normal(20000)
    assert autocorrelation_time(white) == pytest.approx(1.0, abs=0.1)
    phi = 0.9                                          # AR(1): tau = (1 + phi) / (1 - phi) = 19
    x = lfilter([1.0], [1.0, -phi], rng.standard_normal(200000))
    assert autocorrelation_time(x) == pytest.approx(19.0, rel=0.1)
