"""
Sensors (no ROS), each on the protocol of :mod:`.base` (``sample(state, t, rng)``).

The rate gyro (:mod:`.gyro`), the magnetometer (:mod:`.magnetometer`), the
star tracker (:mod:`.star_tracker`) and the sun sensor (:mod:`.sun_sensor`).
The names of the former module ``physics.sensors`` (``GyroErrors``,
``GyroModel``, ``allan_deviation``) are importable from here as before.
"""

from .base import BodyTruth, Sky, stream_rng
from .gyro import allan_deviation, Gyro, GyroErrors, GyroModel, GyroReading
from .magnetometer import Magnetometer, MagnetometerReading
from .star_tracker import StarTracker, StarTrackerReading
from .sun_sensor import SunSensor, SunSensorReading

__all__ = ['allan_deviation', 'BodyTruth', 'Gyro', 'GyroErrors', 'GyroModel', 'GyroReading',
           'Magnetometer', 'MagnetometerReading', 'Sky', 'StarTracker', 'StarTrackerReading',
           'stream_rng', 'SunSensor', 'SunSensorReading']
