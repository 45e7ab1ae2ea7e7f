"""
The example estimator's use of the readings: the MEKF fed in stamp order (no ROS).

attitude_estimator and the campaign's offline runs both feed
:class:`~rigid_body_dynamics.physics.mekf.MEKF` through :class:`MekfFusion`, so
the estimate of a stream of readings is the same on a topic and offline. The
caller hands the readings over in stamp order, a gyro sample before the
readings of its own stamp. Stamps are int ns of simulated time.

A gyro sample propagates the filter to its stamp with the previous sample's
rate, held, as the gyro integrates it. A star tracker, sun sensor or
magnetometer reading first propagates to its own stamp with the last gyro
rate, then updates. The filter starts at the first star tracker reading. A
reading stamped before the estimate is dropped and counted ``late``.
"""

import math

from .mekf import MEKF

#: The readings a fusion counts, with its gyro samples and late readings.
KINDS = ('star_tracker', 'sun_sensor', 'magnetometer')


class MekfFusion:
    """
    The MEKF and the readings it takes: gyro samples, then star tracker, Sun and field.

    ``noise_density`` and ``bias_walk``: the gyro as the filter believes it
    (rad/s/sqrt(Hz), rad/s^2/sqrt(Hz)). ``tracker_covariance``: 3 x 3 (rad^2,
    body frame) of a star tracker reading. ``bias_sigma``: the bias estimate's
    1 sigma at the start (rad/s per axis). ``sun``: an object with
    ``direction(t)`` (unit vector, world frame; t s) and ``sun_noise`` (rad), for
    the sun sensor; ``field`` (``world(t, position)``, T) with ``orbit``
    (``position(t)``, m) and ``magnetometer_noise`` (T), for the magnetometer.
    A reading whose model is missing, or whose noise is 0, is not used.

    ``counts``: readings used per kind, ``gyro`` samples taken and ``late``
    readings dropped; kept across :meth:`restart`.
    """

    def __init__(self, noise_density, bias_walk, tracker_covariance, bias_sigma=0.0,
                 sun=None, sun_noise=0.0, field=None, orbit=None, magnetometer_noise=0.0):
        self.noise_density, self.bias_walk = noise_density, bias_walk
        self.tracker_covariance = tracker_covariance
        self.bias_sigma = float(bias_sigma)
        self.sun, self.sun_noise = sun, float(sun_noise)
        self.field, self.orbit = field, orbit
        self.magnetometer_noise = float(magnetometer_noise)
        self.counts = dict.fromkeys(('gyro',) + KINDS + ('late',), 0)
        self.restart()

    def restart(self):
        """Forget the estimate (a simulator reset); the counts stay."""
        self.filter = MEKF(self.noise_density, self.bias_walk)
        self.time = None           # the filter's stamp (int ns)
        self.last_gyro = None      # (stamp ns, measured rate) of the last gyro sample

    @property
    def started(self):
        """Whether the filter has an estimate (after the first star tracker reading)."""
        return self.filter.started

    def gyro(self, stamp_ns, omega):
        """
        Take a gyro sample: ``omega`` (rad/s, body frame, bias in it) at ``stamp_ns``.

        Propagates to the stamp with the previous sample's rate; returns whether the
        estimate moved (False before the start).
        """
        last, self.last_gyro = self.last_gyro, (stamp_ns, omega)
        self.counts['gyro'] += 1
        if not self.filter.started:
            return False
        held = omega if last is None else last[1]
        self.filter.propagate(held, (stamp_ns - self.time) * 1e-9)
        self.time = stamp_ns
        return True

    def reading(self, stamp_ns, kind, value):
        """
        Take one reading of ``kind`` at ``stamp_ns``; return whether it was used.

        ``value``: a star tracker's attitude (x, y, z, w, body -> world), a sun
        sensor's unit vector or a magnetometer's field (T), both in the body frame.
        The first star tracker reading starts the filter.
        """
        f = self.filter
        if not f.started:
            if kind != 'star_tracker':
                return False
            f.start(value, self.tracker_covariance, bias_sigma=self.bias_sigma)
            self.time = stamp_ns
            self.counts[kind] += 1
            return True
        if stamp_ns < self.time:
            self.counts['late'] += 1
            return False
        if stamp_ns > self.time and self.last_gyro is not None:   # between two gyro samples
            f.propagate(self.last_gyro[1], (stamp_ns - self.time) * 1e-9)
            self.time = stamp_ns
        if not self._correct(stamp_ns * 1e-9, kind, value):
            return False
        self.counts[kind] += 1
        return True

    def _correct(self, t, kind, value):
        """Apply a reading at t (s); False when the model it needs is not configured."""
        f = self.filter
        if kind == 'star_tracker':
            f.update_attitude(value, self.tracker_covariance)
        elif kind == 'sun_sensor':
            if self.sun is None or not self.sun_noise:
                return False
            f.update_vector(value, self.sun.direction(t), self.sun_noise ** 2)
        else:
            if self.field is None or not self.magnetometer_noise:
                return False
            world = self.field.world(t, self.orbit.position(t))
            size = math.sqrt(sum(c * c for c in world))
            # the reading's noise as an angle: sigma / norm(B)
            f.update_vector(value, world, (self.magnetometer_noise / size) ** 2)
        return True
