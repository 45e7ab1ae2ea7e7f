"""
Torque-command flood: 10 kHz for 10 s at attitude_simulator (defaults: 1 kHz, 100 Hz, real time).

A separate flooder process publishes torque_cmd in bursts of 10 every
millisecond (10 kHz on average) for 10 s: valid body torques of 1e-6 N m,
non-finite torques, or an unknown frame_id. Measured during the flood: the
rate actually sent, the commands the simulator took (accepted + rejected
counters in its diagnostics), its achieved real-time factor and missed
deadlines, odom received by a subscriber, the simulator's CPU; for the
rejected classes also the largest deviation of the published state from the
exact free motion (the run that never saw the flood). The floor: the same
valid flood into a bare rclpy process that only takes every pending message
(serialised, with its receive time, as the simulator does) every 10 ms and
counts them, with the simulator's QoS: what receiving the flood costs any
Python node that sees every command. ``./dev bench --only flood`` (about 2
minutes).
"""

import os
import sys
import textwrap
import time

from diagnostic_msgs.msg import DiagnosticArray
from nav_msgs.msg import Odometry

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'test'))
from nodes import cpu_seconds, Process, script, sim  # noqa: E402, I100 (after the path set-up)
from rigid_body_dynamics.physics import presets  # noqa: E402
from ros_harness import exact_errors, Probe  # noqa: E402

RATE = 10_000
SECONDS = 10.0
FLOODER = textwrap.dedent("""
    import math, sys, time
    import rclpy
    from geometry_msgs.msg import WrenchStamped
    kind, rate, seconds = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
    rclpy.init()
    node = rclpy.create_node('flooder')
    pub = node.create_publisher(WrenchStamped, 'torque_cmd', 10)
    end = time.monotonic() + 20.0
    while pub.get_subscription_count() < 1 and time.monotonic() < end:
        time.sleep(0.05)
    time.sleep(1.0)
    msg = WrenchStamped()
    if kind == 'non-finite torque':
        msg.wrench.torque.x = math.nan
    elif kind == 'unknown frame_id':
        msg.header.frame_id = 'map'
    else:
        msg.wrench.torque.x = 1e-6
    burst, n = 10, int(rate * seconds)
    period = burst / rate
    start = time.perf_counter()
    sent = 0
    print('start', flush=True)
    while sent < n:
        wait = start + (sent // burst) * period - time.perf_counter()
        if wait > 0:
            time.sleep(wait)
        for _ in range(burst):
            pub.publish(msg)
        sent += burst
    print('sent', sent, time.perf_counter() - start, flush=True)
    node.destroy_node()
    rclpy.shutdown()
""")
FLOOR = textwrap.dedent("""
    import signal, sys, threading
    import rclpy
    from geometry_msgs.msg import WrenchStamped
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
    rclpy.init()
    node = rclpy.create_node('attitude_simulator')
    qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                     reliability=ReliabilityPolicy.RELIABLE)
    sub = node.create_subscription(WrenchStamped, 'torque_cmd', lambda _m: None, qos, raw=True)
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    taken = 0
    while not stop.wait(0.01):
        with sub.handle:
            while True:
                got = sub.handle.take_message(sub.msg_type, True)
                if got is None:
                    break
                got[1]['received_timestamp']
                taken += 1
    print('taken', taken, flush=True)
""")
KINDS = ('valid body torque', 'non-finite torque', 'unknown frame_id')
COUNTERS = ('accepted', 'rejected_non_finite', 'rejected_frame')


def start_flooder(probe, kind):
    """Start the flooder process with ``kind`` of commands; return it once it floods."""
    flooder = Process(script(FLOODER) + [kind, str(RATE), str(SECONDS)])

    def started():
        flooder.log.seek(0)
        return b'start' in flooder.log.read()
    try:
        probe.spin_until(started, 40.0, 'the flooder')
    except BaseException:
        flooder.close()
        raise
    return flooder


def sent_by(flooder):
    """(commands sent, seconds it took) from a finished flooder's log."""
    flooder.log.seek(0)
    line = [ln for ln in flooder.log.read().decode().splitlines() if ln.startswith('sent')][-1]
    return int(line.split()[1]), float(line.split()[2])


def flood(probe, kind):
    """One flood; returns a row of measurements."""
    probe.messages['/diagnostics'].clear()
    odom = probe.messages['odom']
    odom.clear()
    simulator = Process(sim('publish_clock:=true'))
    flooder = None
    try:
        probe.spin_until(lambda: probe.newest_status('torque command') is not None, 40.0,
                         "the simulator's diagnostics")
        # the previous run's simulator (same node name) may have had diagnostics in flight when
        # it stopped: forget everything so far, and read only what this simulator sends now
        probe.spin_for(1.5)
        probe.messages['/diagnostics'].clear()
        probe.spin_until(lambda: probe.newest_status('torque command') is not None, 10.0,
                         "the simulator's diagnostics")
        flooder = start_flooder(probe, kind)
        before = probe.newest_status('torque command')
        integ0 = probe.newest_status('integrator')
        n0 = len(odom)
        c0, t0 = cpu_seconds(simulator.proc.pid), time.monotonic()
        probe.spin_until(lambda: flooder.proc.poll() is not None, SECONDS + 30.0, 'the flood')
        cpu = (cpu_seconds(simulator.proc.pid) - c0) / (time.monotonic() - t0)
        odom_rate = (len(odom) - n0) / (time.monotonic() - t0)
        probe.spin_for(2.5)
        after = probe.newest_status('torque command')
        integ1 = probe.newest_status('integrator')
        sent, elapsed = sent_by(flooder)
        took = sum(int(after[2][c]) - int(before[2][c]) for c in COUNTERS)
        missed_key = next(k for k in integ1[2] if k.startswith('missed deadlines'))
        missed = int(integ1[2][missed_key]) - int(integ0[2][missed_key])
        achieved = float(integ1[2]['achieved real-time factor'])
        body = presets.get(presets.DEFAULT)
        error = (exact_errors(odom[n0:], body.moments, body.omega0, body.q0)
                 if kind != 'valid body torque' else None)
        alive = simulator.proc.poll() is None
    finally:
        if flooder is not None:
            flooder.close()
        simulator.close()
    return (kind, sent / elapsed, took, took / sent, missed, achieved, odom_rate, cpu, error,
            alive)


def floor(probe):
    """Flood the bare taking process with valid commands; (CPU fraction, fraction taken)."""
    taker = Process(script(FLOOR))
    flooder = None
    try:
        probe.spin_for(3.0)
        flooder = start_flooder(probe, KINDS[0])
        c0, t0 = cpu_seconds(taker.proc.pid), time.monotonic()
        probe.spin_until(lambda: flooder.proc.poll() is not None, SECONDS + 30.0, 'the flood')
        cpu = (cpu_seconds(taker.proc.pid) - c0) / (time.monotonic() - t0)
        probe.spin_for(0.5)
    finally:
        if flooder is not None:
            flooder.close()
        taker.close()
    sent = sent_by(flooder)[0]
    taker.log.seek(0)
    took = [ln for ln in taker.log.read().decode().splitlines() if ln.startswith('taken')]
    return cpu, (int(took[-1].split()[1]) / sent if took else float('nan'))


def measure():
    """All flood classes; returns Markdown lines."""
    probe = Probe('bench_flood')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    probe.subscribe(Odometry, 'odom')
    lines = ['| flood | sent (Hz) | commands taken by the simulator | fraction taken | '
             'missed deadlines | achieved real-time factor | odom received (Hz) | simulator '
             'CPU (% of a core) | state vs exact free motion (rad, rad/s) | still up |',
             '|---|---|---|---|---|---|---|---|---|---|']
    try:
        for kind in KINDS:
            r = flood(probe, kind)
            error = 'n/a (torque applied)' if r[8] is None else f'{r[8][0]:.1e}, {r[8][1]:.1e}'
            lines.append(f'| {r[0]} | {r[1]:.0f} | {r[2]} | {r[3]:.2f} | {r[4]} | {r[5]:.3f} | '
                         f'{r[6]:.0f} | {100 * r[7]:.0f} | {error} | {"yes" if r[9] else "no"} |')
            print(lines[-1], flush=True)
        cpu, taken = floor(probe)
        lines.append(f'| floor: bare rclpy process taking the valid flood every 10 ms | | | '
                     f'{taken:.2f} | | | | {100 * cpu:.0f} | | |')
        print(lines[-1], flush=True)
    finally:
        probe.close()
    return lines + ['', 'The simulator wakes at its ticks (here every 10 ms), takes every '
                    'pending command with its receive time (a subscriber queue of 1000, one '
                    'batch decoded and checked at once) and applies each from the step during '
                    'which it came; every command taken is counted as accepted or rejected.']
