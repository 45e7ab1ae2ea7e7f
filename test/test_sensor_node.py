"""
The estimator's sensors of attitude_simulator over real topics (the node is its own process).

The star tracker and the sun sensor of a spinning satellite in orbit: every
reading on star_tracker and sun_sensor is the sensor's own model replayed at
odom's attitude (the same seeded stream, bit for bit), with the right frames and
covariance layout; the readings the Sun and the Earth blocked are missing and
counted on /diagnostics; bad sensor parameters are refused at start, naming them.
"""

import math

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseWithCovarianceStamped, Vector3Stamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rigid_body_dynamics.physics.environment import circular_elements, KeplerOrbit, Sun
from rigid_body_dynamics.physics.sensors import BodyTruth, Sky, StarTracker, stream_rng, SunSensor
from rigid_body_dynamics.ros.conversions import quaternion_array, time_ns, vector_array
from scipy.spatial.transform import Rotation
from std_srvs.srv import SetBool

SIM = 'rigid_body_dynamics.nodes.simulator'
EPOCH = '2026-03-20T12:00:00Z'
#: A 500 km orbit that enters the Earth's shadow 10 s after the start (at anomaly 1.717).
ELEMENTS = circular_elements(500e3, inclination=0.9, raan=0.4,
                             anomaly=1.717 - 10.0 * KeplerOrbit(circular_elements(500e3)).n)
#: An attitude from which the spin takes the tracker past the Sun and the Earth in 4-14 s.
Q0 = Rotation.random(random_state=0).as_quat().tolist()
MOUNT = (0.1, -0.2, 0.3, math.sqrt(1.0 - 0.14))
NOISE = (2e-5, 3e-5, 1.5e-4)
MISALIGNMENT = (1e-4, 0.0, -2e-4)
SEED = 17


def _tracker():
    return StarTracker(50.0, NOISE, MOUNT, MISALIGNMENT, sun_exclusion=0.5, earth_exclusion=0.2)


def _sun_sensor():
    return SunSensor(25.0, 1e-3, (0.0, 1.0, 0.0), fov=1.0)


def test_star_tracker_and_sun_sensor_over_topics(launch, probe):
    """
    Check every star tracker and sun sensor reading against the models replayed offline.

    A body spinning at 0.6 rad/s in a 500 km orbit that enters the shadow at 10 s:
    the tracker's boresight sweeps past the Sun and the Earth, the sun sensor's field
    of view past the Sun until the eclipse. Replayed at odom's attitude, in step order from the
    same seeded streams, each published reading is the model's, bit for bit, and
    each missing one was excluded; the counts on /diagnostics after a pause are the
    replay's.
    """
    launch(SIM, '-p', 'publish_clock:=true', '-p', 'inertia:=[2.0, 3.0, 1.2]',
           '-p', 'initial_angular_velocity:=[0.5, 0.3, 0.2]', '-p', f'initial_orientation:={Q0}',
           '-p', f'orbit_elements:={list(ELEMENTS)}', '-p', f'epoch:={EPOCH}',
           '-p', 'publish_rate:=50.0', '-p', 'publish_imu:=false', '-p', f'noise_seed:={SEED}',
           '-p', 'star_tracker_rate:=50.0', '-p', f'star_tracker_noise:={list(NOISE)}',
           '-p', f'star_tracker_orientation:={list(MOUNT)}',
           '-p', f'star_tracker_misalignment:={list(MISALIGNMENT)}',
           '-p', 'star_tracker_sun_exclusion:=0.5', '-p', 'star_tracker_earth_exclusion:=0.2',
           '-p', 'sun_sensor_rate:=25.0', '-p', 'sun_sensor_noise:=0.001',
           '-p', 'sun_sensor_boresight:=[0.0, 1.0, 0.0]', '-p', 'sun_sensor_fov:=1.0',
           name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    stars = probe.subscribe(PoseWithCovarianceStamped, 'star_tracker')
    suns = probe.subscribe(Vector3Stamped, 'sun_sensor')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.spin_until(lambda: odom and time_ns(odom[-1].header.stamp) >= 14 * 10 ** 9, 60.0,
                     '14 s simulated')
    assert probe.call(SetBool, '/attitude_simulator/pause', SetBool.Request(data=True)).success
    seen = len(probe.messages['/diagnostics'])
    probe.spin_until(lambda: len(probe.messages['/diagnostics']) > seen + 1, 10.0,
                     'diagnostics after the pause')
    _, _, values = probe.newest_status('sensors')
    last = int(values['star_tracker readings']) + sum(
        int(v) for k, v in values.items() if k.startswith('star_tracker excluded'))
    by_stamp = {time_ns(m.header.stamp): m for m in odom}
    # the ticks before the probe's subscription matched have no odom here: their draws are
    # replayed (a sensor draws whatever it sees), their readings not checked
    missing = [k for k in range(last) if k * 20_000_000 not in by_stamp]
    assert missing == list(range(len(missing))) and len(missing) < last // 2, missing
    # the replay, in step order: the tracker at every tick, the sun sensor at every other
    orbit, sky = KeplerOrbit(ELEMENTS), Sky(sun=Sun(EPOCH))
    tracker, sun_sensor = _tracker(), _sun_sensor()
    rng_t, rng_s = stream_rng(SEED, tracker.stream), stream_rng(SEED, sun_sensor.stream)
    expected_t, expected_s, counts_t, counts_s = {}, {}, {}, {}

    def replay(sensor, truth, t, rng, expected, counts, stamp):
        if truth is None:
            rng.standard_normal(3)
            return
        reading = sensor.sample(truth, t, rng)
        key = reading if isinstance(reading, str) else 'valid'
        counts[key] = counts.get(key, 0) + 1
        if key == 'valid':
            expected[stamp] = reading
    for k in range(last):
        stamp = k * 20_000_000
        t = (k * 20) * (1.0 / 1000.0)
        truth = None if stamp not in by_stamp else BodyTruth(
            tuple(quaternion_array(by_stamp[stamp].pose.pose.orientation).tolist()),
            (0.0, 0.0, 0.0), orbit.position(t), sky)
        replay(tracker, truth, t, rng_t, expected_t, counts_t, stamp)
        if k % 2 == 0:
            replay(sun_sensor, truth, t, rng_s, expected_s, counts_s, stamp)
    assert counts_t.get('sun', 0) >= 10 and counts_t.get('earth', 0) >= 50, counts_t
    assert min(counts_s.get(key, 0) for key in ('valid', 'fov', 'eclipse')) >= 10, counts_s
    # the node's counts: the replay's, and the unchecked first ticks in one of them each
    diag = {key: int(values[f'star_tracker {name}']) for key, name in (
        ('valid', 'readings'), ('sun', 'excluded (sun)'), ('earth', 'excluded (earth)'))}
    extra = {key: diag[key] - counts_t.get(key, 0) for key in diag}
    assert min(extra.values()) >= 0 and sum(extra.values()) == len(missing), (diag, counts_t)
    first = len(missing) * 20_000_000
    got_t = {time_ns(m.header.stamp): m for m in stars
             if first <= time_ns(m.header.stamp) < last * 20e6}
    assert set(got_t) == set(expected_t)
    for stamp, m in got_t.items():
        reading = expected_t[stamp]
        assert m.header.frame_id == 'odom'
        assert tuple(quaternion_array(m.pose.pose.orientation)) == reading.q
        cov = np.reshape(m.pose.covariance, (6, 6))
        assert np.array_equal(cov[3:, 3:].ravel(), reading.covariance)
        assert np.array_equal(np.diag(cov)[:3], [1e12] * 3) and not cov[:3, 3:].any()
        assert vector_array(m.pose.pose.position).tolist() == [0.0, 0.0, 0.0]
    got_s = {time_ns(m.header.stamp): m for m in suns
             if first <= time_ns(m.header.stamp) < last * 20e6}
    assert set(got_s) == set(expected_s)
    for stamp, m in got_s.items():
        assert m.header.frame_id == 'base_link'
        assert tuple(vector_array(m.vector)) == expected_s[stamp].direction


@pytest.mark.parametrize('args, reason', [
    (('-p', 'star_tracker_rate:=10.0', '-p', 'star_tracker_orientation:=[0.0, 0.0, 0.0, 2.0]'),
     'star_tracker_orientation must be a unit quaternion'),
    (('-p', 'star_tracker_rate:=10.0', '-p', 'star_tracker_noise:=[1e-5, -1e-5, 1e-4]'),
     'star_tracker_noise must be in [0, 1] rad'),
    (('-p', 'sun_sensor_rate:=10.0', '-p', 'sun_sensor_boresight:=[0.0, 0.0, 0.0]'),
     'sun_sensor_boresight must not be zero'),
    (('-p', 'sun_sensor_rate:=2000.0'), 'sun_sensor_rate must be at most integration_rate'),
    (('-p', f'orbit_elements:={list(ELEMENTS)}', '-p', 'sun_sensor_rate:=10.0'),
     'need epoch with orbit_elements'),
    (('-p', f'orbit_elements:={list(ELEMENTS)}', '-p', 'epoch:=yesterday'), 'epoch must be'),
    (('-p', 'sun_direction:=[0.0, 0.0, 0.0]'), 'sun_direction must be'),
    (('-p', 'shadow_model:=cone'), 'shadow_model must be one of cylindrical, conical'),
    (('-p', 'sun_sensor_min_light:=1.5'), 'sun_sensor_min_light'),
])
def test_bad_sensor_parameters_are_refused_at_start_naming_them(launch, args, reason):
    proc = launch(SIM, *args, name='bad_sensor')
    assert proc.wait(20.0) == 1
    assert reason in proc.output(), proc.output()


def test_the_sensors_example_file_runs_both_sensors(launch, probe):
    """doc/examples/sensors.yaml starts a simulator whose tracker and sun sensor both sample."""
    from pathlib import Path
    params = Path(__file__).resolve().parents[1] / 'doc' / 'examples' / 'sensors.yaml'
    launch(SIM, '--params-file', str(params), '-p', 'publish_clock:=true', name='sim')
    probe.subscribe(DiagnosticArray, '/diagnostics')

    def sampled():
        found = probe.newest_status('sensors')
        if found is None:
            return False
        counts = {k: int(v) for k, v in found[2].items()}
        return all(sum(n for k, n in counts.items() if k.startswith(name)) > 0
                   for name in ('star_tracker', 'sun_sensor'))
    probe.spin_until(sampled, 30.0, 'star tracker and sun sensor counts on /diagnostics')
