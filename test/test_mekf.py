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
from scipy.spatial.transform import Rotation
import stat_checks

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
    (measured 0.04 %: a covariance, no noise in it). The measured post-update
    attitude errors' and bias errors' mean squares per axis inside the
    chi-square interval of the theory's variance for their independent samples
    (4000 correlated samples each, counted by the autocorrelation time of the
    squares), the six checks failing a correct filter with probability 1e-4
    together. The attitude errors have about 1000 independent samples (an
    interval of 0.82 to 1.2 sigma^2), and errors 25 % larger fail it; the bias
    errors about 10 (0.05 to 4 sigma^2: 400 s hold few independent bias errors).
    """
    q, est, _, cov_body, bias, bias_est = _run(500.0)
    attitude, bias_sigma = _farrenkopf()
    after = slice(int(100 * RATE), None, EVERY)       # post-update samples
    filter_sigma = np.sqrt(cov_body[after][:, [0, 1, 2], [0, 1, 2]].mean(axis=0))
    assert np.allclose(filter_sigma, attitude, rtol=5e-3), (filter_sigma, attitude)
    errors = quaternions.to_rotation_vector(quaternions.multiply(quaternions.conjugate(q), est))
    each = stat_checks.share(6)
    for series, sigma in ((errors[after], attitude), ((bias_est - bias)[after], bias_sigma)):
        for axis in range(3):
            x = series[:, axis]
            low, high, n_eff = stat_checks.correlated_mean_square_interval(x, sigma, each)
            assert low < np.mean(x * x) < high, (axis, np.mean(x * x) / sigma ** 2, n_eff)
            print(axis, np.mean(x * x) / sigma ** 2, low / sigma ** 2, high / sigma ** 2, n_eff)


def test_the_analysis_calls_the_filter_consistent_and_a_detuned_one_overconfident():
    q, est, cov_world, _, bias, bias_est = _run(300.0)
    after = slice(int(60 * RATE), None)
    found = estimation(q[after], est[after], cov_world[after], bias[after], bias_est[after],
                       level=1.0 - stat_checks.FALSE_FAILURE)
    assert found.verdict == 'consistent', found.message
    assert found.correlation > 2.0                     # successive estimates are correlated
    assert 0.99 < found.inside_3_sigma <= 1.0
    assert found.rms_total < 3.0 * SIGMA and found.bias_rms is not None
    q, est, cov_world, *_ = _run(300.0, told_sigma=SIGMA / 10.0)
    found = estimation(q[after], est[after], cov_world[after])
    assert found.verdict == 'overconfident' and found.nees > 30.0, found.message
    assert found.status == 'WARN' and 'overconfident' in found.message


def test_a_filter_told_too_much_noise_is_pessimistic():
    q, est, cov_world, *_ = _run(300.0, told_sigma=SIGMA * 10.0)
    found = estimation(q[6000:], est[6000:], cov_world[6000:],
                       level=1.0 - stat_checks.FALSE_FAILURE)
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
    found = estimation(q[5000:], np.array(est[5000:]), np.array(cov[5000:]),
                       level=1.0 - stat_checks.FALSE_FAILURE)
    assert found.verdict == 'consistent', found.message
    assert found.rms_total < 2e-3


def _ar1(seed, phi, n, columns=None):
    """Return a stationary AR(1) series of unit variance, coefficient phi: (n,) or (n, m)."""
    shape = (n + 1000,) if columns is None else (n + 1000, columns)
    w = np.random.default_rng(seed).standard_normal(shape)
    return lfilter([math.sqrt(1.0 - phi * phi)], [1.0, -phi], w, axis=0)[1000:]


@pytest.mark.parametrize('phi', [0.0, 0.5, 0.9])
def test_autocorrelation_time_is_unbiased_over_200_seeds(phi):
    """
    Check Geyer's estimate of tau against the AR(1)'s (1 + phi) / (1 - phi), over 200 seeds.

    20 000 samples each: the mean of tau_hat / tau within 2 % of 1 (Geyer's
    estimator sums the positive pairs of autocorrelations only, a bias of
    +1.2 to +1.5 % here, measured) widened by the sampling error of the mean of 200
    at a false-failure rate of 1e-4 (one estimate's spread: 2 % white, 9 % at
    phi = 0.9). The maximum of two estimates this replaced had a mean of 1.19 on
    white noise.
    """
    tau = (1.0 + phi) / (1.0 - phi)
    ratios = np.array([autocorrelation_time(_ar1(seed, phi, 20_000)) for seed in range(200)]) / tau
    margin = 0.02 + stat_checks.mean_bound(ratios.std(ddof=1), len(ratios), stat_checks.share(2))
    assert abs(ratios.mean() - 1.0) < margin, (ratios.mean(), margin)


def test_autocorrelation_time_averages_the_columns_and_sees_a_long_correlation():
    three = _ar1(3, 0.9, 20_000, columns=3)
    assert autocorrelation_time(three) == pytest.approx(19.0, rel=0.15)
    assert autocorrelation_time(np.ones(50)) == 1.0             # no variance: no correlation
    # a long excursion over white noise: 4 blocks of 1000 samples displaced by +-1 sigma
    rng = np.random.default_rng(4)
    x = rng.standard_normal(20_000)
    x[2000:3000] += 1.0
    x[7000:8000] -= 1.0
    x[12000:13000] += 1.0
    x[17000:18000] -= 1.0
    # the variance of its mean: 20 000 white (variance 1) plus the blocks', by batch means
    # over blocks of 1000: tau ~ (1 + 4 * 1000 ** 2 / 20_000) / (1 + 4 * 1000 / 20_000) = 168
    assert autocorrelation_time(x) > 80.0


@pytest.mark.parametrize('phi', [0.0, 0.9])
def test_the_nees_verdict_calls_a_consistent_estimator_inconsistent_at_its_stated_rate(phi):
    """
    Judge 1000 synthetic consistent estimators and count the verdicts that are not 'consistent'.

    The errors an AR(1) of coefficient phi per world axis, with the covariance the
    estimator reports: a consistent estimator, 3000 estimates each. At level 0.95
    the count must be inside the binomial interval of rates 4 to 7.5 % (measured 5.4 %
    white, 6.4 % at phi = 0.9: the autocorrelation time is itself estimated) at a
    false-failure rate of 1e-4. The whitened errors' tau (what the interval counted
    before) gave 0.3 % at phi = 0.9: "consistent" was too easy. And an estimator whose
    covariance is 20 % too small is called overconfident in most runs.
    """
    sigma, n = 1e-3, 3000
    q_true = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
    covariances = np.tile(np.eye(3) * sigma ** 2, (n, 1, 1))
    verdicts = []
    for seed in range(1000):
        errors = _ar1(seed, phi, n, columns=3) * sigma
        q_est = Rotation.from_rotvec(errors).as_quat()
        verdicts.append(estimation(q_true, q_est, covariances).verdict)
        if seed < 200:
            told_less = estimation(q_true, q_est, covariances * 0.8).verdict
            verdicts.append('overconfident ok' if told_less == 'overconfident' else 'missed')
    wrong = sum(v in ('overconfident', 'pessimistic') for v in verdicts)
    low, high = stat_checks.binomial_count_interval(1000, 0.04, 0.075)
    assert low <= wrong <= high, (wrong, low, high)
    assert verdicts.count('overconfident ok') > 0.9 * 200, verdicts.count('missed')
