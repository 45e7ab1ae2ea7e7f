"""
A three-axis magnetometer: the field in the body frame plus a constant bias and white noise.

    B_meas = B_body + b + n,   n ~ N(0, sigma^2 I3) per sample

(T; body frame). ``noise`` sigma (T, 1 sigma per axis) and ``bias`` b (T, body
frame) are the simulator's ``magnetometer_noise`` and ``magnetometer_bias``; the
covariance a reading reports is sigma^2 on the diagonal (the bias is not in it:
an estimator must calibrate it). Seeded: the same seed gives the same stream,
and a stream of its own, so turning the magnetometer on does not change the
gyro's noise.
"""

import math

import numpy as np


class Magnetometer:
    """A seeded magnetometer: ``noise`` (T, >= 0), ``bias`` (3, T, body), ``seed`` (int)."""

    #: The stream's second seed word: the gyro draws from seed alone.
    STREAM = 1

    def __init__(self, noise=0.0, bias=(0.0, 0.0, 0.0), seed=0):
        if not (math.isfinite(noise) and noise >= 0.0):
            raise ValueError(f'magnetometer_noise must be a finite number >= 0 (T), got {noise!r}')
        bias = tuple(float(c) for c in bias)
        if len(bias) != 3 or not all(math.isfinite(c) for c in bias):
            raise ValueError(f'magnetometer_bias must be three finite numbers (T), got {bias!r}')
        self.noise, self.bias = float(noise), bias
        self.variance = self.noise ** 2
        self._rng = np.random.default_rng([int(seed), self.STREAM])

    def read(self, field_body):
        """Return the measured field (T, body frame, a tuple) for the true ``field_body`` (T)."""
        b = self.bias
        x, y, z = (float(c) for c in field_body)
        if self.noise:
            n = (self._rng.standard_normal(3) * self.noise).tolist()
            return (x + b[0] + n[0], y + b[1] + n[1], z + b[2] + n[2])
        return (x + b[0], y + b[1], z + b[2])
