"""
Closed loop over topics: lockstep determinism, the example controller, misses, disturbances.

The simulator and attitude_controller run as their own processes, started
through the package's pytest plugin (rigid_body_dynamics.testing), the way a
user's test would start them.
"""

import math
import os
import signal
import subprocess
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rigid_body_dynamics.physics import presets, quaternions, simulate
from rigid_body_dynamics.physics.control import QuaternionPD, settling_time
from rigid_body_dynamics.ros.conversions import status_values, time_ns

TARGET = (0.0, 0.0, math.sin(math.pi / 8), math.cos(math.pi / 8))     # 45 degrees about z
CONTROL = ('-p', f'target_orientation:={list(TARGET)}', '-p', 'natural_frequency:=2.0',
           '-p', 'damping_ratio:=0.7', '-p', 'max_torque:=2.0')


def _fields(msg):
    """Every field of an Odometry, as a tuple (CDR bytes would include padding garbage)."""
    p, t = msg.pose, msg.twist
    return (time_ns(msg.header.stamp), msg.header.frame_id, msg.child_frame_id,
            (p.pose.position.x, p.pose.position.y, p.pose.position.z),
            (p.pose.orientation.x, p.pose.orientation.y, p.pose.orientation.z,
             p.pose.orientation.w), tuple(p.covariance),
            (t.twist.linear.x, t.twist.linear.y, t.twist.linear.z),
            (t.twist.angular.x, t.twist.angular.y, t.twist.angular.z), tuple(t.covariance))


def _stream(sim, until):
    """Run until ``until`` s; every state's fields, in order (the t_0 repeats dropped)."""
    sim.wait_until(until, timeout=120.0)
    seen, out = set(), []
    for msg in sim.odom:
        stamp = time_ns(msg.header.stamp)
        if stamp not in seen:
            seen.add(stamp)
            out.append(_fields(msg))
    return out


def _hogs(count=2):
    """Busy processes, one per core: the second run happens on a loaded machine."""
    return [subprocess.Popen([sys.executable, '-c', 'while True: pass']) for _ in range(count)]


def test_lockstep_is_deterministic_under_load_and_equals_the_offline_loop(attitude_sim):
    """
    Two lockstep runs of the example controller, the second beside two CPU hogs.

    Slew of the default body (spinning at 2 rad/s) to 45 degrees about z, 100 Hz control,
    5 s simulated: both odom streams are identical, every field and stamp, and equal the
    offline closed loop (simulate with the same law held per 10 ms period), bit for bit.
    """
    runs = []
    for loaded in (False, True):
        hogs = _hogs() if loaded else []
        try:
            sim = attitude_sim('symmetric_top')
            sim.start('attitude_controller', *CONTROL)
            runs.append(_stream(sim, 5.0))
            assert sim.stop() == 0
        finally:
            for hog in hogs:
                hog.kill()
                hog.wait()
    a, b = runs
    n = min(len(a), len(b))
    assert n >= 501 and [f[0] for f in a[:n]] == [k * 10_000_000 for k in range(n)]
    assert a[:n] == b[:n]                 # every field of every state, every stamp
    # the offline loop: the same law on the same body, held per control period
    body = presets.get('symmetric_top')
    law = QuaternionPD(body.moments, TARGET, 2.0, 0.7, 2.0)
    run = simulate(body.moments, body.omega0, body.q0, duration=5.0, dt=1e-3,
                   torque=lambda t, q, w: law(q, w), torque_every=10, every=10)
    q = np.array([f[4] for f in a[:501]])
    w = np.array([f[7] for f in a[:501]])
    # one stepping core: bit for bit
    np.testing.assert_array_equal(q, run.q)
    np.testing.assert_array_equal(w, run.omega)
    assert quaternions.angle_between(q[0], np.array(TARGET)) > 0.7      # it did slew,
    assert quaternions.angle_between(q[-1], np.array(TARGET)) < 0.01    # spin and all


def test_slew_in_real_time_settles_as_the_pd_theory_says(attitude_sim):
    """
    No lockstep: the body at rest slews 20 degrees about x at wn = 2 rad/s, zeta = 0.7.

    The 2 % settling time of the error angle is within 20 % of the linear PD response's
    (control.settling_time: 2.99 s); commands take a few ms over DDS and are held 10 ms.
    """
    target = (math.sin(math.radians(10.0)), 0.0, 0.0, math.cos(math.radians(10.0)))
    sim = attitude_sim('symmetric_top', lockstep=False, initial_angular_velocity=[0, 0, 0],
                       real_time_factor=2.0)
    sim.start('attitude_controller', '-p', f'target_orientation:={list(target)}',
              '-p', 'natural_frequency:=2.0', '-p', 'damping_ratio:=0.7')

    def error_of(m):
        o = m.pose.pose.orientation
        return quaternions.angle_between(np.array([o.x, o.y, o.z, o.w]), np.array(target))

    def attitude():
        t = np.array([time_ns(m.header.stamp) for m in sim.odom]) * 1e-9
        return t, np.array([error_of(m) for m in sim.odom])
    # (only the first and the newest state while waiting: the whole list at every spin made
    # the wait quadratic, and the probe fell seconds of simulated time behind the simulator)
    sim._spin_until(lambda: error_of(sim.odom[-1]) < error_of(sim.odom[0]) - 1e-6, 60.0,
                    'the controller to move the body')
    t, error = attitude()
    start = t[np.flatnonzero(error < error[0] - 1e-6)[0] - 1]   # the first command acted here
    sim.wait_until(start + 8.0, timeout=60.0)
    t, error = attitude()
    outside = np.flatnonzero(error > 0.02 * error[0])
    settled = t[outside[-1]] - start
    predicted = settling_time(2.0, 0.7)
    assert predicted == pytest.approx(2.99, abs=0.01)
    assert settled == pytest.approx(predicted, rel=0.20)
    assert error[-1] < 0.005 * error[0]
    assert sim.stop() == 0


def test_a_controller_that_stops_answering_costs_misses_not_the_run(attitude_sim):
    """
    The test answers the first 20 ticks itself, then falls silent (lockstep_timeout 0.2 s).

    The simulator counts the missed ticks in /diagnostics, goes on one tick per timeout with
    the last command held, still serves ~/pause, and ends within a second of SIGINT with 0.
    """
    sim = attitude_sim('symmetric_top', lockstep_timeout=0.2)
    client = sim._client
    pub = client.node.create_publisher(WrenchStamped, 'torque_cmd', 10)
    diags = []
    client.node.create_subscription(DiagnosticArray, '/diagnostics', diags.append, 10)
    answered = []

    def answer(msg):
        if len(answered) < 20 and time_ns(msg.header.stamp) not in answered:
            answered.append(time_ns(msg.header.stamp))
            cmd = WrenchStamped()
            cmd.header.stamp = msg.header.stamp
            cmd.wrench.torque.z = 0.05
            pub.publish(cmd)
    client.node.create_subscription(Odometry, 'odom', answer, 10)
    client.spin_until(lambda: len(answered) == 20, 30.0, '20 answered ticks')
    t_silent = time.monotonic()
    sim.wait_until(0.19 + 0.05, timeout=10.0)          # 5 more ticks, each after a timeout
    took = time.monotonic() - t_silent
    assert 4 * 0.2 <= took < 5 * 0.2 + 1.0

    def integrator_value(key):
        for array in reversed(diags):
            for status in array.status:
                if status.name.endswith(': integrator'):
                    return int(status_values(status).get(key, 0))
        return 0
    client.spin_until(lambda: integrator_value('missed ticks') >= 4, 5.0,
                      'missed ticks in diagnostics')
    assert integrator_value('answered ticks') == 20
    assert sim.pause(True) == 'paused' and sim.pause(False) == 'running'
    start = time.monotonic()
    sim.process.send_signal(signal.SIGINT)
    assert sim.process.wait(5.0) == 0 and time.monotonic() - start < 1.0


def test_the_manuals_closed_loop_example_passes_as_written(tmp_path):
    """The ten-line controller test of the manual's tutorial passes under pytest, as written."""
    example = os.path.join(os.path.dirname(__file__), '..', 'doc', 'examples', 'test_detumble.py')
    text = open(example).read()
    assert len(text.strip().splitlines()) <= 12
    (tmp_path / 'test_user.py').write_text(text)
    env = {k: v for k, v in os.environ.items() if not k.startswith('ROS_DOMAIN')}
    result = subprocess.run([sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider',
                             str(tmp_path / 'test_user.py')], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=180)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-2000:]
    assert '1 passed' in result.stdout


@pytest.mark.parametrize('args, reason', [
    (('-p', 'lockstep:=true', '-p', 'control_period:=0.0015'),
     'control_period must be a whole number of integration steps'),
    (('-p', 'lockstep:=true', '-p', 'lockstep_answer:=magnetorquer_cmd'),
     'lockstep_answer magnetorquer_cmd needs magnetorquers'),
    (('-p', 'disturbance_torque_body:=[0.0, .nan, 0.0]',), 'disturbance_torque_body'),
])
def test_bad_closed_loop_parameters_are_refused_with_the_reason(launch, args, reason):
    proc = launch('rigid_body_dynamics.nodes.simulator', *args, name='bad_closed_loop')
    assert proc.wait(30.0) == 1
    assert reason in proc.output()


def _latch_inertia(probe, moments=(1.0, 2.0, 3.0)):
    """Publish the body's inertia latched, as the simulator does (the controller waits for it)."""
    from geometry_msgs.msg import InertiaStamped
    from ros_harness import LATCHED
    msg = InertiaStamped()
    msg.inertia.ixx, msg.inertia.iyy, msg.inertia.izz = moments
    probe.node.create_publisher(InertiaStamped, 'inertia', LATCHED).publish(msg)


def test_the_controller_takes_best_effort_odometry_when_told(launch, probe):
    """
    Answer a best-effort odom source once told so by qos_overrides.

    It does not reach the controller's reliable subscription by default; with
    qos_overrides./odom.subscription.reliability best_effort it does, and is answered.
    """
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from ros_harness import odom_msg
    best_effort = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
    launch('rigid_body_dynamics.nodes.controller', '-p', 'control_rate:=0.0',
           '-p', 'qos_overrides./odom.subscription.reliability:=best_effort', name='ctl')
    answers = probe.subscribe(WrenchStamped, 'torque_cmd')
    _latch_inertia(probe)
    odom = probe.publisher(Odometry, 'odom', qos=best_effort)
    probe.handshake(odom, odom_msg(0.01, (0.0, 0.0, 0.0, 1.0), (0.1, 0.0, 0.0)),
                    lambda: bool(answers))
    assert answers[0].wrench.torque.x < 0.0          # the target is rest: it brakes omega_x


def test_the_controller_drops_hostile_odometry_and_exits_zero(launch, probe):
    """A NaN rate or a zero quaternion is not answered (warned, counted); SIGINT exits 0."""
    from ros_harness import odom_msg
    ctl = launch('rigid_body_dynamics.nodes.controller', '-p', 'control_rate:=0.0', name='ctl')
    answers = probe.subscribe(WrenchStamped, 'torque_cmd')
    _latch_inertia(probe)
    odom = probe.publisher(Odometry, 'odom')
    probe.handshake(odom, odom_msg(0.01, (0.0, 0.0, 0.0, 1.0), (0.1, 0.0, 0.0)),
                    lambda: bool(answers))
    n = len(answers)
    # (each alone: the controller answers the newest of the states pending together)
    odom.publish(odom_msg(0.02, (0.0, 0.0, 0.0, 1.0), (float('nan'), 0.0, 0.0)))
    probe.spin_until(lambda: 'odom with a non-finite value dropped (1 so far)' in ctl.output(),
                     10.0, 'the NaN state dropped')
    odom.publish(odom_msg(0.03, (0.0, 0.0, 0.0, 0.0), (0.1, 0.0, 0.0)))
    probe.spin_until(lambda: 'odom with a zero quaternion dropped (2 so far)' in ctl.output(),
                     10.0, 'the zero quaternion dropped')
    assert len(answers) == n                         # neither was answered
    odom.publish(odom_msg(0.04, (0.0, 0.0, 0.0, 1.0), (0.2, 0.0, 0.0)))
    probe.spin_until(lambda: len(answers) > n, 10.0, 'the next good state answered')
    a = answers[-1]
    assert a.header.stamp.nanosec == 40_000_000 and a.wrench.torque.x < answers[0].wrench.torque.x
    code, _ = ctl.stop()
    assert code == 0 and 'Traceback' not in ctl.output()


def _answers_by_stamp(answers):
    return [(time_ns(a.header.stamp), a) for a in answers]


def test_the_controller_answers_a_state_sent_again_with_the_same_command(launch, probe):
    """
    A state it answered, seen again, is answered again the same; one not due is not.

    Lockstep sends its first state again every second until the tick is answered: the
    answer to the first copy is lost when the simulator's subscription did not know the
    controller's publisher yet, and the run must not then wait for ever.
    """
    from ros_harness import odom_msg
    launch('rigid_body_dynamics.nodes.controller', name='ctl')        # 100 Hz of stamps
    answers = probe.subscribe(WrenchStamped, 'torque_cmd')
    _latch_inertia(probe)
    odom = probe.publisher(Odometry, 'odom')
    q = (0.1, 0.0, 0.0, math.sqrt(0.99))
    probe.handshake(odom, odom_msg(0.0, q, (0.1, 0.0, 0.0)), lambda: bool(answers))
    # (each alone: the controller answers the newest of the states pending together)
    for k in (1, 2):                          # due, answered; the same again, answered again
        odom.publish(odom_msg(0.01, q, (0.2, 0.0, 0.0)))
        probe.spin_until(lambda: sum(t == 10_000_000 for t, _ in _answers_by_stamp(
            answers)) == k, 10.0, f'answer {k} to the state at 0.01 s')
    odom.publish(odom_msg(0.01, q, (0.3, 0.0, 0.0)))          # other values, not due
    odom.publish(odom_msg(0.015, q, (0.2, 0.0, 0.0)))         # not due
    odom.publish(odom_msg(0.02, q, (0.2, 0.0, 0.0)))          # due
    probe.spin_until(lambda: any(t == 20_000_000 for t, _ in _answers_by_stamp(answers)),
                     10.0, 'the answer to the state at 0.02 s')
    got = [(t, a.wrench.torque) for t, a in _answers_by_stamp(answers) if t > 0]
    assert [t for t, _ in got] == [10_000_000, 10_000_000, 20_000_000], got
    assert got[0][1] == got[1][1] and got[0][1].x < 0.0


def test_bdot_answers_a_reading_sent_again_with_the_same_dipole(launch, probe):
    """
    A magnetometer reading it answered, seen again, gets the same dipole, not a new dB/dt.

    The law keeps the last reading for dB/dt: going through it a second time with the same
    reading would give zero (no time passed), so the answer sent again is the one kept.
    """
    from geometry_msgs.msg import Vector3Stamped
    from rigid_body_dynamics.physics.control import BDot
    from rigid_body_dynamics.ros.conversions import time_msg, vector_msg
    from sensor_msgs.msg import MagneticField
    launch('rigid_body_dynamics.nodes.controller', '-p', 'mode:=bdot', '-p',
           'actuator:=magnetorquers', '-p', 'bdot_gain:=100000.0',
           '-p', 'magnetorquer_max_dipole:=[0.2, 0.2, 0.2]', name='ctl')
    answers = probe.subscribe(Vector3Stamped, 'magnetorquer_cmd')

    def reading(t, b):
        msg = MagneticField()
        msg.header.stamp = time_msg(round(t * 1e9))
        msg.magnetic_field = vector_msg(b)
        return msg
    b0, b1 = (2e-5, -1e-5, 3e-5), (2.1e-5, -1.05e-5, 2.9e-5)
    field = probe.publisher(MagneticField, 'magnetic_field')
    probe.handshake(field, reading(0.0, b0), lambda: bool(answers))
    field.publish(reading(1.0, b1))
    field.publish(reading(1.0, b1))
    field.publish(reading(2.0, b1))
    probe.spin_until(lambda: any(t == 2 * 10 ** 9 for t, _ in _answers_by_stamp(answers)),
                     10.0, 'the answer to the reading at 2 s')
    law = BDot(1e5, (0.2, 0.2, 0.2))
    law.dipole(0.0, b0)
    expected = law.dipole(1.0, b1)
    got = [(t, (a.vector.x, a.vector.y, a.vector.z)) for t, a in _answers_by_stamp(answers)
           if t > 0]
    assert got == [(10 ** 9, expected), (10 ** 9, expected), (2 * 10 ** 9, law.dipole(2.0, b1))]
    assert max(map(abs, expected)) > 0.05


@pytest.mark.parametrize('args, reason', [
    (('-p', 'target_orientation:=[0.0, 0.0, 0.0, 0.0]'),
     'target_orientation must not be the zero quaternion'),
    (('-p', 'natural_frequency:=-1.0'), 'natural_frequency'),
    (('-p', 'mode:=spin'), 'mode'),
])
def test_bad_controller_parameters_are_refused_with_the_reason(launch, args, reason):
    proc = launch('rigid_body_dynamics.nodes.controller', *args, name='bad_controller')
    assert proc.wait(30.0) == 1
    assert reason in proc.output() and 'Traceback' not in proc.output()
