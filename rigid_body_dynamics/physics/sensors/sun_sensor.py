"""
A sun sensor: the unit Sun direction in the body frame, turned by a small random rotation.

    s_m = exp([e]x) s_body,   e ~ N(0, noise^2 I3)

(rad per axis: the pointing error then has E[angle^2] = 2 noise^2, the
rotation about s itself changing nothing). A reading exists only when the Sun
is within ``fov`` (half-angle, rad; pi = all directions) of the ``boresight``
(a body unit vector) and the body is not in the planet's shadow; otherwise the
engine counts it as ``'fov'`` or ``'eclipse'``. In the conical shadow's penumbra
the sensor reads while at least ``min_light`` of the Sun's disc is uncovered
(and never in umbra), and then reads the direction to the disc's centre: the
visible part's centroid is off it by less than the Sun's angular radius
(4.65e-3 rad), which this model neglects.
"""

import math
from typing import NamedTuple

from .base import check_rate, check_scalar, check_vector
from .. import quaternions as quat


class SunSensorReading(NamedTuple):
    """One sun sensor reading: the measured unit ``direction`` (body) and ``variance`` (rad^2)."""

    direction: tuple
    variance: float


class SunSensor:
    """
    A sun sensor at ``rate`` Hz: ``noise`` (rad), ``boresight`` (body), ``fov`` (rad).

    ``min_light`` (0 to 1): the fraction of the Sun's disc it needs uncovered.

    Bad values raise ValueError naming the simulator's parameter.
    """

    name = 'sun_sensor'
    stream = 3

    def __init__(self, rate, noise=0.0, boresight=(0.0, 0.0, 1.0), fov=math.pi,
                 min_light=0.5):
        self.rate = check_rate('sun_sensor_rate', rate)
        self.noise = check_scalar('sun_sensor_noise', noise, 'rad', 1.0)
        b = check_vector('sun_sensor_boresight', boresight, 'body unit vector')
        n = math.sqrt(sum(c * c for c in b))
        if n == 0.0:
            raise ValueError('sun_sensor_boresight must not be zero')
        self.boresight = tuple(c / n for c in b)
        self.fov = check_scalar('sun_sensor_fov', fov, 'rad', math.pi)
        self.variance = self.noise ** 2
        self.min_light = check_scalar('sun_sensor_min_light', min_light, 'of the disc', 1.0)

    def start(self, rng, rate):
        """Start (nothing to draw)."""

    def sample(self, state, t, rng):
        """Return a :class:`SunSensorReading` of ``state`` at t (s), or why there is none."""
        e = (rng.standard_normal(3) * self.noise).tolist()      # drawn whatever the view
        sky = state.sky
        light = sky.light(t, state.position)
        if light <= 0.0 or light < self.min_light:
            return 'eclipse'
        q = state.q
        s = quat.rotate_components((-q[0], -q[1], -q[2], q[3]), sky.sun_world(t))
        b = self.boresight
        if self.fov < math.pi:
            cos = s[0] * b[0] + s[1] * b[1] + s[2] * b[2]
            sin = math.sqrt((s[1] * b[2] - s[2] * b[1]) ** 2 + (s[2] * b[0] - s[0] * b[2]) ** 2
                            + (s[0] * b[1] - s[1] * b[0]) ** 2)
            if math.atan2(sin, cos) > self.fov:
                return 'fov'
        m = quat.rotate_components(quat.from_rotation_vector(e), s) if self.noise else s
        n = math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
        return SunSensorReading((m[0] / n, m[1] / n, m[2] / n), self.variance)
