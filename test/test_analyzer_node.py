"""
attitude_analyzer over real topics, against the simulator and against test publishers.

Both nodes run as separate processes; the test reads the analyzer's
/diagnostics and its Float64 topics. Every wait has a deadline.
"""

import math
import os
import subprocess
import sys

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rcl_interfaces.srv import SetParametersAtomically
from rclpy.duration import Duration
from rclpy.parameter import Parameter
from rigid_body_dynamics.nodes.analyzer import SampleBuffer
from rigid_body_dynamics.physics import FreeRigidBody, presets
from rigid_body_dynamics.physics.analysis import theory
from rigid_body_dynamics.ros.conversions import vector_msg
from ros_harness import analyzer_heard, odom_msg
from std_msgs.msg import Float64
from std_srvs.srv import Trigger

SIM = 'rigid_body_dynamics.nodes.simulator'
ANALYZER = 'rigid_body_dynamics.nodes.analyzer'


def wait_status(probe, check, predicate, timeout, what):
    """Spin until the newest status ``check`` satisfies ``predicate(values)``; return it."""
    def ok():
        found = probe.newest_status(f'attitude_analyzer: {check}')
        return found is not None and predicate(found[2])
    probe.spin_until(ok, timeout, what)
    return probe.newest_status(f'attitude_analyzer: {check}')


def window_seconds(values):
    """Return the span (s of stamps) of the analysed window, from the input status' values."""
    try:
        last, first = (int(values[f'window {end} stamp (ns)']) for end in ('last', 'first'))
        return (last - first) / 1e9
    except (KeyError, ValueError):
        return 0.0


def wait_window(probe, seconds, timeout, what):
    """Spin until the analyzer's window spans ``seconds`` of stamps (its statuses with it)."""
    return wait_status(probe, 'input', lambda v: window_seconds(v) >= seconds, timeout, what)


def is_number(text):
    """Tell whether a diagnostic value is a number (not 'not available: ...')."""
    try:
        float(text)
    except (TypeError, ValueError):
        return False
    return True


def set_params(probe, **values):
    """Set the analyzer's parameters atomically; returns the SetParametersResult."""
    request = SetParametersAtomically.Request(parameters=[
        Parameter(name, value=value).to_parameter_msg() for name, value in values.items()])
    return probe.call(SetParametersAtomically, '/attitude_analyzer/set_parameters_atomically',
                      request).result


def stop_cleanly(*procs):
    """SIGINT ends every node with exit code 0."""
    for proc in procs:
        code, _ = proc.stop()
        assert code == 0, proc.output()
        assert 'Traceback' not in proc.output()


def test_symmetric_top_precession_and_conservation(launch, probe):
    """Default body: body and lab precession within 1e-12 of theory; conservation OK."""
    sim = launch(SIM, '-p', 'publish_clock:=true', '-p', 'real_time_factor:=4.0', name='sim')
    analyzer = launch(ANALYZER, name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    body_rate = probe.subscribe(Float64, 'precession/body_rate')
    energy = probe.subscribe(Float64, 'kinetic_energy')
    level, message, values = wait_status(
        probe, 'precession', lambda v: 'body rate error (rel.)' in v, 40.0,
        'a precession estimate')
    # let the window fill with a few precession periods (1 rad/s: 6.3 s a period)
    wait_window(probe, 9.9, 40.0, 'a full 10 s window')
    probe.wait_for('precession/body_rate', 1, timeout=20.0)
    probe.wait_for('kinetic_energy', 1, timeout=20.0)
    level, message, values = probe.newest_status('attitude_analyzer: precession')
    # (the estimates agree with theory to round-off: 0 to 4.4e-16 measured)
    assert float(values['body rate error (rel.)']) < 1e-12
    assert float(values['lab rate error (rel.)']) < 1e-12
    assert values['body rate status'] == 'OK' and values['lab rate status'] == 'OK'
    assert float(values['body rate, theory (rad/s)']) == pytest.approx(1.0, rel=1e-12)
    assert body_rate and body_rate[-1].data == pytest.approx(1.0, rel=1e-12)
    assert energy[-1].data == pytest.approx(0.5 * (0.09 + 1.5 * 4.0), rel=1e-12)
    level, message, values = probe.newest_status('attitude_analyzer: conservation')
    assert level == DiagnosticStatus.OK, message
    assert float(values['energy drift since baseline (rel.)']) < 1e-12
    level, message, values = probe.newest_status('attitude_analyzer: stability')
    assert values['class'] == 'stable' and values['nearest principal axis'] == '3'
    # one frequency, one number: the top's wobble is its body precession Omega
    assert float(values['wobble frequency, theory (rad/s)']) == pytest.approx(1.0, rel=1e-12)
    assert float(values['wobble frequency error (rel.)']) < 1e-4
    level, message, values = probe.newest_status('attitude_analyzer: input')
    assert level == DiagnosticStatus.OK and float(values['rate (Hz)']) > 100.0
    assert values['inertia source'] == 'topic'
    stop_cleanly(analyzer, sim)


def test_earth_wobble_period(launch, probe):
    """The Chandler wobble of the earth preset at a million times real time: 300 days +- 0.5 %."""
    sim = launch(SIM, '-p', 'preset:=earth_chandler', '-p', 'publish_clock:=true',
                 '-p', 'publish_rate:=0.0002777777777777778', '-p', 'real_time_factor:=1.0e6',
                 name='sim')
    analyzer = launch(ANALYZER, '-p', 'window:=3.0e6', '-p', 'max_gap:=1.0e5',
                      '-p', 'reset_jump:=1.0e5', name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    level, message, values = wait_status(
        probe, 'precession', lambda v: 'body rate, measured (rad/s)' in v, 60.0,
        'a wobble estimate')
    period_days = 2.0 * math.pi / float(values['body rate, measured (rad/s)']) / \
        theory.SIDEREAL_DAY
    assert period_days == pytest.approx(300.0, rel=0.005)
    stop_cleanly(analyzer, sim)


def test_tennis_racket_is_unstable_with_measured_growth_and_flips(launch, probe):
    body = presets.get('tennis_racket')
    sim = launch(SIM, '-p', 'preset:=tennis_racket', '-p', 'publish_clock:=true',
                 '-p', 'real_time_factor:=8.0', name='sim')
    analyzer = launch(ANALYZER, '-p', 'window:=50.0', name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    level, message, values = wait_status(
        probe, 'stability', lambda v: is_number(v.get('flip interval, measured (s)'))
        and is_number(v.get('growth rate, measured (1/s)')), 60.0, 'measured flips')
    assert values['class'] == 'unstable' and values['nearest principal axis'] == '2'
    assert level == DiagnosticStatus.WARN
    assert float(values['growth rate, measured (1/s)']) == pytest.approx(
        theory.separatrix_growth_rate(body.moments, body.omega0), rel=0.02)
    assert float(values['flip interval, measured (s)']) == pytest.approx(
        theory.flip_interval(body.moments, body.omega0), rel=0.02)
    level, message, values = wait_status(
        probe, 'precession', lambda v: 'omega period error (rel.)' in v, 30.0,
        'a full period of omega in the window')
    assert float(values['omega period error (rel.)']) < 1e-3
    measured = float(values['mean precession of axis 3 about L, measured (rad/s)'])
    assert measured == pytest.approx(
        theory.mean_precession_rate(body.moments, body.omega0, 2), rel=0.02)
    stop_cleanly(analyzer, sim)


def test_torque_pulses_keep_balance_laws_ok(launch, probe):
    sim = launch(SIM, '-p', 'publish_clock:=true', '-p', 'torque_timeout:=0.3', name='sim')
    analyzer = launch(ANALYZER, '-p', 'window:=3.0', name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    energy = probe.subscribe(Float64, 'kinetic_energy')
    wait_status(probe, 'conservation', lambda v: v.get('mode') == 'free motion', 30.0,
                'free-motion conservation')
    probe.wait_for('kinetic_energy', 1, timeout=20.0)   # matched later than /diagnostics, maybe
    e_before = energy[-1].data
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    torque = probe.publisher(WrenchStamped, 'torque_cmd')
    for vec in ((0.3, 0.1, 0.5), (-0.2, 0.3, 0.4)):
        msg = WrenchStamped()
        msg.header.frame_id = 'base_link'
        msg.wrench.torque = vector_msg(vec)
        probe.handshake(torque, msg,
                        lambda: applied and applied[-1].wrench.torque == msg.wrench.torque)
        probe.spin_for(0.6)
    level, message, values = wait_status(
        probe, 'conservation', lambda v: v.get('mode', '').startswith('balance'), 10.0,
        'balance-law mode')
    assert level == DiagnosticStatus.OK, message
    assert float(values['work-energy residual (rel.)']) < 1e-2
    probe.spin_for(1.5)
    assert abs(energy[-1].data / e_before - 1.0) > 0.01          # T really changed
    levels = [st.level for a in probe.messages['/diagnostics'] for st in a.status
              if st.name == 'attitude_analyzer: conservation']
    assert max(levels) == DiagnosticStatus.OK
    # torque gone from the window: back to free-motion drift checks, still OK
    level, message, values = wait_status(
        probe, 'conservation', lambda v: v.get('mode') == 'free motion', 15.0, 'free motion')
    assert level == DiagnosticStatus.OK
    stop_cleanly(analyzer, sim)


def _publish_states(probe, pub, times, body, scale=None):
    """Publish exact top states at ``times`` (s) as odom, optionally scaling omega by scale(t)."""
    q, w = body.state_at(np.asarray(times))
    for k, t in enumerate(times):
        pub.publish(odom_msg(t, q[k], w[k] * (scale(t) if scale else 1.0)))
        if k % 50 == 0:
            probe.spin_for(0.005)


def _odom_publisher(probe, body):
    """Odom publisher, once the analyzer counted a first sample (``body`` at t = 0) from it."""
    pub = probe.publisher(Odometry, 'odom')
    q, w = body.state_at(np.array([0.0]))
    probe.handshake(pub, odom_msg(0.0, q[0], w[0]), lambda: analyzer_heard(probe))
    return pub


def test_broken_physics_turns_conservation_to_error(launch, probe):
    analyzer = launch(ANALYZER, '-p', 'inertia:=[1.0, 1.0, 1.5]', name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    body = FreeRigidBody((1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    pub = _odom_publisher(probe, body)
    # a "simulator" whose energy drifts by 2e-4 per second of stamps, fed second by second
    # until the analyzer (baseline at its first analysis, whenever that is) sees the drift

    def drift_seen():
        found = probe.newest_status('attitude_analyzer: conservation')
        return found is not None and float(
            found[2].get('energy drift since baseline (rel.)', 0.0)) > 1e-4
    for second in range(40):
        _publish_states(probe, pub, np.arange(second, second + 1.0, 0.01), body,
                        scale=lambda t: 1 + 1e-4 * t)
        probe.spin_for(0.3)
        if drift_seen():
            break
    assert drift_seen(), 'the analyzer never reported the energy drift'
    level, message, values = probe.newest_status('attitude_analyzer: conservation')
    assert level == DiagnosticStatus.ERROR, message
    assert 'energy' in message
    stop_cleanly(analyzer)


def test_dropped_duplicated_reordered_and_time_reset(launch, probe, rng):
    analyzer = launch(ANALYZER, '-p', 'inertia:=[1.0, 1.0, 1.5]', '-p', 'window:=5.0',
                      name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    body = FreeRigidBody((1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    pub = _odom_publisher(probe, body)

    def messy(t0, t1):
        t = np.arange(t0, t1, 0.01)
        t = t[rng.uniform(size=t.size) > 0.1]                       # 10 % dropped
        t = np.concatenate([t, rng.choice(t, t.size // 20)])         # 5 % duplicated
        t.sort()
        blocks = [rng.permutation(t[i:i + 5]) for i in range(0, t.size, 5)]
        return np.concatenate(blocks)                                # reordered locally

    _publish_states(probe, pub, messy(0.0, 8.0), body)
    level, message, values = wait_status(
        probe, 'precession', lambda v: 'body rate error (rel.)' in v, 20.0, 'an estimate')
    assert float(values['body rate error (rel.)']) < 1e-9
    assert float(values['lab rate error (rel.)']) < 1e-9
    # the source restarts: stamps go back to 0, with a different body state
    body2 = FreeRigidBody((1.0, 1.0, 1.5), (0.5, 0.0, 1.0))
    _publish_states(probe, pub, messy(0.0, 6.0), body2)
    level, message, values = wait_status(
        probe, 'input', lambda v: int(v.get('restarts after a time reset', 0)) >= 1, 20.0,
        'the reset to be noticed')
    level, message, values = wait_status(
        probe, 'precession', lambda v: is_number(v.get('body rate, theory (rad/s)')) and abs(
            float(v['body rate, theory (rad/s)']) - 0.5) < 1e-9, 20.0,
        'the estimates of the body after the reset')
    assert float(values['body rate, theory (rad/s)']) == pytest.approx(0.5, rel=1e-12)
    assert float(values['body rate error (rel.)']) < 1e-9
    level, message, values = probe.newest_status('attitude_analyzer: conservation')
    assert level == DiagnosticStatus.OK
    # ~/reset_baseline: drift is measured again from a sample after the newest one heard
    before = float(values['baseline stamp (s)'])
    assert before < 1.0
    assert probe.call(Trigger, '/attitude_analyzer/reset_baseline', Trigger.Request()).success
    _publish_states(probe, pub, np.arange(6.0, 8.0, 0.01), body2)
    level, message, values = wait_status(
        probe, 'conservation', lambda v: is_number(v.get('baseline stamp (s)', '')) and
        float(v['baseline stamp (s)']) >= 5.99, 20.0, 'the baseline to move past the reset')
    assert level == DiagnosticStatus.OK
    assert float(values['energy drift since baseline (rel.)']) < 1e-14
    # and the input goes STALE when odom stops (stale_timeout 1 s)
    probe.spin_until(lambda: probe.newest_status('attitude_analyzer: input')[0] ==
                     DiagnosticStatus.STALE, 10.0, 'the input to go stale')
    assert 'no odom for' in probe.newest_status('attitude_analyzer: input')[1]
    stop_cleanly(analyzer)


def test_without_inertia_nothing_is_made_up(launch, probe):
    analyzer = launch(ANALYZER, name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    rates = probe.subscribe(Float64, 'precession/body_rate')
    energy = probe.subscribe(Float64, 'kinetic_energy')
    body = FreeRigidBody((1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    pub = _odom_publisher(probe, body)
    _publish_states(probe, pub, np.arange(0.0, 3.0, 0.01), body)
    probe.spin_for(2.5)
    level, message, values = probe.newest_status('attitude_analyzer: precession')
    assert 'no inertia' in message and level == DiagnosticStatus.WARN
    assert not rates and not energy
    level, message, values = probe.newest_status('attitude_analyzer: input')
    assert values['inertia source'] == 'none'
    # parameters are validated with a reason, then applied
    refused = set_params(probe, inertia=[1.0, 1.0, 3.0])
    assert not refused.successful and 'triangle' in refused.reason
    refused = set_params(probe, window=-1.0)
    assert not refused.successful and 'window' in refused.reason
    assert set_params(probe, inertia=[1.0, 1.0, 1.5]).successful
    _publish_states(probe, pub, np.arange(3.0, 6.0, 0.01), body)
    level, message, values = wait_status(
        probe, 'precession', lambda v: 'body rate error (rel.)' in v, 20.0, 'estimates')
    assert float(values['body rate error (rel.)']) < 1e-9
    assert probe.newest_status('attitude_analyzer: input')[2]['inertia source'] == 'parameter'
    stop_cleanly(analyzer)


def test_bad_parameters_are_refused(launch):
    proc = launch(ANALYZER, '-p', 'inertia:=[1.0, 1.0, 3.0]', name='bad')
    assert proc.wait(20.0) == 1
    assert 'triangle inequality' in proc.output()


def test_drift_is_measured_from_the_first_stamp_whatever_the_arrival(launch, probe):
    """
    A burst of 10 s of stamps, sent within a fraction of the first analysis period.

    The baseline is the first sample by stamp (t = 0), not whatever sample was newest at the
    first analysis: energy drift (1 + 1e-4 t)^2 - 1 = 2.0e-3 at t = 10 s.
    """
    analyzer = launch(ANALYZER, '-p', 'inertia:=[1.0, 1.0, 1.5]', '-p', 'window:=20.0',
                      name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    body = FreeRigidBody((1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    pub = _odom_publisher(probe, body)
    _publish_states(probe, pub, np.arange(0.01, 10.005, 0.01), body,
                    scale=lambda t: 1 + 1e-4 * t)
    level, message, values = wait_status(
        probe, 'conservation', lambda v: float(v.get('energy drift since baseline (rel.)', 0))
        > 1.9e-3, 20.0, 'the drift of the whole burst')
    assert float(values['baseline stamp (s)']) == 0.0
    assert float(values['energy drift since baseline (rel.)']) == pytest.approx(
        (1 + 1e-3) ** 2 - 1, rel=2e-3)
    assert level == DiagnosticStatus.ERROR
    stop_cleanly(analyzer)


def test_twist_frames_are_honoured(launch, probe):
    """
    A twist in the world frame (child_frame_id = header.frame_id) is rotated into the body.

    Twists in a third frame are dropped and counted, never analysed as body rates.
    """
    from geometry_msgs.msg import InertiaStamped
    from ros_harness import LATCHED
    from rigid_body_dynamics.ros.conversions import vector_msg as vec
    from rigid_body_dynamics.physics import quaternions
    analyzer = launch(ANALYZER, name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    inertia = probe.node.create_publisher(InertiaStamped, 'inertia', LATCHED)
    latched = InertiaStamped()
    latched.header.frame_id = 'base_link'
    latched.inertia.ixx, latched.inertia.iyy, latched.inertia.izz = 1.0, 1.0, 1.5
    inertia.publish(latched)
    body = FreeRigidBody((1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    pub = probe.publisher(Odometry, 'odom')

    def world_twist(t, q, w):
        msg = odom_msg(t, q, w)
        msg.child_frame_id = 'odom'
        msg.twist.twist.angular = vec(quaternions.rotate(q, w))
        return msg
    q0, w0 = body.state_at(np.array([0.0]))
    probe.handshake(pub, world_twist(0.0, q0[0], w0[0]), lambda: analyzer_heard(probe))
    times = np.arange(0.01, 6.0, 0.01)
    q, w = body.state_at(times)
    for k, t in enumerate(times):
        pub.publish(world_twist(t, q[k], w[k]))
        if k % 50 == 0:
            probe.spin_for(0.005)
    level, message, values = wait_status(
        probe, 'precession', lambda v: 'body rate error (rel.)' in v, 20.0, 'an estimate')
    assert float(values['body rate, theory (rad/s)']) == pytest.approx(1.0, rel=1e-12)
    assert float(values['body rate error (rel.)']) < 1e-9
    wrong = 30
    for k in range(wrong):
        msg = odom_msg(6.0 + 0.01 * k, q[0], w[0])
        msg.child_frame_id = 'imu_link'
        pub.publish(msg)
    level, message, values = wait_status(
        probe, 'input', lambda v: int(v.get('dropped samples in another frame', 0)) >= wrong,
        20.0, 'the samples in imu_link to be dropped')
    assert int(values['dropped samples in another frame']) == wrong
    assert values['body frame'] == 'base_link'
    stop_cleanly(analyzer)


def test_clearing_the_inertia_parameter_falls_back_to_the_topic(launch, probe):
    """With the inertia parameter unset again (an empty list), the latched topic is used."""
    from geometry_msgs.msg import InertiaStamped
    from ros_harness import LATCHED
    analyzer = launch(ANALYZER, '-p', 'inertia:=[1.0, 1.0, 1.5]', name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    latched = InertiaStamped()
    latched.header.frame_id = 'base_link'
    latched.inertia.ixx, latched.inertia.iyy, latched.inertia.izz = 1.0, 1.0, 2.0
    probe.node.create_publisher(InertiaStamped, 'inertia', LATCHED).publish(latched)
    wait_status(probe, 'input', lambda v: v.get('inertia source') == 'parameter', 20.0,
                'the parameter in use')
    probe.spin_for(1.0)                                  # the topic arrives and is ignored
    assert set_params(probe, inertia=[]).successful          # an empty list unsets it
    level, message, values = wait_status(
        probe, 'input', lambda v: v.get('inertia source') == 'topic', 20.0, 'the topic in use')
    assert values['body frame'] == 'base_link'
    stop_cleanly(analyzer)


def test_intake_takes_every_pending_message_in_order(probe):
    """ros/intake.py: messages wait on the hidden helper node until take() drains them."""
    from rclpy.serialization import deserialize_message
    from rigid_body_dynamics.ros.intake import Intake
    from ros_harness import DEEP
    intake = Intake(probe.node)
    try:
        intake.subscribe(Odometry, 'intake_test', DEEP)
        # a writer deep enough to hold all 200 until the reader acknowledges them
        pub = probe.publisher(Odometry, 'intake_test', qos=DEEP)
        body = FreeRigidBody((1.0, 2.0, 3.0), (0.3, 1.5, -0.4))
        times = np.arange(200) * 0.01
        q, w = body.state_at(times)
        for k, t in enumerate(times):
            pub.publish(odom_msg(t, q[k], w[k]))
        assert pub.wait_for_all_acked(Duration(seconds=20.0))    # all 200 at the reader
        probe.spin_for(0.2)                              # spinning the probe takes nothing
        raws = intake.take('intake_test')
        assert len(raws) == 200 and intake.take('intake_test') == []
        got = [deserialize_message(raw, Odometry) for raw in raws]
        assert [m.header.stamp.nanosec for m in got[:3]] == [0, 10_000_000, 20_000_000]
        assert got[-1].twist.twist.angular.x == w[-1][0]
    finally:
        intake.destroy()


def test_disturbances_keep_the_balance_laws_ok(launch, probe):
    """
    Gravity gradient (a 0.5 rad/s orbit) plus body and world disturbances on a tumbling body.

    applied_torque carries their sum (non-zero, changing as the body turns), T really changes,
    and the analyzer's work-energy and impulse-momentum balances stay OK (residuals < 1e-4).
    """
    sim = launch(SIM, '-p', 'publish_clock:=true', '-p', 'inertia:=[2.0, 3.0, 1.0]',
                 '-p', 'initial_angular_velocity:=[0.3, -0.2, 0.6]',
                 '-p', 'orbit_mu:=1.0', '-p', 'planet_radius:=0.0', '-p', 'gravity_gradient:=true',
                 '-p', f'orbit_elements:=[{0.25 ** (-1 / 3)!r}, 0.0, 0.0, 0.0, 0.0, 0.0]',
                 '-p', 'disturbance_torque_body:=[0.01, 0.0, 0.0]',
                 '-p', 'disturbance_torque_world:=[0.0, 0.0, -0.01]',
                 '-p', 'real_time_factor:=3.0', name='sim')
    # kinetic_energy comes once per diagnostic_period (steady clock): 0.5 s gives the 20
    # values below in about 10 s of wall time, whatever else the machine is running
    analyzer = launch(ANALYZER, '-p', 'window:=4.0', '-p', 'diagnostic_period:=0.5',
                      name='analyzer')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    applied = probe.subscribe(WrenchStamped, 'applied_torque')
    energy = probe.subscribe(Float64, 'kinetic_energy')
    level, message, values = wait_status(
        probe, 'conservation', lambda v: v.get('mode', '').startswith('balance'), 30.0,
        'balance-law mode')
    wait_window(probe, 3.99, 30.0, 'a full window under the disturbances')
    probe.spin_until(lambda: len(applied) > 20 and len(energy) > 20, 60.0,
                     'applied_torque and kinetic_energy')
    level, message, values = probe.newest_status('attitude_analyzer: conservation')
    assert values['mode'].startswith('balance')
    assert level == DiagnosticStatus.OK, message
    # the analyzer's tolerance is 1e-2; measured here about 9e-6 and 5e-6
    assert float(values['work-energy residual (rel.)']) < 1e-4
    assert float(values['impulse-momentum residual (rel.)']) < 1e-4
    # (the state at t = 0 has no step behind it, so its applied_torque is zero by design)
    tau = np.array([[m.wrench.torque.x, m.wrench.torque.y, m.wrench.torque.z] for m in applied
                    if m.header.stamp.sec or m.header.stamp.nanosec])
    assert np.min(np.linalg.norm(tau, axis=1)) > 1e-3 and np.ptp(tau[:, 1]) > 1e-3
    e = np.array([m.data for m in energy])
    assert np.ptp(e) / e[0] > 0.01
    stop_cleanly(analyzer, sim)


def _threads_after(code, env):
    """Run ``code`` in a fresh interpreter; the number of its threads afterwards."""
    script = code + '; import os; print(len(os.listdir("/proc/self/task")))'
    out = subprocess.run([sys.executable, '-c', script], capture_output=True, text=True,
                         env=env, timeout=60, check=True)
    return int(out.stdout.split()[-1])


@pytest.mark.parametrize('module', ['analyzer', 'entry'])
def test_node_processes_run_numpy_on_one_blas_thread_unless_told_otherwise(module):
    """
    Idle OpenBLAS workers spin after each call: the analyzer at 1 kHz paid 12 % for one.

    Both ways a node starts: ``python -m rigid_body_dynamics.nodes.<node>`` and the
    console entry point (which imports the node module, and numpy, after ``entry``).
    """
    env = {k: v for k, v in os.environ.items() if k != 'OPENBLAS_NUM_THREADS'}
    first = f'import os, rigid_body_dynamics.nodes.{module}, numpy'
    ours = _threads_after(f'{first}; assert os.environ["OPENBLAS_NUM_THREADS"] == "1"', env)
    if (os.cpu_count() or 1) > 1:     # numpy first: its OpenBLAS keeps a worker per extra core
        assert _threads_after(f'import numpy, rigid_body_dynamics.nodes.{module}', env) > ours
    _threads_after(f'{first}; assert os.environ["OPENBLAS_NUM_THREADS"] == "2"',
                   dict(env, OPENBLAS_NUM_THREADS='2'))


def test_a_lost_bias_message_leaves_out_its_stamp_not_the_bias_finding():
    """
    Match 10 states, estimates and biases, one estimate's bias lost (best-effort input).

    The attitudes are matched at all 10 stamps and the biases at the other 9; the
    bias finding was dropped altogether for one lost message before.
    """
    buf = SampleBuffer()
    for k in range(10):
        t = k * 10 ** 8
        buf.add(t, (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0), 10 ** 9, 10 ** 9)
        buf.add_estimate(t, (0.0, 0.0, 0.0, 1.0), np.eye(3) * 1e-8)
        buf.add_bias('true', t, (1e-3, 0.0, 0.0))
        if k != 4:
            buf.add_bias('estimate', t, (1e-3 + k * 1e-6, 0.0, 0.0))
    q_true, q_est, cov, bias_true, bias_est = buf.estimate_arrays()
    assert len(q_true) == len(q_est) == len(cov) == 10
    assert bias_true.shape == bias_est.shape == (9, 3)
    assert bias_est[:, 0].tolist() == [1e-3 + k * 1e-6 for k in range(10) if k != 4]
    buf.bias['true'].clear()
    assert buf.estimate_arrays()[3:] == (None, None)
