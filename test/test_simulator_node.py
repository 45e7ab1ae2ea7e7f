"""
attitude_simulator over real topics: the node runs as its own process.

Runs use ``publish_clock:=true`` so that header stamps are the simulated time
from 0, which lets every received state be compared with the exact solution
at its own stamp whatever the test happened to miss while discovering.
"""

import math
import os

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import InertiaStamped, Vector3Stamped, WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rcl_interfaces.srv import SetParameters
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from rigid_body_dynamics.physics import FreeRigidBody, Inertia, presets, quaternions, simulate
from rigid_body_dynamics.ros.conversions import quaternion_array, time_ns, vector_array
from ros_harness import assert_exact, LATCHED, listen_tf, odom_arrays, relative, stamp
from ros_harness import status_count
from rosgraph_msgs.msg import Clock
from std_srvs.srv import SetBool, Trigger

SIM = 'rigid_body_dynamics.nodes.simulator'
NODE = '/attitude_simulator'


def vectors(msgs):
    """(t, v) arrays from Vector3Stamped messages."""
    return np.array([stamp(m) for m in msgs]), np.array([vector_array(m.vector) for m in msgs])


def set_params(probe, **values):
    """Set parameters through the node's service; returns the SetParametersResult list."""
    request = SetParameters.Request(parameters=[
        Parameter(name, value=value).to_parameter_msg() for name, value in values.items()])
    return probe.call(SetParameters, f'{NODE}/set_parameters', request).results


def thread_policies(pid):
    """(scheduling policy, real-time priority) of every thread of a process, from /proc."""
    found = []
    for tid in os.listdir(f'/proc/{pid}/task'):
        with open(f'/proc/{pid}/task/{tid}/stat') as f:
            fields = f.read().rsplit(')', 1)[1].split()
        found.append((int(fields[38]), int(fields[37])))   # stat fields 41 and 40
    return found


def stop_cleanly(proc):
    """SIGINT must end the node with exit code 0 within a second."""
    code, seconds = proc.stop()
    assert code == 0, proc.output()
    assert seconds < 1.0
    assert 'Traceback' not in proc.output()


def test_torque_free_motion_is_exact_and_bad_input_changes_nothing(launch, probe):
    """Default integrator, 10 s simulated; NaN / inf / unknown-frame torques and bad parameters."""
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', 'real_time_factor:=2.0', name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    l_world = probe.subscribe(Vector3Stamped, 'angular_momentum')
    inertia = probe.subscribe(InertiaStamped, 'inertia', LATCHED)
    probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.wait_for('inertia')
    assert inertia[0].header.frame_id == 'base_link'
    assert (inertia[0].inertia.ixx, inertia[0].inertia.iyy, inertia[0].inertia.izz) == \
        (1.0, 1.0, 1.5)
    probe.wait_for('odom', 5)

    torque = probe.publisher(WrenchStamped, 'torque_cmd')
    for k, (vec, frame) in enumerate((
            ((math.nan, 0.0, 0.0), ''), ((0.0, math.inf, 0.0), 'base_link'),
            ((0.0, 0.0, -math.inf), 'odom'), ((1.0, 0.0, 0.0), 'map'),
            ((1.0, 0.0, 0.0), 'x' * 10000))):
        msg = WrenchStamped()
        msg.header.frame_id = frame
        msg.wrench.torque.x, msg.wrench.torque.y, msg.wrench.torque.z = vec
        if k == 0:                  # until the node counts it: then it is matched both ways
            shaken = probe.handshake(torque, msg, lambda: status_count(
                probe, 'torque command', 'rejected_non_finite') > 0)
        else:
            torque.publish(msg)
    refusals = {
        'inertia': ([1.0, 1.0, 5.0], 'triangle'),
        'initial_angular_velocity': ([1.0, math.nan, 0.0], 'finite'),
        'publish_rate': (5000.0, 'publish_rate'),
        'integrator': ('euler', 'unknown integrator'),
        'real_time_factor': (-1.0, ''),
    }
    for name, (value, reason) in refusals.items():
        result = set_params(probe, **{name: value})[0]
        assert not result.successful, name
        assert reason in result.reason, result.reason
    assert not set_params(probe, inertia=[-1.0, 2.0, 2.0])[0].successful
    assert 'read-only' in set_params(probe, integration_rate=10.0)[0].reason

    probe.spin_until(lambda: odom and stamp(odom[-1]) >= 10.0, 30.0, '10 s of simulated time')
    assert len(odom) > 200
    # the published state is the exact solution as if nothing bad had come
    assert_exact(odom, (1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    t, q, w = odom_arrays(odom)
    energy = 0.5 * np.sum(np.array([1.0, 1.0, 1.5]) * w * w, axis=1)
    # (the exact flow keeps them to round-off: 0, 2.2e-16 and 1.5e-16 offline)
    assert np.max(np.abs(energy / energy[0] - 1.0)) <= 1e-14
    _, lw = vectors(l_world)
    assert np.max(np.abs(np.linalg.norm(lw, axis=1) / np.linalg.norm(lw[0]) - 1.0)) <= 1e-14
    angles = np.arctan2(np.linalg.norm(np.cross(lw, lw[0]), axis=1), lw @ lw[0])
    assert np.max(angles) <= 1e-14
    probe.spin_until(lambda: (probe.newest_status('torque command') or (0, '', {}))[2].get(
        'rejected_frame') == '2', 10.0, 'rejections counted in diagnostics')
    _, message, values = probe.newest_status('torque command')
    assert 3 <= int(values['rejected_non_finite']) <= 2 + shaken
    assert values['accepted'] == '0'
    assert 'rejected' in message
    stop_cleanly(proc)


def _torque_on_time(applied):
    """Stamp at which the first non-zero applied torque began (start of its step)."""
    first = next(m for m in applied if any(vector_array(m.wrench.torque)))
    return first, stamp(first)


def test_constant_body_torque_about_the_symmetry_axis(launch, probe):
    """omega3(t) = omega3(t_on) + tau (t - t_on) / I3 for a top spinning about its axis."""
    tau, i3 = 0.3, 1.5
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', 'initial_angular_velocity:=[0,0,2]',
                  '-p', 'torque_timeout:=0.0', '-p', 'publish_rate:=1000.0', name='sim')
    omega = probe.subscribe(Vector3Stamped, 'angular_velocity')
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    probe.wait_for('angular_velocity', 10)
    cmd = WrenchStamped()
    cmd.header.frame_id = 'base_link'
    cmd.wrench.torque.z = tau
    probe.handshake(probe.publisher(WrenchStamped, 'torque_cmd'), cmd,
                    lambda: any(m.wrench.torque.z for m in applied))
    first, t_end_of_first = _torque_on_time(applied)
    assert vector_array(first.wrench.torque).tolist() == [0.0, 0.0, tau]
    t_on = t_end_of_first - 1e-3           # the torque is held over the step ending there
    probe.spin_until(lambda: stamp(omega[-1]) > t_on + 1.0, 20.0, '1 s under torque')
    t, w = vectors(omega)
    before = t < t_on - 1e-9
    w3_on = w[before][-1, 2]
    after = t > t_on
    expected = w3_on + tau * (t[after] - t_on) / i3
    np.testing.assert_allclose(w[after, 2], expected, rtol=1e-9)
    assert np.max(np.abs(w[:, :2])) == 0.0
    stop_cleanly(proc)


def test_torque_schedule_over_topics_matches_offline_simulate(launch, probe):
    """
    A schedule of body torques sent on torque_cmd gives what simulate() gives offline.

    Asymmetric body, every step published (1 kHz); applied_torque says which
    command each step integrated (it is stamped at the end of that step), so the
    offline run replays exactly those torques from the odom state before the first
    one. Both run the default integrator: 1e-12 (rad; relative for omega).
    """
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', 'inertia:=[1.0, 2.0, 3.0]',
                  '-p', 'initial_angular_velocity:=[0.3, 1.5, -0.4]', '-p', 'torque_timeout:=0.0',
                  '-p', 'publish_rate:=1000.0', name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    probe.wait_for('odom', 10)
    pub = probe.publisher(WrenchStamped, 'torque_cmd')
    schedule = [(0.3 * math.sin(0.7 * k), 0.2 * math.cos(1.3 * k), 0.25 * math.sin(0.4 * k + 1.0))
                for k in range(12)]

    def command(tau):
        msg = WrenchStamped()
        msg.header.frame_id = 'base_link'
        msg.wrench.torque.x, msg.wrench.torque.y, msg.wrench.torque.z = tau
        return msg
    probe.handshake(pub, command(schedule[0]),
                    lambda: any(any(vector_array(m.wrench.torque)) for m in applied))
    for tau in schedule[1:]:
        probe.spin_for(0.05)
        pub.publish(command(tau))
    probe.spin_for(0.2)
    ns = {time_ns(m.header.stamp): tuple(vector_array(m.wrench.torque)) for m in applied}
    used = {v for v in ns.values() if any(v)}
    assert len(used) >= 10, f'only {len(used)} of the 12 commands were integrated'
    _, t_first = _torque_on_time(applied)
    t_start_ns = int(round(t_first * 1e9)) - 1_000_000        # state before the first torque
    by_stamp = {time_ns(m.header.stamp): m for m in odom}
    t_end_ns = max(ns)
    steps = (t_end_ns - t_start_ns) // 1_000_000
    missing = [k for k in range(1, steps + 1) if t_start_ns + k * 1_000_000 not in ns]
    assert not missing, f'applied_torque missing for {len(missing)} steps'
    start = by_stamp[t_start_ns]
    _, q0, w0 = odom_arrays([start])
    run = simulate((1.0, 2.0, 3.0), w0[0], q0[0], duration=steps * 1e-3, dt=1e-3,
                   torque=lambda t, _q, _w: ns.get(t_start_ns + int(round(t * 1e3)) * 1_000_000
                                                   + 1_000_000, (0.0, 0.0, 0.0)))
    stamps = t_start_ns + np.round(run.t * 1e3).astype(np.int64) * 1_000_000
    have = [i for i, t in enumerate(stamps) if int(t) in by_stamp]
    assert len(have) > 0.9 * len(stamps)
    _, q, w = odom_arrays([by_stamp[int(stamps[i])] for i in have])
    assert np.max(quaternions.angle_between(q, run.q[have])) < 1e-12
    assert np.max(np.linalg.norm(w - run.omega[have], axis=1)) < 1e-12 * np.linalg.norm(w0)
    assert np.max(np.abs(run.torque[:-1] - np.array(
        [ns[int(t) + 1_000_000] for t in stamps[:-1]]))) == 0.0
    stop_cleanly(proc)


def test_world_torque_changes_l_world_by_its_integral_then_times_out(launch, probe):
    """L_w(t) - L_w(t_on) = tau_w (t - t_on); after the timeout the motion is free again."""
    tau_w = np.array([0.05, -0.02, 0.04])
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', 'preset:=tennis_racket',
                  '-p', 'torque_timeout:=0.3', '-p', 'publish_rate:=1000.0', name='sim')
    l_world = probe.subscribe(Vector3Stamped, 'angular_momentum')
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    odom = probe.subscribe(Odometry, 'odom')
    probe.wait_for('angular_momentum', 10)
    cmd = WrenchStamped()
    cmd.header.frame_id = 'odom'
    cmd.wrench.torque.x, cmd.wrench.torque.y, cmd.wrench.torque.z = tau_w
    cmd.wrench.force.x = 1.0                           # ignored, with a warning
    # a repeat would restart the 0.3 s timeout, so it comes only after 1 s without an effect
    probe.handshake(probe.publisher(WrenchStamped, 'torque_cmd'), cmd,
                    lambda: any(any(vector_array(m.wrench.torque)) for m in applied), period=1.0)
    _, t_first = _torque_on_time(applied)
    t_on = t_first - 1e-3
    # wait for the timeout (0.3 s of steady time at real time) and 1 s of free motion
    probe.spin_until(lambda: stamp(applied[-1]) > t_on + 1.5, 20.0, 'the timeout')
    torques = np.array([vector_array(m.wrench.torque) for m in applied])
    t_applied = np.array([stamp(m) for m in applied])
    on = np.any(torques != 0.0, axis=1)
    t_off = t_applied[on][-1]                          # last step under torque ends here
    assert 0.2 < t_off - t_on < 0.5                    # about the 0.3 s timeout
    assert not np.any(on[t_applied > t_off])           # zero after the timeout
    t, lw = vectors(l_world)
    l_on = lw[np.argmin(np.abs(t - t_on))]
    during = (t > t_on) & (t <= t_off)
    expected = l_on + np.outer(t[during] - t_on, tau_w)
    np.testing.assert_allclose(lw[during], expected, rtol=0, atol=1e-9 * np.linalg.norm(l_on))
    after = t > t_off
    np.testing.assert_allclose(lw[after], lw[after][0] + 0.0 * lw[after], atol=1e-12)
    # the free motion after the timeout is exact from the state at t_off
    to, qo, wo = odom_arrays(odom)
    k = np.argmin(np.abs(to - t_off))
    free = FreeRigidBody((1.0, 2.0, 3.0), wo[k], qo[k])
    later = to > t_off
    q_ref, w_ref = free.state_at(to[later] - to[k])
    assert np.max(quaternions.angle_between(qo[later], q_ref)) < 1e-9
    assert 'only the torque is used' in proc.output()
    stop_cleanly(proc)


def test_reset_and_pause(launch, probe):
    proc = launch(SIM, '-p', 'publish_clock:=true', name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    probe.spin_until(lambda: odom and stamp(odom[-1]) > 0.5, 20.0, '0.5 s of motion')
    paused = probe.call(SetBool, f'{NODE}/pause', SetBool.Request(data=True))
    assert paused.success and paused.message == 'paused'
    probe.spin_for(0.3)
    count = len(odom)
    t_paused = stamp(odom[-1])
    probe.spin_for(0.5)
    assert len(odom) == count                          # frozen: nothing new published
    probe.call(SetBool, f'{NODE}/pause', SetBool.Request(data=False))
    probe.spin_until(lambda: stamp(odom[-1]) > t_paused + 0.2, 10.0, 'motion after resume')
    t = np.array([stamp(m) for m in odom])
    # resumed where it stopped: every 10 ms tick once, no jump over the pause (ns stamps)
    assert np.all(np.abs(np.diff(t) - 0.01) < 1e-8), np.diff(t)[np.abs(np.diff(t) - 0.01) > 1e-8]
    assert_exact(odom, (1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    result = probe.call(Trigger, f'{NODE}/reset', Trigger.Request())
    assert result.success
    n_before = len(odom)
    probe.spin_until(lambda: len(odom) > n_before + 5, 10.0, 'motion after reset')
    t_after = np.array([stamp(m) for m in odom[n_before:]])
    assert t_after[0] < 0.1                            # time restarted at 0
    assert_exact(odom[n_before:], (1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    stop_cleanly(proc)


def test_two_namespaces_remapping_and_clock(launch, probe):
    a = launch(SIM, '-r', '__ns:=/sat_a', '-p', 'publish_clock:=true',
               '-r', 'odom:=truth', name='sat_a')
    b = launch(SIM, '-r', '__ns:=/sat_b', '-p', 'preset:=tennis_racket', name='sat_b')
    truth_a = probe.subscribe(Odometry, '/sat_a/truth')
    odom_b = probe.subscribe(Odometry, '/sat_b/odom')
    inertia_a = probe.subscribe(InertiaStamped, '/sat_a/inertia', LATCHED)
    inertia_b = probe.subscribe(InertiaStamped, '/sat_b/inertia', LATCHED)
    clock = probe.subscribe(Clock, '/clock', qos_profile_sensor_data)
    probe.wait_for('/sat_a/truth', 20)
    probe.wait_for('/sat_b/odom', 20)
    probe.wait_for('/clock', 20)
    probe.wait_for('/sat_a/inertia', 1)                 # latched, but each topic has its own
    probe.wait_for('/sat_b/inertia', 1)                 # discovery: may come after the odom
    assert inertia_a[0].inertia.izz == 1.5 and inertia_b[0].inertia.izz == 3.0
    assert_exact(truth_a, (1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    # b is the tennis racket, stamped from the ROS time at its start (no /clock)
    start_b = time_ns(inertia_b[0].header.stamp)
    assert_exact(relative(odom_b, start_b), (1.0, 2.0, 3.0), (0.01, 2.0, 0.01))
    clock_t = [c.clock.sec + 1e-9 * c.clock.nanosec for c in clock]
    assert clock_t[-1] > clock_t[0] and np.all(np.diff(clock_t) > 0.0)
    stop_cleanly(a)
    stop_cleanly(b)


def test_unknown_preset_and_bad_inertia_refuse_to_start(launch):
    proc = launch(SIM, '-p', 'preset:=hoop', name='bad_preset')
    assert proc.wait(20.0) == 1
    assert "unknown preset 'hoop'" in proc.output()
    proc = launch(SIM, '-p', 'inertia:=[1.0, 1.0, 3.0]', name='bad_inertia')
    assert proc.wait(20.0) == 1
    assert 'triangle inequality' in proc.output()


def test_rotated_tensor_publishes_in_the_users_body_frame(launch, probe):
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])   # 90 deg about z
    tensor = rot @ np.diag([1.0, 2.0, 3.0]) @ rot.T
    six = [tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]]
    w_user = rot @ np.array([0.3, 0.5, 2.0])
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', 'real_time_factor:=5.0',
                  '-p', 'inertia_tensor:=[' + ','.join(f'{v:.1f}' for v in six) + ']',
                  '-p', 'initial_angular_velocity:=[' + ','.join(repr(float(v)) for v in w_user)
                  + ']', name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    probe.spin_until(lambda: odom and stamp(odom[-1]) > 2.0, 20.0, '2 s of motion')
    assert_exact(odom, Inertia.from_tensor(tensor), tuple(w_user))
    stop_cleanly(proc)


@pytest.mark.parametrize('signal_name', ['SIGTERM', 'SIGINT'])
def test_signals_exit_zero(launch, probe, signal_name):
    import signal
    proc = launch(SIM, name='sim')
    probe.subscribe(Odometry, 'odom')
    probe.wait_for('odom', 3)
    proc.proc.send_signal(getattr(signal, signal_name))
    assert proc.wait(5.0) == 0
    assert 'Traceback' not in proc.output()


def test_as_fast_as_possible_still_serves_services_and_diagnostics(launch, probe):
    """real_time_factor 0 must not starve the executor: services, parameters, diagnostics."""
    proc = launch(SIM, '-p', 'real_time_factor:=0.0', '-p', 'publish_rate:=1.0', name='sim')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.wait_for('/diagnostics', 2, timeout=20.0)
    _, _, values = probe.newest_status('integrator')
    assert float(values['achieved real-time factor']) > 5.0
    assert probe.call(Trigger, f'{NODE}/reset', Trigger.Request(), timeout=10.0).success
    assert set_params(probe, max_torque=2.0)[0].successful
    stop_cleanly(proc)


def test_thread_priority_is_applied_or_refused_with_the_reason(launch, probe):
    """SCHED_FIFO for the integration thread: used where allowed, a warning where not."""
    proc = launch(SIM, '-p', 'thread_priority:=100', name='bad_priority')
    assert proc.wait(20.0) == 1
    assert 'thread_priority out of range. Min: 0, Max: 99' in proc.output()
    proc = launch(SIM, '-p', 'thread_priority:=2.5', name='float_priority')
    assert proc.wait(20.0) == 1
    assert "'thread_priority' to '2.5' of type 'DOUBLE', expecting type 'INTEGER'" in \
        proc.output()
    proc = launch(SIM, '-p', 'thread_priority:=10', name='priority')
    odom = probe.subscribe(Odometry, 'odom')
    probe.wait_for('odom', 20)
    output = proc.output()
    assert len(odom) >= 20                         # runs either way
    if 'SCHED_FIFO refused' in output:
        assert 'integration thread keeps normal scheduling' in output
        stop_cleanly(proc)
        assert not os.environ.get('RBD_REQUIRE_SCHED_FIFO'), output
        pytest.skip('this machine refuses SCHED_FIFO (no CAP_SYS_NICE / rtprio limit): '
                    'the refusal was logged and the node ran normally')
    assert 'SCHED_FIFO at priority 10' in output
    assert (1, 10) in thread_policies(proc.proc.pid)   # one thread really runs under it
    stop_cleanly(proc)


def test_noisy_gyro_stream_is_the_seeded_model_at_the_imu_stamps(launch, probe):
    """
    The imu topic carries what offline simulate(gyro=...) reads, ~/imu_bias its true bias.

    Gyro at 200 Hz (every 5th step), noise density 1e-3, bias random walk 1e-4, turn-on bias
    1e-3, orientation noise 0.01 rad, seed 42. The stream is a function of the sample index
    only, so the offline run with the same model reproduces every received sample (rates and
    orientations to 1e-12, the bias bit for bit).
    """
    from sensor_msgs.msg import Imu
    from rigid_body_dynamics.physics.sensors import GyroErrors, GyroModel
    omega0 = (0.3, 1.5, -0.4)
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', 'inertia:=[1.0, 2.0, 3.0]',
                  '-p', 'initial_angular_velocity:=[0.3, 1.5, -0.4]', '-p', 'imu_rate:=200.0',
                  '-p', 'gyro_noise_density:=0.001', '-p', 'gyro_bias_random_walk:=0.0001',
                  '-p', 'gyro_turn_on_bias:=0.001', '-p', 'orientation_noise:=0.01',
                  '-p', 'noise_seed:=42', '-p', 'real_time_factor:=2.0', name='sim')
    imu = probe.subscribe(Imu, 'imu')
    bias = probe.subscribe(Vector3Stamped, f'{NODE}/imu_bias')
    probe.spin_until(lambda: len(imu) > 300 and len(bias) > 300, 30.0, '300 gyro samples')
    index = np.array([time_ns(m.header.stamp) for m in imu]) // 5_000_000
    assert np.all(np.array([time_ns(m.header.stamp) for m in imu]) % 5_000_000 == 0)
    model = GyroModel(GyroErrors(1e-3, 1e-4, 1e-3, orientation_noise=0.01), 200.0, seed=42)
    offline = simulate((1.0, 2.0, 3.0), omega0, duration=index.max() * 5e-3, dt=1e-3,
                       gyro=model).imu
    measured = np.array([vector_array(m.angular_velocity) for m in imu])
    np.testing.assert_allclose(measured, offline.omega[index], rtol=0, atol=1e-12)
    reported = np.array([quaternion_array(m.orientation) for m in imu])
    np.testing.assert_allclose(reported, offline.q[index], rtol=0, atol=1e-12)
    _, w_true = FreeRigidBody((1.0, 2.0, 3.0), omega0).state_at(offline.t)
    assert np.max(np.abs(measured - w_true[index])) > 1e-3        # the noise is really there
    b_index = np.array([time_ns(m.header.stamp) for m in bias]) // 5_000_000
    np.testing.assert_array_equal(np.array([vector_array(m.vector) for m in bias]),
                                  offline.bias[b_index])
    # the white noise over topics: imu - truth - bias has N sqrt(rate) per sample, within 10 %
    white = measured - w_true[index] - offline.bias[index]
    assert white.std() == pytest.approx(1e-3 * math.sqrt(200.0), rel=0.10)
    cov = imu[-1].angular_velocity_covariance
    assert [cov[0], cov[4], cov[8]] == pytest.approx([1e-6 * 200.0] * 3, rel=1e-14)  # N^2 rate
    assert cov[1] == 0.0
    assert list(imu[-1].orientation_covariance)[::4] == pytest.approx([1e-4] * 3, rel=1e-14)
    assert imu[-1].linear_acceleration_covariance[0] == -1.0
    stop_cleanly(proc)


def test_tf_is_broadcast_with_the_odom_stamp_and_frames(launch, tf2_msgs_env):
    """
    /tf carries odom -> base_link at every odom stamp, the odom orientation, no translation.

    Simulator and listener run with the tf2_msgs interface built from its definition
    (test/tf2_msgs_build.py); the /tf publisher's type hash is Jazzy's, so a ROS install's
    tf2 listeners and RViz accept it; tf2_ros' broadcaster QoS (reliable, volatile).
    """
    import tf2_msgs_build
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', 'inertia:=[1.0, 2.0, 3.0]',
                  '-p', 'initial_angular_velocity:=[0.3, 1.5, -0.4]',
                  '-p', 'real_time_factor:=2.0', name='sim_tf', env=tf2_msgs_env)
    got = listen_tf(tf2_msgs_env, 100, 'odom')
    odom = dict(got['odom'])                         # stamp -> quaternion
    assert all(len(m) == 1 for m in got['tf'])
    transforms = [m[0] for m in got['tf']]
    matched = [t for t in transforms if t[0] in odom]
    assert len(matched) >= 90                        # each TF has an odom at its very stamp
    for t, parent, child, translation, rotation in transforms:
        assert (parent, child) == ('odom', 'base_link')
        assert translation == [0.0, 0.0, 0.0]
        if t in odom:
            assert rotation == odom[t]               # the same quaternion, bit for bit
    stamps = [t[0] for t in transforms]
    assert stamps == sorted(stamps) and len(set(np.diff(stamps))) == 1   # every 10 ms tick
    assert got['publishers'] == [['attitude_simulator', 'tf2_msgs/msg/TFMessage',
                                  tf2_msgs_build.JAZZY_TYPE_HASH, 'RELIABLE', 'VOLATILE']]
    assert 'tf2_msgs is not importable' not in proc.output()
    stop_cleanly(proc)


def test_two_namespaced_simulators_give_two_tf_trees(launch, tf2_msgs_env):
    """
    Two simulators in /sat1 and /sat2 with frame_prefix sat1/ and sat2/: /tf has both trees.

    Each broadcasts its own sat<k>/odom -> sat<k>/base_link (and no plain odom ->
    base_link); odom carries the same frame ids.
    """
    for k in (1, 2):
        launch(SIM, '-r', f'__ns:=/sat{k}', '-p', f'frame_prefix:=sat{k}/',
               '-p', 'real_time_factor:=2.0', name=f'sim{k}', env=tf2_msgs_env)
    got = listen_tf(tf2_msgs_env, 100, '/sat2/odom')
    pairs = {(t[1], t[2]) for m in got['tf'] for t in m}
    assert pairs == {('sat1/odom', 'sat1/base_link'), ('sat2/odom', 'sat2/base_link')}, pairs
    assert len(got['publishers']) == 2


def test_a_bad_frame_prefix_is_refused_naming_it(launch):
    proc = launch(SIM, '-p', 'frame_prefix:=/sat1/', name='bad_prefix')
    assert proc.wait(20.0) == 1
    assert 'frame_prefix must not start with /' in proc.output(), proc.output()


def test_without_tf2_msgs_the_simulator_says_so_and_runs(launch, probe):
    """Where tf2_msgs cannot be imported (pip-only), no /tf publisher and one info line."""
    proc = launch(SIM, '-p', 'real_time_factor:=2.0', name='sim_no_tf')
    probe.subscribe(Odometry, 'odom')
    probe.wait_for('odom', 5)                       # running: the state topics are there
    assert probe.node.get_publishers_info_by_topic('/tf') == []
    assert 'tf2_msgs is not importable' in proc.output()
    stop_cleanly(proc)


def test_the_manuals_gyro_yaml_gives_that_gyro(launch, probe, tmp_path):
    """
    The parameters file of the manual's "noisy IMU" guide, as a user passes it, sets the imu.

    N = 1e-4 at 200 Hz: angular velocity covariance N^2 * 200 = 2e-6, orientation 0.002^2;
    the stream is seed 7's (the offline model's at every index; the bias bit for bit) and
    imu minus truth minus bias has N sqrt(200) per sample (within 10 %).
    """
    from sensor_msgs.msg import Imu
    from rigid_body_dynamics.physics.sensors import GyroErrors, GyroModel
    params = os.path.join(os.path.dirname(__file__), '..', 'doc', 'examples', 'gyro.yaml')
    proc = launch(SIM, '--params-file', str(params), '-p', 'publish_clock:=true',
                  '-p', 'real_time_factor:=4.0', name='sim_yaml')
    imu = probe.subscribe(Imu, 'imu')
    bias = probe.subscribe(Vector3Stamped, f'{NODE}/imu_bias')
    probe.spin_until(lambda: len(imu) > 400 and len(bias) > 400, 30.0, '400 gyro samples')
    stamps = np.array([time_ns(m.header.stamp) for m in imu])
    assert np.all(np.diff(stamps) == 5_000_000)                   # 200 Hz
    cov = imu[-1].angular_velocity_covariance
    assert [cov[0], cov[4], cov[8]] == pytest.approx([1e-8 * 200.0] * 3, rel=1e-14)
    assert list(imu[-1].orientation_covariance)[::4] == pytest.approx([4e-6] * 3, rel=1e-14)
    # every received sample is the offline model's at its index (bias bit for bit)
    index = stamps // 5_000_000
    preset = presets.get(presets.DEFAULT)
    offline = simulate(preset.moments, preset.omega0, preset.q0, duration=index.max() * 5e-3,
                       dt=1e-3, gyro=GyroModel(GyroErrors(1e-4, 1e-6, 1e-3,
                                                          orientation_noise=0.002),
                                               200.0, seed=7)).imu
    b_index = np.array([time_ns(m.header.stamp) for m in bias]) // 5_000_000
    b = np.array([vector_array(m.vector) for m in bias])
    np.testing.assert_array_equal(b, offline.bias[b_index])
    assert np.all(b.std(axis=0) > 0.0)                            # the bias walks
    measured = np.array([vector_array(m.angular_velocity) for m in imu])
    np.testing.assert_allclose(measured, offline.omega[index], rtol=0, atol=1e-12)
    truth = simulate(preset.moments, preset.omega0, preset.q0, duration=index.max() * 5e-3,
                     dt=1e-3, every=5).omega
    white = measured - truth[index] - offline.bias[index]
    assert white.std() == pytest.approx(1e-4 * math.sqrt(200.0), rel=0.10)
    stop_cleanly(proc)


def test_state_topics_leaves_out_what_is_not_asked_for(launch, probe):
    """state_topics: only the named topics besides odom are published; a typo is refused."""
    proc = launch(SIM, '-p', 'state_topics:=applied_torque', '-p', 'publish_imu:=false',
                  name='sim_topics')
    probe.subscribe(Odometry, 'odom')
    probe.subscribe(WrenchStamped, 'applied_torque')
    probe.wait_for('odom', 5)
    probe.wait_for('applied_torque', 5)
    for topic in ('/orientation', '/angular_velocity', '/angular_momentum',
                  '/angular_momentum_body', '/imu'):
        assert probe.node.get_publishers_info_by_topic(topic) == [], topic
    stop_cleanly(proc)
    bad = launch(SIM, '-p', 'state_topics:=odom,angular_speed', name='sim_bad_topics')
    assert bad.wait(30.0) == 1
    assert 'state_topics: unknown topic(s) odom, angular_speed' in bad.output()


def test_frames_initial_orientation_and_no_tf_as_configured(launch, probe):
    """world_frame, body_frame, initial_orientation (normalised) and publish_tf:=false act."""
    q0 = [0.0, 0.0, 2.0 * math.sin(0.3), 2.0 * math.cos(0.3)]     # not unit: normalised
    launch(SIM, '-p', 'publish_clock:=true', '-p', 'world_frame:=earth', '-p',
           'body_frame:=sat', '-p', f'initial_orientation:={q0}', '-p', 'publish_tf:=false',
           '-p', 'initial_angular_velocity:=[0.0, 0.0, 0.0]', name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    probe.wait_for('odom', 3)
    m = odom[-1]
    assert m.header.frame_id == 'earth' and m.child_frame_id == 'sat'
    # at rest and free the attitude stays the initial one, normalised
    unit = np.array(q0) / 2.0
    assert quaternions.angle_between(quaternion_array(m.pose.pose.orientation), unit) < 1e-15
    # no /tf from this node, and a command in its body frame is taken, one in another refused
    probe.spin_until(lambda: probe.endpoints('pub', 'attitude_simulator'), 10.0, 'the node')
    assert '/tf' not in probe.endpoints('pub', 'attitude_simulator')
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    pub = probe.publisher(WrenchStamped, 'torque_cmd')
    command = WrenchStamped()
    command.header.frame_id = 'sat'
    command.wrench.torque.x = 0.1
    probe.handshake(pub, command, lambda: applied and applied[-1].wrench.torque.x == 0.1)
    assert applied[-1].header.frame_id == 'sat'
    command.header.frame_id = 'base_link'
    pub.publish(command)
    probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.spin_until(lambda: status_count(probe, 'torque command', 'rejected_frame') >= 1,
                     10.0, 'the base_link command refused')


def test_max_torque_changed_at_run_time_clips_the_next_command(launch, probe):
    """A max_torque of 0.05 set at run time: a 1 N m command acts as 0.05, counted."""
    launch(SIM, '-p', 'publish_clock:=true', name='sim')
    assert set_params(probe, max_torque=0.05)[0].successful
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    pub = probe.publisher(WrenchStamped, 'torque_cmd')
    command = WrenchStamped()
    command.wrench.torque.z, command.wrench.torque.x = 1.0, -0.02
    probe.handshake(pub, command, lambda: applied and applied[-1].wrench.torque.z != 0.0)
    torque = applied[-1].wrench.torque
    assert (torque.x, torque.y, torque.z) == (-0.02, 0.0, 0.05)
    probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.spin_until(lambda: status_count(probe, 'torque command', 'clipped') >= 1, 10.0,
                     'the clipping counted')
