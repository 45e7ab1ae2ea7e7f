"""The gyro error model (physics/sensors.py): statistics against its definition, seeds, edges."""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics import quaternions
from rigid_body_dynamics.physics.sensors import GyroErrors, GyroModel

RATE = 100.0


def allan_deviation(x, rate, tau):
    """Non-overlapping Allan deviation of a rate signal x (N,) at cluster time tau (s)."""
    m = int(round(tau * rate))
    clusters = x[:x.size // m * m].reshape(-1, m).mean(axis=1)
    return math.sqrt(0.5 * np.mean(np.diff(clusters) ** 2))


def test_a_perfect_gyro_returns_the_truth_exactly():
    omega = np.random.default_rng(1).normal(size=(50, 3))
    gyro = GyroModel(GyroErrors(), RATE, seed=3)
    measured, bias = gyro.sample(omega)
    assert np.array_equal(measured, omega) and not np.any(bias)
    assert gyro.rate_variance == 0.0 and gyro.orientation_variance == 0.0
    assert np.array_equal(gyro.orientation((0.1, 0.2, 0.3, 0.9)), [0.1, 0.2, 0.3, 0.9])


def test_white_noise_per_sample_and_allan_deviation_give_the_density():
    """N = 1e-3 rad/s/sqrt(Hz) at 100 Hz: per-sample stddev N sqrt(rate) = 1e-2; ADEV(1 s) = N."""
    gyro = GyroModel(GyroErrors(noise_density=1e-3), RATE, seed=11)
    measured, _ = gyro.sample(np.zeros((200_000, 3)))     # 2000 s
    assert measured.std(axis=0) == pytest.approx([1e-2] * 3, rel=0.01)
    assert gyro.rate_variance == pytest.approx(1e-4, rel=1e-12)
    for axis in range(3):
        assert allan_deviation(measured[:, axis], RATE, 1.0) == pytest.approx(1e-3, rel=0.06)


def test_bias_random_walk_increments_and_allan_slope():
    """K = 1e-4 rad/s^2/sqrt(Hz): increments K sqrt(dt) per sample; ADEV(tau) = K sqrt(tau / 3)."""
    gyro = GyroModel(GyroErrors(bias_random_walk=1e-4), RATE, seed=12)
    measured, bias = gyro.sample(np.zeros((400_000, 3)))  # 4000 s
    steps = np.diff(bias, axis=0)
    assert steps.std() == pytest.approx(1e-4 * math.sqrt(0.01), rel=0.01)
    assert np.array_equal(measured, bias)                  # no white noise: the bias itself
    adev = np.mean([allan_deviation(measured[:, a], RATE, 30.0) for a in range(3)])
    assert adev == pytest.approx(1e-4 * math.sqrt(30.0 / 3.0), rel=0.15)


def test_gauss_markov_bias_stationary_deviation_and_correlation():
    """A 5 s correlation time: lag-1 correlation exp(-dt / tau), deviation K sqrt(tau / 2)."""
    k, tau = 2e-4, 5.0
    gyro = GyroModel(GyroErrors(bias_random_walk=k, correlation_time=tau), RATE, seed=13)
    _, bias = gyro.sample(np.zeros((500_000, 3)))          # 5000 s = 1000 tau
    assert bias.std() == pytest.approx(k * math.sqrt(tau / 2.0), rel=0.05)
    b = bias[:, 0] - bias[:, 0].mean()
    assert np.dot(b[1:], b[:-1]) / np.dot(b, b) == pytest.approx(math.exp(-0.01 / tau), abs=1e-3)


def test_turn_on_bias_over_seeds():
    b0 = np.array([GyroModel(GyroErrors(turn_on_bias=0.01), RATE, seed=s).bias
                   for s in range(3000)])
    assert b0.std() == pytest.approx(0.01, rel=0.05) and abs(b0.mean()) < 1e-3
    gyro = GyroModel(GyroErrors(turn_on_bias=0.01), RATE, seed=5)
    measured, bias = gyro.sample(np.ones((10, 3)))
    assert np.array_equal(measured, 1.0 + bias) and np.all(bias == gyro.bias)


def test_same_seed_same_stream_bit_for_bit_single_or_in_blocks():
    errors = GyroErrors(noise_density=1e-3, bias_random_walk=1e-4, turn_on_bias=1e-3)
    omega = np.random.default_rng(2).normal(size=(300, 3))
    a, bias_a = GyroModel(errors, RATE, seed=7).sample(omega)
    one = GyroModel(errors, RATE, seed=7)
    b = np.array([one.measure(w)[0] for w in omega])
    c, _ = GyroModel(errors, RATE, seed=8).sample(omega)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    blocks = GyroModel(errors, RATE, seed=7)
    d = np.concatenate([blocks.sample(omega[:120])[0], blocks.sample(omega[120:])[0]])
    assert np.array_equal(a, d)


@pytest.mark.parametrize('errors', [
    GyroErrors(),
    GyroErrors(turn_on_bias=1e-3),
    GyroErrors(noise_density=1e-3, bias_random_walk=1e-4, turn_on_bias=1e-3),
    GyroErrors(noise_density=1e-3, bias_random_walk=1e-4, correlation_time=2.0),
    GyroErrors(noise_density=1e-3, bias_random_walk=1e-4, resolution=1e-3),
    GyroErrors(noise_density=1e-3, bias_random_walk=1e-4, orientation_noise=0.01),
], ids=['perfect', 'turn-on bias', 'random walk', 'gauss-markov', 'quantised', 'orientation'])
def test_read_in_scalars_equals_the_vectorised_model_bit_for_bit(errors):
    """read() (the simulator's per-tick path, plain floats) draws and computes as sample()."""
    rng = np.random.default_rng(3)
    omega = rng.normal(size=(200, 3))
    q = rng.normal(size=(200, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    fast, ref = GyroModel(errors, RATE, seed=11), GyroModel(errors, RATE, seed=11)
    for qk, wk in zip(q, omega):
        q_read, measured, bias = fast.read(tuple(qk), tuple(wk))
        m_ref, b_ref = ref.measure(wk)
        assert measured == tuple(m_ref) and bias == tuple(b_ref)
        assert q_read == tuple(ref.orientation(qk))
        assert all(type(c) is float for c in (*q_read, *measured, *bias))
    assert np.array_equal(fast.bias, ref.bias)
    if errors.resolution:
        assert np.allclose(np.asarray(measured) / errors.resolution,
                           np.round(np.asarray(measured) / errors.resolution), atol=1e-9)


def test_orientation_noise_statistics():
    gyro = GyroModel(GyroErrors(orientation_noise=0.01), RATE, seed=9)
    q0 = quaternions.from_axis_angle(np.array([0.0, 0.0, 1.0]), 0.7)
    angles = np.array([float(quaternions.angle_between(q0, gyro.orientation(q0)))
                       for _ in range(5000)])
    # the angle of a rotation vector N(0, sigma^2 I3) has mean sigma sqrt(8 / pi)
    assert angles.mean() == pytest.approx(0.01 * math.sqrt(8.0 / math.pi), rel=0.03)
    assert gyro.orientation_variance == pytest.approx(1e-4)


def test_gazebo_conversion_and_bad_parameters():
    errors = GyroErrors.from_gazebo(stddev=0.009, rate=400.0, bias_stddev=0.002,
                                    dynamic_bias_stddev=4e-6,
                                    dynamic_bias_correlation_time=1000.0)
    assert errors.noise_density == pytest.approx(0.009 / 20.0)
    assert (errors.turn_on_bias, errors.bias_random_walk, errors.correlation_time) == (
        0.002, 4e-6, 1000.0)
    for name in ('noise_density', 'bias_random_walk', 'turn_on_bias', 'correlation_time',
                 'orientation_noise', 'resolution'):
        with pytest.raises(ValueError, match=name):
            GyroErrors(**{name: -1.0})
        with pytest.raises(ValueError, match=name):
            GyroErrors(**{name: math.nan})
    with pytest.raises(ValueError, match='rate'):
        GyroModel(GyroErrors(), 0.0)


def test_allan_deviation_equals_allantools_overlapping_adev():
    """physics.sensors.allan_deviation against allantools.oadev (frequency data) to 1e-12."""
    import allantools
    from rigid_body_dynamics.physics.sensors import allan_deviation
    gyro = GyroModel(GyroErrors(noise_density=1e-3, bias_random_walk=1e-4), RATE, seed=21)
    x = gyro.sample(np.zeros((20_000, 3)))[0][:, 0]
    taus, adev = allan_deviation(x, RATE, [0.01, 0.1, 0.5, 1.0, 3.0, 10.0, 50.0])
    ref_taus, ref, _, _ = allantools.oadev(x, rate=RATE, data_type='freq', taus=taus)
    np.testing.assert_allclose(ref_taus, taus, rtol=1e-12)
    np.testing.assert_allclose(adev, ref, rtol=1e-12)


def test_four_hours_of_gyro_read_n_at_1_s_and_k_at_3_s_within_5_percent():
    """
    A user's N = 1e-3 rad/s/sqrt(Hz) and K = 1e-5 rad/s^2/sqrt(Hz), 4 h at 100 Hz, 3 axes.

    Each term alone (the other would dominate at the reading point): white noise gives
    ADEV(1 s) = N, the bias random walk ADEV(3 s) = K, within 5 % (mean over the axes).
    """
    from rigid_body_dynamics.physics.sensors import allan_deviation
    samples = int(4 * 3600 * RATE)
    white = GyroModel(GyroErrors(noise_density=1e-3), RATE, seed=31).sample(
        np.zeros((samples, 3)))[0]
    walk = GyroModel(GyroErrors(bias_random_walk=1e-5), RATE, seed=32).sample(
        np.zeros((samples, 3)))[0]
    n_read = np.mean([allan_deviation(white[:, a], RATE, [1.0])[1][0] for a in range(3)])
    k_read = np.mean([allan_deviation(walk[:, a], RATE, [3.0])[1][0] for a in range(3)])
    assert n_read == pytest.approx(1e-3, rel=0.05)
    assert k_read == pytest.approx(1e-5, rel=0.05)


def test_simulate_with_a_gyro_reads_the_run_at_the_gyro_rate():
    """simulate(gyro=...) reads the trajectory at every 5th step, in the node's draw order."""
    from rigid_body_dynamics.physics import simulate
    errors = GyroErrors(noise_density=1e-3, bias_random_walk=1e-4, turn_on_bias=1e-3,
                        orientation_noise=0.01)
    run = simulate((1.0, 2.0, 3.0), (0.3, 1.5, -0.4), duration=1.0, dt=1e-3,
                   gyro=GyroModel(errors, 200.0, seed=4))
    imu = run.imu
    assert imu.rate == 200.0 and imu.t.shape == (201,)
    np.testing.assert_allclose(imu.t, run.t[::5], rtol=0, atol=1e-15)
    ref = GyroModel(errors, 200.0, seed=4)
    readings = [ref.read(q, w) for q, w in zip(run.q[::5], run.omega[::5])]
    np.testing.assert_array_equal(imu.q, [r[0] for r in readings])
    np.testing.assert_array_equal(imu.omega, [r[1] for r in readings])
    np.testing.assert_array_equal(imu.bias, [r[2] for r in readings])
    assert np.max(np.abs(imu.omega - run.omega[::5])) > 1e-3
    with pytest.raises(ValueError, match='whole fraction'):
        simulate((1.0, 2.0, 3.0), (0.3, 1.5, -0.4), duration=0.1, dt=1e-3,
                 gyro=GyroModel(errors, 300.0))


def test_quantised_readings_are_whole_counts_with_the_r2_over_12_variance():
    """Resolution r = 1e-3 rad/s on white noise 1e-2 per sample: counts, variance + r^2/12."""
    r = 1e-3
    gyro = GyroModel(GyroErrors(noise_density=1e-3, resolution=r), RATE, seed=41)
    plain = GyroModel(GyroErrors(noise_density=1e-3), RATE, seed=41)
    omega = np.full((200_000, 3), 0.123456)
    measured, _ = gyro.sample(omega)
    exact, _ = plain.sample(omega)
    counts = measured / r
    np.testing.assert_allclose(counts, np.round(counts), rtol=0, atol=1e-6)
    assert np.max(np.abs(measured - exact)) <= 0.5 * r * (1 + 1e-9)   # nearest count
    error = measured - exact
    assert error.var() == pytest.approx(r * r / 12.0, rel=0.02)
    assert gyro.rate_variance == plain.rate_variance                  # N^2 rate, as documented
    still = GyroModel(GyroErrors(resolution=0.01), RATE).sample(np.full((3, 3), 0.123))[0]
    np.testing.assert_allclose(still, 0.12, rtol=0, atol=1e-15)
