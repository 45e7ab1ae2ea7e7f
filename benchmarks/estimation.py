"""
The estimator's sensors and the example MEKF over topics, against their theory; the sensors' cost.

Star tracker: attitude_simulator with only the star tracker at 100 Hz (noise 2e-5, 3e-5,
1.5e-4 rad about the tracker's axes, mounted turned by (0.3, -1.1, 0.7) rad xyz, a
misalignment of (1e-4, -2e-4, 5e-4) rad) on a tumbling body (I = (2, 3, 1.2) kg m^2,
omega0 = (0.3, -0.5, 0.8) rad/s), 10 000 readings at 10x real time, each paired with the odom
of its stamp: the rotation from the truth to the reading in the tracker frame, minus the
misalignment, per axis: mean and variance against the 99 % intervals of zero and of noise^2.
Estimator: doc/examples/estimator.yaml (gyro N = 1e-4 rad/s/sqrt(Hz), K = 1e-6
rad/s^2/sqrt(Hz) at 20 Hz; star tracker at 5 Hz) with attitude_estimator, 600 s simulated:
after 100 s, the error per body axis (1 sigma) of the estimates just after each star
tracker reading against the covariance the estimator reports there and against the steady
state of the single-axis gyro and attitude-sensor filter (Farrenkopf's problem, Markley and
Crassidis section 6.3: the discrete Riccati equation's fixed point, per axis with that
axis' tracker noise). Cost: the simulator's share of a core at 1 kHz, real time, with the
gyro alone (100 Hz) and with gyro, magnetometer (10 Hz), star tracker (10 Hz) and sun sensor
(10 Hz) in a 500 km orbit, three runs each, alternating.
``./dev bench --only estimation``.
"""

import math
import os
import statistics
import sys

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry
from nodes import measure_cpu, Probe, Process, sim
import numpy as np
from rigid_body_dynamics.physics import quaternions as quat
from rigid_body_dynamics.ros.conversions import quaternion_array, time_ns
from scipy import stats
from scipy.linalg import solve_discrete_are
from scipy.spatial.transform import Rotation

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLE = os.path.join(HERE, '..', 'doc', 'examples', 'estimator.yaml')
NOISE = np.array([2e-5, 3e-5, 1.5e-4])
MOUNT = Rotation.from_euler('xyz', [0.3, -1.1, 0.7])
MISALIGNMENT = np.array([1e-4, -2e-4, 5e-4])
ROUNDS = 3


def measure():
    """Return RESULTS.md lines: star tracker statistics, the estimator, the sensors' cost."""
    probe = Probe('bench_estimation')
    try:
        return star_tracker(probe) + [''] + estimator(probe) + [''] + cost(probe)
    finally:
        probe.close()


def star_tracker(probe, count=10_000):
    """Measure the star tracker's errors over topics against its parameters."""
    odom = probe.subscribe(Odometry, 'odom')
    readings = probe.subscribe(PoseWithCovarianceStamped, 'star_tracker')
    proc = Process(sim('inertia:=[2.0, 3.0, 1.2]', 'initial_angular_velocity:=[0.3, -0.5, 0.8]',
                       'publish_clock:=true', 'publish_rate:=100.0', 'publish_imu:=false',
                       'real_time_factor:=10.0', 'star_tracker_rate:=100.0',
                       f'star_tracker_noise:={NOISE.tolist()}',
                       f'star_tracker_orientation:={MOUNT.as_quat().tolist()}',
                       f'star_tracker_misalignment:={MISALIGNMENT.tolist()}'))
    try:
        probe.spin_until(lambda: len(readings) >= count + 100, 300.0, 'star tracker readings')
    finally:
        proc.close()
    truth = {time_ns(m.header.stamp): quaternion_array(m.pose.pose.orientation) for m in odom}
    errors = []
    for m in readings:
        t = time_ns(m.header.stamp)
        if t in truth and len(errors) < count:
            true, got = Rotation.from_quat(truth[t]), Rotation.from_quat(
                quaternion_array(m.pose.pose.orientation))
            turn = (Rotation.from_rotvec(MISALIGNMENT).inv() * MOUNT.inv() * true.inv() * got
                    * MOUNT)
            errors.append(turn.as_rotvec())
    errors = np.array(errors)
    n = len(errors)
    z = stats.norm.ppf(0.995)
    low, high = (stats.chi2.ppf(p, n - 1) / (n - 1) for p in (0.005, 0.995))
    lines = [f'Star tracker, {n} readings over topics:', '',
             '| tracker axis | noise (rad) | mean error (rad) | 99 % interval of the mean | '
             'variance / noise^2 | 99 % interval | inside both |', '|---|---|---|---|---|---|---|']
    for k, axis in enumerate('xyz'):
        mean, ratio = errors[:, k].mean(), errors[:, k].var(ddof=1) / NOISE[k] ** 2
        half = z * NOISE[k] / math.sqrt(n)
        inside = abs(mean) < half and low < ratio < high
        lines.append(f'| {axis} | {NOISE[k]:g} | {mean:.2e} | +-{half:.2e} | {ratio:.4f} | '
                     f'{low:.4f} to {high:.4f} | {"yes" if inside else "no"} |')
    probe.messages.pop('odom')
    probe.messages.pop('star_tracker')
    return lines


def _farrenkopf(noise_density, bias_walk, sigma, dt):
    """Steady post-update attitude sigma of the single-axis gyro + attitude sensor filter."""
    phi = np.array([[1.0, -dt], [0.0, 1.0]])
    q = np.array([[noise_density ** 2 * dt + bias_walk ** 2 * dt ** 3 / 3.0,
                   -bias_walk ** 2 * dt ** 2 / 2.0],
                  [-bias_walk ** 2 * dt ** 2 / 2.0, bias_walk ** 2 * dt]])
    h, r = np.array([[1.0, 0.0]]), np.array([[sigma ** 2]])
    prior = solve_discrete_are(phi.T, h.T, q, r)
    post = prior - prior @ h.T @ np.linalg.inv(h @ prior @ h.T + r) @ h @ prior
    return math.sqrt(post[0, 0])


def estimator(probe, seconds=600.0):
    """Measure the example MEKF's steady-state error against its covariance and theory."""
    odom = probe.subscribe(Odometry, 'odom')
    estimates = probe.subscribe(PoseWithCovarianceStamped, 'attitude_estimate')
    tracker = probe.subscribe(PoseWithCovarianceStamped, 'star_tracker')
    est = Process([sys.executable, '-m', 'rigid_body_dynamics.nodes.estimator', '--ros-args',
                   '--params-file', EXAMPLE])
    probe.spin_until(lambda: probe.endpoints('sub', 'attitude_estimator'), 30.0, 'estimator')
    proc = Process(sim() + ['--params-file', EXAMPLE])
    try:
        probe.spin_until(lambda: odom and time_ns(odom[-1].header.stamp) >= seconds * 1e9,
                         300.0, f'{seconds} s simulated')
    finally:
        proc.close()
        est.close()
    truth = {time_ns(m.header.stamp): quaternion_array(m.pose.pose.orientation) for m in odom}
    updates = {time_ns(m.header.stamp) for m in tracker}
    errors, sigmas = [], []
    for m in estimates:
        t = time_ns(m.header.stamp)
        if t in truth and t in updates and t >= 100e9:
            q = quaternion_array(m.pose.pose.orientation)
            errors.append(quat.to_rotation_vector(quat.multiply(quat.conjugate(truth[t]), q)))
            cov_world = np.reshape(m.pose.covariance, (6, 6))[3:, 3:]
            a = quat.matrix(q)
            sigmas.append(np.sqrt(np.diag(a.T @ cov_world @ a)))
    errors, sigmas = np.array(errors), np.array(sigmas)
    theory = [_farrenkopf(1e-4, 1e-6, s, 0.2) for s in (2e-5, 2e-5, 1.5e-4)]
    lines = [f'The example MEKF (doc/examples/estimator.yaml), {len(errors)} post-update '
             'estimates over topics after 100 s:', '',
             '| body axis | error, measured 1 sigma (rad) | reported 1 sigma (mean) | '
             'Farrenkopf steady state | measured / theory |', '|---|---|---|---|---|']
    for k, axis in enumerate('xyz'):
        measured = errors[:, k].std()
        lines.append(f'| {axis} | {measured:.3e} | {sigmas[:, k].mean():.3e} | '
                     f'{theory[k]:.3e} | {measured / theory[k]:.3f} |')
    for topic in ('odom', 'attitude_estimate', 'star_tracker'):
        probe.messages.pop(topic)
    return lines


def cost(probe):
    """Measure the simulator's CPU with the gyro alone and with every sensor."""
    probe.subscribe(DiagnosticArray, '/diagnostics')
    body = ('inertia:=[2.0, 3.0, 1.2]', 'initial_angular_velocity:=[0.3, -0.5, 0.8]',
            'imu_rate:=100.0', 'gyro_noise_density:=1e-4')
    orbit = ('orbit_elements:=[6878137.0, 0.0, 1.0, 0.3, 0.0, 0.0]',
             'epoch:=2026-03-20T12:00:00Z', 'magnetic_field_model:=dipole')
    cases = {'gyro at 100 Hz': sim(*body, *orbit),
             'gyro, magnetometer, star tracker, sun sensor': sim(
                 *body, *orbit, 'magnetometer_rate:=10.0', 'magnetometer_noise:=1e-7',
                 'star_tracker_rate:=10.0', 'sun_sensor_rate:=10.0', 'sun_sensor_noise:=1e-3')}
    found = {name: [] for name in cases}
    for _ in range(ROUNDS):
        for name, cmd in cases.items():
            cpu, _diag = measure_cpu(cmd, probe)
            found[name].append(cpu)
            print(f'{name}: {cpu:.3f} of a core', flush=True)
    base = statistics.median(found['gyro at 100 Hz'])
    lines = ['The simulator at 1 kHz in a 500 km orbit (no torque model), real time:', '',
             '| sensors | CPU (share of one core, each run) | / gyro alone |', '|---|---|---|']
    for name, runs in found.items():
        median = statistics.median(runs)
        lines.append(f'| {name} | {", ".join(f"{c:.3f}" for c in runs)} (median {median:.3f}) '
                     f'| {median / base:.2f} |')
    return lines


if __name__ == '__main__':
    print('\n'.join(measure()))
