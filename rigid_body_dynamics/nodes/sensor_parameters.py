"""
The estimator's sensor parameters (star tracker, sun sensor, the Sun), defined once.

attitude_simulator and attitude_fleet fly them; the example estimator reads
the same names for its noise model, so one parameters file (``/**:``)
configures both. :func:`sensors_from` turns a simulator's validated values into
the engine's sensors (gyro, magnetometer, star tracker, sun sensor), refusing
with a reason that names the parameter.
"""

import math

from ..physics.environment import Sun
from ..physics.environment.shadow import SHADOW_MODELS
from ..physics.sensors import Gyro, GyroErrors, Magnetometer, StarTracker, SunSensor
from ..ros.parameters import ConfigurationError, Param

#: Every sensor parameter, by name, in the order the manual lists them.
SENSOR_PARAMS = {p.name: p for p in (
    Param('epoch', 'string', '', '"" (none)',
          'The UTC time of simulated time 0, ISO 8601 (e.g. 2026-03-20T12:00:00Z; TT is '
          "taken as UTC): with an orbit the Sun is where the Astronomical Almanac's "
          'low-precision solar coordinates put it (about 0.01 deg, 1950-2050). Needed by the '
          "star tracker's Sun exclusion and the sun sensor when there is an orbit. It "
          'is also the date of the IGRF field and, unless earth_rotation_angle is set, '
          'turns the Earth by its Greenwich mean sidereal time.',
          read_only=True),
    Param('sun_direction', 'double[3]', [1.0, 0.0, 0.0], '[1, 0, 0]',
          'Unit vector to the Sun in the world frame when there is no orbit (fixed; no '
          'eclipse). Normalised.', read_only=True),
    Param('shadow_model', 'string', 'cylindrical', 'cylindrical',
          "The Earth's shadow, with an orbit: cylindrical (a cylinder of planet_radius "
          'behind the Earth, sunlit or not) or conical (the umbra and penumbra cones of '
          "the Sun's and the planet's discs, Montenbruck and Gill; the fraction of the "
          "Sun's disc uncovered).", choices=SHADOW_MODELS, read_only=True),
    Param('star_tracker_rate', 'double', 0.0, '0.0 Hz',
          'Star tracker readings per simulated second on star_tracker (Hz, 0 = off); at most '
          'integration_rate, rounded to a whole number of steps.', low=0.0, high=1e5,
          read_only=True),
    Param('star_tracker_noise', 'double[3]', [2e-5, 2e-5, 1.5e-4],
          '[2e-5, 2e-5, 1.5e-4] rad',
          "Star tracker noise (rad, 1 sigma) about the tracker's x, y and z axes (z is the "
          "boresight); the reading's covariance.", read_only=True),
    Param('star_tracker_orientation', 'double[4]', [0.0, 0.0, 0.0, 1.0], '[0, 0, 0, 1]',
          "The tracker's orientation in the body (x, y, z, w; as TF gives body_frame -> "
          'tracker); its z axis is the boresight.', read_only=True),
    Param('star_tracker_misalignment', 'double[3]', [0.0, 0.0, 0.0], '[0, 0, 0] rad',
          'A fixed misalignment of the tracker (rotation vector, tracker frame, rad), applied '
          'to every reading and not in the covariance.', read_only=True),
    Param('star_tracker_sun_exclusion', 'double', 0.0, '0.0 rad',
          'No reading while the boresight is within this angle of the Sun (rad, 0 = none).',
          low=0.0, high=math.pi, read_only=True),
    Param('star_tracker_earth_exclusion', 'double', 0.0, '0.0 rad',
          "With an orbit, no reading while the boresight is within this angle of the Earth's "
          "limb (rad); the Earth's disc itself always blocks the view.", low=0.0,
          high=math.pi, read_only=True),
    Param('sun_sensor_rate', 'double', 0.0, '0.0 Hz',
          'Sun sensor readings per simulated second on sun_sensor (Hz, 0 = off); at most '
          'integration_rate, rounded to a whole number of steps.', low=0.0, high=1e5,
          read_only=True),
    Param('sun_sensor_noise', 'double', 0.0, '0.0 rad',
          'Sun sensor noise: a random rotation of the direction, N(0, noise^2) per axis (rad; '
          'the pointing error then has E[angle^2] = 2 noise^2).', low=0.0, high=1.0,
          read_only=True),
    Param('sun_sensor_boresight', 'double[3]', [0.0, 0.0, 1.0], '[0, 0, 1]',
          "The sun sensor's boresight (body frame; normalised).", read_only=True),
    Param('sun_sensor_fov', 'double', math.pi, '3.14159 rad (all directions)',
          "Half-angle of the sun sensor's field of view about its boresight (rad); outside "
          'it, or in eclipse, there is no reading.', low=0.0, high=math.pi, read_only=True),
    Param('sun_sensor_min_light', 'double', 0.5, '0.5',
          "The fraction of the Sun's disc the sun sensor needs uncovered to read, in the "
          'penumbra of shadow_model conical (never in umbra; the cylinder is 0 or 1).',
          low=0.0, high=1.0, read_only=True),
)}


def sensor_params(*names):
    """Return the Params called ``names`` (all when none is named), for a ParameterTable."""
    return [SENSOR_PARAMS[n] for n in (names or SENSOR_PARAMS)]


def epoch_of(out, orbit):
    """
    Return the UTC time of simulated time 0 (ISO 8601 text; '' = none) of values ``out``.

    ``epoch`` when set; else a TLE orbit's own epoch (its t = 0).
    """
    if out.get('epoch'):
        return out['epoch']
    return getattr(orbit, 'start_text', '')


def sun_from(out, orbit):
    """
    Return the Sun of validated values ``out`` (None without an epoch in an orbit).

    With an orbit the Sun needs an epoch (:func:`epoch_of`); without one it is
    ``sun_direction``.
    """
    try:
        if orbit is None:
            return Sun(fixed=out['sun_direction'])
        epoch = epoch_of(out, orbit)
        return Sun(epoch=epoch) if epoch else None
    except ValueError as err:
        raise ConfigurationError(str(err)) from None


def sensors_from(out, disturbances):
    """
    Return the engine's sensors of a simulator's validated values ``out``.

    ``disturbances`` (the engine's Disturbances, with the Sun) says what the
    sensors can see. Refuses (ConfigurationError, naming the parameter) a rate
    above integration_rate, a sun sensor or Sun exclusion without a Sun, and a
    value a sensor refuses.
    """
    for name in ('imu_rate', 'magnetometer_rate', 'star_tracker_rate', 'sun_sensor_rate'):
        if out[name] > out['integration_rate']:
            raise ConfigurationError(f'{name} must be at most integration_rate '
                                     f'({out["integration_rate"]:g} Hz), got {out[name]:g}')
    needs_sun = out['sun_sensor_rate'] > 0.0 or (
        out['star_tracker_rate'] > 0.0 and out['star_tracker_sun_exclusion'] > 0.0)
    if needs_sun and disturbances.sun is None:
        raise ConfigurationError("the sun sensor and the star tracker's Sun exclusion need "
                                 "epoch with orbit_elements, or orbit_tle (the Sun's direction "
                                 'on the orbit)')
    sensors = []
    try:
        if out['publish_imu']:
            sensors.append(Gyro(GyroErrors(
                out['gyro_noise_density'], out['gyro_bias_random_walk'],
                out['gyro_turn_on_bias'], out['gyro_bias_correlation_time'],
                out['orientation_noise'], out['gyro_resolution']), out['imu_rate']))
        if out['magnetometer_rate'] > 0.0:
            sensors.append(Magnetometer(out['magnetometer_rate'], out['magnetometer_noise'],
                                        out['magnetometer_bias']))
        if out['star_tracker_rate'] > 0.0:
            sensors.append(StarTracker(
                out['star_tracker_rate'], out['star_tracker_noise'],
                out['star_tracker_orientation'], out['star_tracker_misalignment'],
                out['star_tracker_sun_exclusion'], out['star_tracker_earth_exclusion']))
        if out['sun_sensor_rate'] > 0.0:
            sensors.append(SunSensor(out['sun_sensor_rate'], out['sun_sensor_noise'],
                                     out['sun_sensor_boresight'], out['sun_sensor_fov'],
                                     out['sun_sensor_min_light']))
    except ValueError as err:
        raise ConfigurationError(str(err)) from None
    return sensors
