"""
Hostile input against the running nodes (issue 6, the CI-sized part).

For each class of bad input the node stays up, keeps publishing, its state
matches a run that never saw the (rejected) input, and the rejection is
counted in its diagnostics.
"""

import math

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from hypothesis import given, HealthCheck, settings, strategies as st
from nav_msgs.msg import Odometry
import numpy as np
from rcl_interfaces.srv import SetParameters
from rclpy.parameter import Parameter
from rigid_body_dynamics.physics import FreeRigidBody
from ros_harness import analyzer_heard, assert_exact, odom_msg, stamp, status_count
from std_srvs.srv import SetBool, Trigger

SIM = 'rigid_body_dynamics.nodes.simulator'
ANALYZER = 'rigid_body_dynamics.nodes.analyzer'
#: The default body: moments (kg m^2) and initial body rate (rad/s).
TOP = ((1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
BAD_VALUES = [math.nan, math.inf, -math.inf]
BAD_FRAMES = ['map', 'x' * 100000, 'base_link ', '/odom', 'ödom', '\t']


@st.composite
def garbage_wrench(draw):
    """Draw a WrenchStamped the simulator must reject: non-finite torque or unknown frame."""
    msg = WrenchStamped()
    torque = [draw(st.floats(allow_nan=True, allow_infinity=True)) for _ in range(3)]
    if draw(st.booleans()):
        torque[draw(st.integers(0, 2))] = draw(st.sampled_from(BAD_VALUES))
        msg.header.frame_id = draw(st.sampled_from(['', 'base_link', 'odom']))
    else:
        torque = [0.0 if not math.isfinite(v) else v for v in torque]
        msg.header.frame_id = draw(st.sampled_from(BAD_FRAMES))
    msg.wrench.torque.x, msg.wrench.torque.y, msg.wrench.torque.z = torque
    return msg


def test_torque_flood_of_garbage_changes_nothing(launch, probe):
    """A flood of rejected torque commands (as fast as Python publishes) plus a parameter storm."""
    proc = launch(SIM, '-p', 'publish_clock:=true', name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.wait_for('odom', 5)
    pub = probe.publisher(WrenchStamped, 'torque_cmd', qos=1000)
    nan = WrenchStamped()
    nan.wrench.torque.x = math.nan
    shaken = probe.handshake(pub, nan, lambda: status_count(
        probe, 'torque command', 'rejected_non_finite') > 0)
    sent = [nan] * shaken

    @settings(max_examples=3000, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(garbage_wrench())
    def flood(msg):
        pub.publish(msg)
        sent.append(msg)
    flood()
    n_before = len(odom)
    # a parameter storm: hundreds of calls, valid and invalid
    client_results = []
    for k in range(100):
        values = [Parameter('torque_timeout', value=0.5 + 0.001 * k),
                  Parameter('publish_rate', value=1e9 if k % 2 else 100.0)]
        request = SetParameters.Request(parameters=[v.to_parameter_msg() for v in values])
        client_results += probe.call(SetParameters, '/attitude_simulator/set_parameters',
                                     request).results
    assert sum(r.successful for r in client_results) == 150      # 1e9 Hz refused 50 times
    assert probe.call(SetBool, '/attitude_simulator/pause', SetBool.Request(data=False)).success
    probe.spin_until(lambda: len(odom) > n_before + 50, 20.0, 'publishing to go on')
    assert_exact(odom, *TOP)
    t = np.array([stamp(m) for m in odom])
    assert np.all(np.diff(t) > 0.0)
    # commands are "latest wins": a flood overflows the subscriber's queue (depth 10) by
    # design, so only the ones that arrived are counted, and none of them was accepted
    probe.spin_for(2.5)
    _, _, values = probe.newest_status('torque command')
    rejected = int(values['rejected_non_finite']) + int(values['rejected_frame'])
    assert 0 < rejected <= len(sent)
    assert values['accepted'] == '0'
    code, _ = proc.stop()
    assert code == 0 and 'Traceback' not in proc.output()


def test_huge_and_denormal_torques_are_clipped_or_taken_exactly(launch, probe):
    proc = launch(SIM, '-p', 'publish_clock:=true', '-p', 'max_torque:=1.0',
                  '-p', 'torque_timeout:=0.0', '-p', 'initial_angular_velocity:=[0,0,2]',
                  name='sim')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    probe.wait_for('applied_torque', 3)
    pub = probe.publisher(WrenchStamped, 'torque_cmd')
    for value in (5e-324, 1e308):                      # a denormal, then far over the limit
        msg = WrenchStamped()
        msg.wrench.torque.z = value
        if value < 1.0:                                # repeated until applied (latest wins)
            probe.handshake(pub, msg, lambda: applied[-1].wrench.torque.z == value)
        else:                                          # matched both ways now: sent once
            pub.publish(msg)
            probe.spin_until(lambda: applied[-1].wrench.torque.z == 1.0, 10.0, 'the clip')
    probe.spin_until(lambda: probe.newest_status('torque command') is not None
                     and probe.newest_status('torque command')[2]['clipped'] == '1', 10.0, 'clip')
    assert proc.proc.poll() is None
    code, _ = proc.stop()
    assert code == 0


def test_services_while_paused_and_reset_storm(launch, probe):
    proc = launch(SIM, '-p', 'publish_clock:=true', name='sim')
    odom = probe.subscribe(Odometry, 'odom')
    probe.wait_for('odom', 3)
    for k in range(20):
        assert probe.call(SetBool, '/attitude_simulator/pause',
                          SetBool.Request(data=k % 3 == 0)).success
        assert probe.call(Trigger, '/attitude_simulator/reset', Trigger.Request()).success
    probe.call(SetBool, '/attitude_simulator/pause', SetBool.Request(data=False))
    n = len(odom)
    probe.spin_until(lambda: len(odom) > n + 20, 10.0, 'motion after the storm')
    last_reset = max(i for i, m in enumerate(odom) if stamp(m) < 1e-6)
    assert_exact(odom[last_reset:], *TOP)
    code, _ = proc.stop()
    assert code == 0


def test_analyzer_survives_hostile_odom(launch, probe):
    analyzer = launch(ANALYZER, '-p', 'inertia:=[1.0, 1.0, 1.5]', name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    pub = probe.publisher(Odometry, 'odom', qos=1000)
    body = FreeRigidBody(*TOP)
    t = np.arange(0.0, 6.0, 0.01)
    q, w = body.state_at(t)
    # the first (good) sample until the analyzer counts it, so the burst is not lost in discovery
    shaken = probe.handshake(pub, odom_msg(t[0], q[0], w[0]), lambda: analyzer_heard(probe))
    rng = np.random.default_rng(3)
    bad = 0
    for k in range(1, t.size):
        qk, wk = q[k].copy(), w[k].copy()
        kind = rng.integers(0, 10)
        if kind == 0:
            qk = qk * 3.0                                   # not unit: normalised, still right
        elif kind == 1:
            wk[rng.integers(0, 3)] = math.nan               # dropped and counted
            bad += 1
        elif kind == 2:
            qk = np.zeros(4)                                # dropped and counted
            bad += 1
        pub.publish(odom_msg(t[k], qk, wk))
        if k % 50 == 0:
            probe.spin_for(0.005)

    def received():
        return int(probe.newest_status('input')[2]['messages received'])
    # from the first handshake sample taken on nothing is lost (reliable, and both queues of
    # 1000 are deeper than the burst); earlier handshake samples may have been
    probe.spin_until(lambda: received() >= t.size, 20.0, 'the analyzer to count the burst')
    assert received() <= t.size - 1 + shaken
    _, _, values = probe.newest_status('input')
    assert int(values['dropped non-finite samples']) == bad > 0
    _, _, values = probe.newest_status('precession')
    assert float(values['body rate error (rel.)']) < 1e-9   # the good samples still agree
    for far in (4e9, 0.0):                                  # a far-future stamp, then the past
        pub.publish(odom_msg(far, (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 1.0)))
        probe.spin_for(1.5)
    _, _, values = probe.newest_status('input')
    assert int(values['restarts after a gap']) >= 1
    assert int(values['restarts after a time reset']) >= 1
    assert analyzer.proc.poll() is None
    code, _ = analyzer.stop()
    assert code == 0 and 'Traceback' not in analyzer.output()
