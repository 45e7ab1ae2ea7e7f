"""
A rate gyro with the error model calibration tools use, seeded and reproducible (no ROS).

Model (per axis, body frame, samples at ``rate`` Hz, dt = 1 / rate):

    omega_meas[k] = omega[k] + b[k] + n[k],    n[k] ~ N(0, N^2 / dt)
    b[k + 1] = b[k] + K sqrt(dt) w[k]          (bias random walk, correlation_time 0)
    b[k + 1] = phi b[k] + s w[k]               (Gauss-Markov, correlation_time tau > 0)
    phi = exp(-dt / tau),  s = K sqrt(tau / 2 (1 - exp(-2 dt / tau))),  b[0] ~ N(0, bias0^2)

N is the noise density (angle random walk, rad/s/sqrt(Hz)) and K the bias
random walk (rate random walk, rad/s^2/sqrt(Hz)), as Kalibr and Allan-variance
plots name them: the Allan deviation is N / sqrt(tau) for the white noise
(read N at tau = 1 s) and K sqrt(tau / 3) for the walk. With a correlation
time the bias is a first-order Gauss-Markov process whose short-term
increments are those of the walk (s -> K sqrt(dt) for dt << tau) and whose
stationary deviation is K sqrt(tau / 2) - Gazebo's ``dynamic_bias_stddev``
plays the role of K there, which is why its bias wanders by
``dynamic_bias_stddev * sqrt(tau / 2)``, not by ``dynamic_bias_stddev``.
Conversions from Gazebo's per-sample ``stddev``: N = stddev * sqrt(dt); its
turn-on ``bias_stddev`` is ``turn_on_bias`` here (Gazebo also draws a random
sign around ``bias_mean``; not modelled). Orientation noise: a random rotation
whose rotation vector is N(0, sigma^2) per axis, applied in the body frame.

Quantisation (``resolution`` r > 0, rad/s per count, Gazebo's ``precision``
of ``gaussian_quantized``): the reading is rounded to the nearest multiple of
r, which adds r^2 / 12 of variance per sample that the Imu covariance (N^2 *
rate) does not include, and makes readings of a still gyro exact multiples of r.

A perfect gyro (every parameter 0) returns the truth exactly and draws
nothing. The same seed and parameters give the same stream, bit for bit,
whether it is drawn sample by sample (:meth:`GyroModel.measure`) or in
blocks (:meth:`GyroModel.sample`).
"""

from dataclasses import dataclass
import math
from typing import NamedTuple

import numpy as np

from .. import quaternions


@dataclass(frozen=True)
class GyroErrors:
    """
    Error parameters of a gyro, all >= 0 and finite; 0 switches the term off.

    ``noise_density`` N (rad/s/sqrt(Hz)); ``bias_random_walk`` K
    (rad/s^2/sqrt(Hz)); ``turn_on_bias`` stddev of b[0] (rad/s);
    ``correlation_time`` tau (s, 0 = a pure random walk); ``orientation_noise``
    stddev (rad) of the rotation applied to the reported orientation;
    ``resolution`` (rad/s per count, 0 = no quantisation).
    """

    noise_density: float = 0.0
    bias_random_walk: float = 0.0
    turn_on_bias: float = 0.0
    correlation_time: float = 0.0
    orientation_noise: float = 0.0
    resolution: float = 0.0

    def __post_init__(self):
        """Refuse negative or non-finite values, naming the parameter."""
        for name in ('noise_density', 'bias_random_walk', 'turn_on_bias', 'correlation_time',
                     'orientation_noise', 'resolution'):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0):
                raise ValueError(f'{name} must be a finite number >= 0, got {value!r}')

    @classmethod
    def from_gazebo(cls, stddev, rate, bias_stddev=0.0, dynamic_bias_stddev=0.0,
                    dynamic_bias_correlation_time=0.0):
        """Convert Gazebo / SDFormat ``<noise>`` values (per sample) at ``rate`` Hz."""
        return cls(noise_density=stddev / math.sqrt(rate), turn_on_bias=bias_stddev,
                   bias_random_walk=dynamic_bias_stddev,
                   correlation_time=dynamic_bias_correlation_time)


class GyroModel:
    """
    A seeded gyro sampling at ``rate`` Hz with :class:`GyroErrors` ``errors``.

    Draws from ``rng`` when given (a numpy Generator), else from its own
    generator seeded ``seed``.

    ``bias`` is the current true bias (rad/s, body frame, 3 axes), for
    estimator evaluation.
    """

    def __init__(self, errors, rate, seed=0, rng=None):
        if not (rate > 0.0 and math.isfinite(rate)):
            raise ValueError(f'rate must be positive and finite, got {rate!r}')
        self.errors = errors
        self.rate = float(rate)
        self.dt = 1.0 / self.rate
        self._rng = np.random.default_rng(seed) if rng is None else rng
        self._white = errors.noise_density / math.sqrt(self.dt)
        tau, k = errors.correlation_time, errors.bias_random_walk
        if tau > 0.0:
            self._phi = math.exp(-self.dt / tau)
            self._walk = k * math.sqrt(0.5 * tau * -math.expm1(-2.0 * self.dt / tau))
        else:
            self._phi, self._walk = 1.0, k * math.sqrt(self.dt)
        self.bias = (self._rng.standard_normal(3) * errors.turn_on_bias
                     if errors.turn_on_bias else np.zeros(3))
        self._perfect = not (self._white or self._walk)

    @property
    def rate_variance(self):
        """Variance (rad/s)^2 of the white noise per sample: N^2 * rate (the Imu covariance)."""
        return self._white ** 2

    @property
    def orientation_variance(self):
        """Variance (rad^2) per axis of the orientation noise."""
        return self.errors.orientation_noise ** 2

    def measure(self, omega):
        """Measure one sample: (measured rate, the bias in it), both (3,) rad/s, body frame."""
        measured, bias = self.sample(np.asarray(omega, dtype=float).reshape(1, 3))
        return measured[0], bias[0]

    def sample(self, omega):
        """
        Measure consecutive true rates ``omega`` (N, 3) rad/s: returns (measured, bias) (N, 3).

        Draws per sample first the white noise, then the bias increment (3 normals
        each), so blocks and single samples give the same stream.
        """
        omega = np.asarray(omega, dtype=float).reshape(-1, 3)
        n = omega.shape[0]
        if self._perfect:       # no draws: the truth plus the constant turn-on bias (or 0)
            bias = np.repeat(self.bias[None, :], n, axis=0)
            return self._quantise(omega + bias), bias
        draws = self._rng.standard_normal((n, 2, 3))
        phi, walk = self._phi, self._walk
        if phi == 1.0:      # a random walk: b[k] = ((b[0] + s w[0]) + s w[1]) ..., in order
            path = np.cumsum(np.concatenate([self.bias[None, :], walk * draws[:, 1]]), axis=0)
            bias, self.bias = path[:-1], path[-1]
        else:
            bias = np.empty((n, 3))
            b = self.bias
            for k in range(n):
                bias[k] = b
                b = phi * b + walk * draws[k, 1]
            self.bias = b
        return self._quantise(omega + bias + self._white * draws[:, 0]), bias

    def _quantise(self, rates):
        r = self.errors.resolution
        return np.round(rates / r) * r if r else rates

    def read(self, q, omega):
        """
        Take one IMU reading of the true attitude q (x, y, z, w) and rate omega (3,) rad/s.

        Returns (reported q, measured rate, bias in it) as tuples of floats, body
        frame: the rate is drawn first, then the orientation noise, the order the
        simulator uses, so a stream offline and one over topics are the same.
        The same numbers as :meth:`measure` (tested bit for bit), in scalar
        arithmetic: the simulator reads its gyro at every IMU tick, and numpy's
        per-call cost made a reading 29 us (56 us with noise) where this takes
        a few.
        """
        bias = self.bias
        b = (float(bias[0]), float(bias[1]), float(bias[2]))
        w = (float(omega[0]), float(omega[1]), float(omega[2]))
        if self._perfect:
            rates = (w[0] + b[0], w[1] + b[1], w[2] + b[2])
        else:
            # the draws of sample(): white noise, then the bias increment, 3 normals each
            d = self._rng.standard_normal(6).tolist()
            white, phi, walk = self._white, self._phi, self._walk
            rates = (w[0] + b[0] + white * d[0], w[1] + b[1] + white * d[1],
                     w[2] + b[2] + white * d[2])
            if phi == 1.0:
                self.bias = np.array((b[0] + walk * d[3], b[1] + walk * d[4],
                                      b[2] + walk * d[5]))
            else:
                self.bias = np.array((phi * b[0] + walk * d[3], phi * b[1] + walk * d[4],
                                      phi * b[2] + walk * d[5]))
        r = self.errors.resolution
        if r:
            rates = (round(rates[0] / r) * r, round(rates[1] / r) * r, round(rates[2] / r) * r)
        if self.errors.orientation_noise:
            q = tuple(self.orientation(q).tolist())
        else:
            q = (float(q[0]), float(q[1]), float(q[2]), float(q[3]))
        return q, rates, b

    def orientation(self, q):
        """Return the attitude q (x, y, z, w) with the orientation noise applied (body frame)."""
        sigma = self.errors.orientation_noise
        if not sigma:
            return np.asarray(q, dtype=float)
        v = self._rng.standard_normal(3) * sigma
        angle = float(np.linalg.norm(v))
        axis = v / angle if angle > 0.0 else np.array([1.0, 0.0, 0.0])
        return quaternions.multiply(np.asarray(q, dtype=float),
                                    quaternions.from_axis_angle(axis, angle))


class GyroReading(NamedTuple):
    """
    One IMU reading, body frame: the reported attitude ``q_body`` (x, y, z, w).

    Also the measured rate ``omega_body`` (rad/s), the true ``bias_body`` in it
    (rad/s), and the ``rate_variance`` (rad/s)^2 and ``orientation_variance``
    (rad^2) per axis that the Imu message's covariances carry.
    """

    q_body: tuple
    omega_body: tuple
    bias_body: tuple
    rate_variance: float
    orientation_variance: float


class Gyro:
    """
    The gyro as a sensor on the protocol of :mod:`.base`: :class:`GyroErrors` at ``rate`` Hz.

    Its stream is the seed alone (``stream`` None), as before sensors had streams
    of their own. :meth:`start` makes its :class:`GyroModel` at the rate it
    actually samples at (the turn-on bias is drawn there).
    """

    name = 'gyro'
    stream = None

    def __init__(self, errors, rate):
        if not (rate > 0.0 and math.isfinite(rate)):
            raise ValueError(f'imu_rate must be positive and finite, got {rate!r}')
        self.errors, self.rate = errors, float(rate)
        self.model = None

    def start(self, rng, rate):
        """Start again: a fresh :class:`GyroModel` at ``rate`` Hz drawing from ``rng``."""
        self.model = GyroModel(self.errors, rate, rng=rng)

    def sample(self, state, t, rng):
        """Return a :class:`GyroReading` of ``state`` (its rate first, then its attitude)."""
        model = self.model
        q, measured, bias = model.read(state.q, state.omega)
        return GyroReading(q, measured, bias, model.rate_variance, model.orientation_variance)


def allan_deviation(rates, rate, taus):
    """
    Overlapping Allan deviation of a rate signal at cluster times ``taus`` (s).

    ``rates`` (N,) rad/s sampled at ``rate`` Hz; each tau is rounded to a whole
    number m of samples (1 <= m <= (N - 1) / 2). Returns (the taus used (s),
    the deviations (rad/s)); white noise of density N gives N / sqrt(tau), a
    bias random walk K gives K sqrt(tau / 3). Written here rather than taken
    from allantools (which the tests compare it with) so that the report
    needs no package a ROS install lacks.
    """
    x = np.asarray(rates, dtype=float).ravel()
    theta = np.concatenate(([0.0], np.cumsum(x))) / rate       # integrated angle (rad)
    n = x.size
    ms = np.unique(np.clip(np.round(np.asarray(taus, dtype=float) * rate), 1, (n - 1) // 2)
                   ).astype(int)
    out = np.empty(ms.size)
    for i, m in enumerate(ms):
        tau = m / rate
        d = theta[2 * m:] - 2.0 * theta[m:-m] + theta[:-2 * m]
        out[i] = math.sqrt(np.mean(d * d) / (2.0 * tau * tau))
    return ms / rate, out
