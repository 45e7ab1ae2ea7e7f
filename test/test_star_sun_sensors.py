"""
The estimator's sensors without ROS: the Sun, the shadow, the star tracker and the sun sensor.

The Sun against the 2026 equinox and solstice (independent almanac times), the
shadow against the cylinder's closed-form eclipse fraction, the star tracker's and
the sun sensor's errors against their parameters (10 000 readings, 99 % intervals),
their exclusions, and the streams: turning a sensor on leaves the gyro's noise
unchanged, bit for bit.
"""

import math

import numpy as np
import pytest
from rigid_body_dynamics.engine import BodySimulation, Disturbances
from rigid_body_dynamics.physics import Inertia, quaternions
from rigid_body_dynamics.physics.environment import (circular_elements, in_shadow, julian_date,
                                                     KeplerOrbit, R_EARTH, Sun)
from rigid_body_dynamics.physics.sensors import (BodyTruth, Gyro, GyroErrors, Sky, StarTracker,
                                                 SunSensor)
from scipy.spatial.transform import Rotation
import stat_checks

#: The mean obliquity of the ecliptic at the 2026 June solstice (deg), from the IAU 2006
#: precession (Capitaine, Wallace and Chapront, A&A 412, 2003: 84381.406" - 46.836769" T,
#: T = 0.26469 Julian centuries from J2000), not from the package's formula; the nutation
#: in obliquity (under 0.0026 deg) is inside the test's 0.01 deg.
EPS_2026 = 23.43584


def _radec(s):
    """Right ascension and declination (deg) of a world unit vector."""
    return (math.degrees(math.atan2(s[1], s[0])) % 360.0,
            math.degrees(math.asin(max(-1.0, min(1.0, s[2])))))


def test_julian_date_of_j2000_and_of_an_offset_time():
    assert julian_date('2000-01-01T12:00:00Z') == 2451545.0
    assert julian_date('2000-01-01T13:00:00+01:00') == 2451545.0
    assert julian_date('2000-01-01T12:00:00') == 2451545.0       # no offset: UTC
    with pytest.raises(ValueError, match='epoch'):
        julian_date('the first of March')


def test_the_sun_at_the_2026_equinox_and_solstice():
    """
    Check the Sun's direction against the 2026 March equinox and June solstice.

    Equinox 2026-03-20 14:46 UTC: right ascension 0 and declination 0; solstice
    2026-06-21 08:24 UTC: right ascension 90 deg and declination the obliquity.
    Within 0.01 deg (the formula's accuracy; the Sun moves 0.0007 deg in the
    minute the times are rounded to).
    """
    ra, dec = _radec(Sun('2026-03-20T14:46:00Z').direction(0.0))
    assert min(ra, 360.0 - ra) < 0.01 and abs(dec) < 0.01, (ra, dec)
    sun = Sun('2026-06-21T00:00:00Z')
    ra, dec = _radec(sun.direction(8.4 * 3600.0))          # simulated time moves the Sun
    assert abs(ra - 90.0) < 0.01 and abs(dec - EPS_2026) < 0.01, (ra, dec)
    assert Sun(fixed=(0.0, 2.0, 0.0)).direction(1e6) == (0.0, 1.0, 0.0)
    with pytest.raises(ValueError, match='sun_direction'):
        Sun(fixed=(0.0, 0.0, 0.0))


def test_the_cylindrical_shadow_takes_its_closed_form_share_of_an_orbit():
    """
    Check the shadow on a circular orbit with the Sun in its plane (beta = 0).

    The body is in the shadow for a fraction asin(R / a) / pi of the orbit; sampled
    every 0.01 s over one orbit, the share agrees to the sampling (1e-5).
    """
    a = R_EARTH + 500e3
    orbit = KeplerOrbit(circular_elements(500e3))
    sun = (1.0, 0.0, 0.0)
    t = np.arange(0.0, orbit.period, 0.01)
    shade = np.mean([in_shadow(orbit.position(k), sun, R_EARTH) for k in t[::10]])
    assert shade == pytest.approx(math.asin(R_EARTH / a) / math.pi, abs=2e-4)
    assert in_shadow((-a, 0.0, 0.0), sun, R_EARTH)
    assert not in_shadow((a, 0.0, 0.0), sun, R_EARTH)
    assert not in_shadow((-a, R_EARTH * 1.0001, 0.0), sun, R_EARTH)


def test_quaternion_rotation_vectors_against_scipy():
    rng = np.random.default_rng(1)
    for v in list(rng.normal(size=(20, 3))) + [np.array([1e-9, -2e-9, 3e-10]), np.zeros(3)]:
        q = quaternions.from_rotation_vector(v)
        assert np.allclose(q, Rotation.from_rotvec(v).as_quat(), atol=1e-15, rtol=0)
        assert np.allclose(quaternions.matrix(q), Rotation.from_quat(q).as_matrix(), atol=1e-15)
        assert np.allclose(quaternions.to_rotation_vector(q), Rotation.from_quat(q).as_rotvec(),
                           atol=1e-15)


def _truth(q, position=None, sun=(1.0, 0.0, 0.0)):
    return BodyTruth(tuple(q), (0.0, 0.0, 0.0), position, Sky(sun=Sun(fixed=sun)))


NOISE = np.array([2e-5, 3e-5, 1.5e-4])
MOUNT = Rotation.from_euler('xyz', [0.3, -1.1, 0.7])
MISALIGNMENT = np.array([1e-4, -2e-4, 5e-4])


def _tracker_readings(seed, n):
    """Return (truths, readings) of n star tracker readings of random attitudes."""
    tracker = StarTracker(10.0, NOISE, MOUNT.as_quat(), MISALIGNMENT)
    rng = np.random.default_rng(seed)
    truths = Rotation.random(n, random_state=seed + 7)
    return truths, [tracker.sample(_truth(q), 0.1 * k, rng)
                    for k, q in enumerate(truths.as_quat())]


def _tracker_errors(truths, readings):
    """Return the rotation from truth to reading in the tracker frame, less the misalignment."""
    measured = Rotation.from_quat([r.q for r in readings])
    in_tracker = MOUNT.inv() * truths.inv() * measured * MOUNT
    return (Rotation.from_rotvec(MISALIGNMENT).inv() * in_tracker).as_rotvec()


def _tracker_errors_fail(errors, alpha):
    """
    Say whether the errors fail their noise model at a false-failure rate alpha (six checks).

    Per tracker axis: the mean inside the two-sided interval of zero for n
    independent N(0, noise^2) samples, and the variance (about the sample mean)
    inside the chi-square interval of n - 1 degrees of freedom; alpha / 6 each.
    """
    n = len(errors)
    each = stat_checks.share(6, alpha)
    low, high = stat_checks.variance_interval(n, each, ddof=1)
    variance = errors.var(axis=0, ddof=1) / NOISE ** 2
    return bool(np.any(np.abs(errors.mean(axis=0)) > stat_checks.mean_bound(NOISE, n, each))
                or np.any((variance < low) | (variance > high)))


def test_star_tracker_errors_match_its_parameters_in_the_tracker_frame():
    """
    Check 10 000 star tracker readings against their noise model.

    The rotation from the truth to the reading, in the tracker frame, minus the
    misalignment: per axis its mean and its variance inside their intervals,
    the six checks together failing a correct tracker with probability 1e-4
    (stat_checks); the covariance the reading reports equals the noise turned
    into the world frame.
    """
    truths, readings = _tracker_readings(5, 10_000)
    errors = _tracker_errors(truths, readings)
    assert not _tracker_errors_fail(errors, stat_checks.FALSE_FAILURE), \
        (errors.mean(axis=0), errors.var(axis=0) / NOISE ** 2)
    for truth, reading in zip(truths[:50], readings[:50]):
        measured = Rotation.from_quat(reading.q)
        expected = (measured * MOUNT).as_matrix() @ np.diag(NOISE ** 2) @ \
            (measured * MOUNT).as_matrix().T
        assert np.abs(np.reshape(reading.covariance, (3, 3)) - expected).max() < 1e-22
    # a tracker 3 % noisier than it says fails the same check
    assert _tracker_errors_fail(errors * 1.03, stat_checks.FALSE_FAILURE)


def test_the_star_tracker_check_fails_a_correct_tracker_at_its_stated_rate():
    """
    Run the star tracker's check at a nominal 5 % over 400 seeds of 250 readings each.

    A correct tracker fails the six checks together in at most 5 % of seeds
    (Bonferroni; 4.9 % for independent checks): the count of failures must be
    inside the binomial interval of rates 3.5 to 5 % at a false-failure rate of
    1e-4, so that the check's thresholds, not the seed, are what the
    10 000-reading test passes by.
    """
    failed = sum(_tracker_errors_fail(_tracker_errors(*_tracker_readings(seed, 250)), 0.05)
                 for seed in range(400))
    low, high = stat_checks.binomial_count_interval(400, 0.035, 0.05)
    assert low <= failed <= high, (failed, low, high)


def test_star_tracker_exclusions_by_the_sun_and_the_earth():
    """A boresight at the Sun is excluded ('sun'); one at the Earth's disc or limb ('earth')."""
    tracker = StarTracker(10.0, sun_exclusion=math.radians(30.0),
                          earth_exclusion=math.radians(10.0))
    rng = np.random.default_rng(0)
    up = Rotation.from_euler('y', 90.0, degrees=True)         # the body z (boresight) to +x
    assert tracker.sample(_truth(up.as_quat()), 0.0, rng) == 'sun'
    tilted = Rotation.from_euler('y', 90.0 - 29.0, degrees=True)
    assert tracker.sample(_truth(tilted.as_quat()), 0.0, rng) == 'sun'
    clear = Rotation.from_euler('y', 90.0 - 31.0, degrees=True)
    assert tracker.sample(_truth(clear.as_quat()), 0.0, rng) != 'sun'
    a = R_EARTH + 500e3
    limb = math.degrees(math.asin(R_EARTH / a))              # 68.0 deg from nadir
    position = (0.0, 0.0, a)                                  # over the pole: nadir is -z
    for off_nadir, expected in ((0.0, 'earth'), (limb + 9.9, 'earth')):
        q = Rotation.from_euler('x', 180.0 - off_nadir, degrees=True).as_quat()
        assert tracker.sample(_truth(q, position, sun=(0.0, 1.0, 0.0)), 0.0, rng) == expected
    q = Rotation.from_euler('x', 180.0 - limb - 10.1, degrees=True).as_quat()
    assert not isinstance(tracker.sample(_truth(q, position, sun=(0.0, 1.0, 0.0)), 0.0, rng),
                          str)


SUN_NOISE = 1e-3


def _sun_angles2(seed, n):
    """Return the squared pointing errors (rad^2) of a sun sensor's readings in its view."""
    sensor = SunSensor(10.0, SUN_NOISE, boresight=(1.0, 0.0, 0.0), fov=math.radians(60.0))
    rng = np.random.default_rng(seed)
    truths = Rotation.from_euler('xyz', np.random.default_rng(seed + 1).uniform(-0.5, 0.5, (n, 3)))
    readings = [sensor.sample(_truth(q), 0.0, rng) for q in truths.as_quat()]
    seen = [k for k, r in enumerate(readings) if not isinstance(r, str)]
    measured = np.array([readings[k].direction for k in seen])
    true = truths[seen].inv().apply((1.0, 0.0, 0.0))
    assert np.allclose(np.linalg.norm(measured, axis=1), 1.0, rtol=0, atol=1e-15)
    return np.arctan2(np.linalg.norm(np.cross(measured, true), axis=1),
                      np.sum(measured * true, axis=1)) ** 2


def _sun_angles_fail(angles2, alpha):
    """Say whether the mean squared error leaves 2 noise^2's chi-square(2 n) interval (alpha)."""
    low, high = stat_checks.variance_interval(len(angles2), alpha, dof_per_sample=2)
    return not low < np.mean(angles2) / (2.0 * SUN_NOISE ** 2) < high


def test_sun_sensor_errors_field_of_view_and_eclipse():
    """
    Check the sun sensor: E[angle^2] = 2 noise^2, its field of view and the eclipse.

    10 000 readings: the mean squared pointing error inside its interval (a
    chi-square with 2 degrees of freedom per reading, scaled by noise^2) at a
    false-failure rate of 1e-4; a sensor 3 % noisier fails it.
    """
    angles2 = _sun_angles2(2, 10_000)
    assert len(angles2) > 9000
    assert not _sun_angles_fail(angles2, stat_checks.FALSE_FAILURE), \
        np.mean(angles2) / SUN_NOISE ** 2
    assert _sun_angles_fail(angles2 * 1.03 ** 2, stat_checks.FALSE_FAILURE)
    sensor = SunSensor(10.0, SUN_NOISE, boresight=(1.0, 0.0, 0.0), fov=math.radians(60.0))
    rng = np.random.default_rng(0)
    away = Rotation.from_euler('z', 61.0, degrees=True).as_quat()
    assert sensor.sample(_truth(away), 0.0, rng) == 'fov'
    a = R_EARTH + 500e3
    assert sensor.sample(_truth((0, 0, 0, 1), (-a, 0.0, 0.0)), 0.0, rng) == 'eclipse'
    assert sensor.sample(_truth((0, 0, 0, 1), (a, 0.0, 0.0)), 0.0, rng) != 'eclipse'


def test_the_sun_sensor_check_fails_a_correct_sensor_at_its_stated_rate():
    """The sun sensor's check at a nominal 5 % over 400 seeds of 250 readings: 4 to 6 % fail."""
    failed = sum(_sun_angles_fail(_sun_angles2(seed, 250), 0.05) for seed in range(400))
    low, high = stat_checks.binomial_count_interval(400, 0.04, 0.06)
    assert low <= failed <= high, (failed, low, high)


def test_sensor_parameters_are_refused_naming_them():
    for make, match in ((lambda: StarTracker(0.0), 'star_tracker_rate'),
                        (lambda: StarTracker(1.0, (1e-5, math.nan, 0.0)), 'star_tracker_noise'),
                        (lambda: StarTracker(1.0, orientation=(0, 0, 0, 2)),
                         'star_tracker_orientation'),
                        (lambda: StarTracker(1.0, sun_exclusion=-0.1),
                         'star_tracker_sun_exclusion'),
                        (lambda: SunSensor(1.0, boresight=(0, 0, 0)), 'sun_sensor_boresight'),
                        (lambda: SunSensor(1.0, fov=4.0), 'sun_sensor_fov'),
                        (lambda: SunSensor(1.0, noise=-1.0), 'sun_sensor_noise')):
        with pytest.raises(ValueError, match=match):
            make()


def test_each_sensor_draws_from_its_own_stream():
    """
    Check that turning the star tracker and sun sensor on leaves the gyro's readings unchanged.

    Bit for bit, over 2 s at 1 kHz; the new sensors' readings are counted, and a
    reset starts every stream again.
    """
    def body(*extra):
        gyro = Gyro(GyroErrors(1e-3, 1e-4, 1e-3, orientation_noise=1e-3), 100.0)
        return BodySimulation(Inertia((1.0, 2.0, 3.0)), 'exact', 1000.0,
                              ((0.0, 0.0, 0.0, 1.0), (0.3, 1.5, -0.4)), publish_every=100,
                              sensors=[gyro, *extra], seed=4,
                              disturbances=Disturbances(sun=Sun(fixed=(0.0, 0.0, 1.0))))

    def run(b):
        out = []
        with b.lock:
            for _ in range(2000):
                b.advance(0, out)
        return out
    plain = run(body())
    both = run(body(StarTracker(10.0, (1e-4, 1e-4, 1e-3)), SunSensor(20.0, 1e-3)))
    gyro = [s for s in both if getattr(s, 'sensor', None) == 'gyro']
    assert gyro == [s for s in plain if getattr(s, 'sensor', None) == 'gyro'] and len(gyro) == 200
    b = body(StarTracker(10.0, (1e-4, 1e-4, 1e-3)), SunSensor(20.0, 1e-3, fov=0.5))
    first = run(b)
    counts = b.sensor_health()
    assert counts['star_tracker'] == {'valid': 20}
    assert counts['sun_sensor']['valid'] + counts['sun_sensor']['fov'] == 40
    assert counts['sun_sensor']['fov'] > 0
    b.reset()
    assert run(b) == first
