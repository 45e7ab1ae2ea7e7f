"""
A three-axis magnetometer: the field in the body frame plus a constant bias and white noise.

    B_meas = B_body + b + n,   n ~ N(0, sigma^2 I3) per sample

(T; body frame). ``noise`` sigma (T, 1 sigma per axis) and ``bias`` b (T, body
frame) are the simulator's ``magnetometer_noise`` and ``magnetometer_bias``; the
covariance a reading reports is sigma^2 on the diagonal (the bias is not in it:
an estimator must calibrate it). A sensor on the protocol of :mod:`.base`, with
a stream of its own (``stream`` 1), so turning the magnetometer on does not
change the gyro's noise.
"""

from typing import NamedTuple

from .base import check_rate, check_scalar, check_vector
from .. import quaternions as quat


class MagnetometerReading(NamedTuple):
    """One reading: ``field`` (T, body frame) and the white noise's ``variance`` (T^2 per axis)."""

    field: tuple
    variance: float


class Magnetometer:
    """A magnetometer at ``rate`` Hz: ``noise`` (T, >= 0), ``bias`` (3, T, body)."""

    name = 'magnetometer'
    stream = 1

    def __init__(self, rate, noise=0.0, bias=(0.0, 0.0, 0.0)):
        self.rate = check_rate('magnetometer_rate', rate)
        self.noise = check_scalar('magnetometer_noise', noise, 'T', 1.0)
        self.bias = check_vector('magnetometer_bias', bias, 'T')
        self.variance = self.noise ** 2

    def start(self, rng, rate):
        """Start (the bias is a parameter: nothing to draw)."""

    def read(self, field_body, rng):
        """Return the measured field (T, body frame, a tuple) for the true ``field_body`` (T)."""
        b = self.bias
        x, y, z = (float(c) for c in field_body)
        if self.noise:
            n = (rng.standard_normal(3) * self.noise).tolist()
            return (x + b[0] + n[0], y + b[1] + n[1], z + b[2] + n[2])
        return (x + b[0], y + b[1], z + b[2])

    def sample(self, state, t, rng):
        """Return a :class:`MagnetometerReading` of ``state`` at t (s)."""
        q = state.q
        b_world = state.sky.field_world(t, state.position)
        b_body = quat.rotate_components((-q[0], -q[1], -q[2], q[3]), b_world)
        return MagnetometerReading(self.read(b_body, rng), self.variance)
