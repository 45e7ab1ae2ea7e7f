"""
Sensors (no ROS): the rate gyro (:mod:`.gyro`) and the magnetometer (:mod:`.magnetometer`).

The names of the former module ``physics.sensors`` (``GyroErrors``,
``GyroModel``, ``allan_deviation``) are importable from here as before.
"""

from .gyro import allan_deviation, GyroErrors, GyroModel
from .magnetometer import Magnetometer

__all__ = ['allan_deviation', 'GyroErrors', 'GyroModel', 'Magnetometer']
