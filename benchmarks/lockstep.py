"""
Lockstep closed loop: throughput and period, against the floor of two DDS hops.

attitude_simulator (lockstep, 100 Hz control, 1 kHz exact steps, the default body
slewing to 45 degrees about z) with a controller process, 20 s simulated after the first
command. Throughput is simulated seconds per wall second; the period is the wall
time between consecutive control-tick states at a recorder (p50 / p99), the wait the
simulator's own mean wait per tick (diagnostics). The floor is a DDS ping-pong of the same
two messages (Odometry out, WrenchStamped back) between two bare rclpy processes, once with
executor callbacks on both sides and once with wait-set takes (ros/intake.py's calls).
Controllers: the example attitude_controller (wait-set take), and a ten-line executor-callback
controller as a user writes first.
"""

import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'test'))

SIM_TIME = 20.0

#: A ping-pong peer or a plain controller, run as its own process (argv: role).
PEER = r"""
import sys, time
import rclpy
from rclpy.node import Node
from nav_msgs.msg import Odometry
from geometry_msgs.msg import WrenchStamped
from rigid_body_dynamics.ros.intake import Intake
from rclpy.serialization import deserialize_message
role = sys.argv[1]
rclpy.init()
node = Node('peer')
pub = node.create_publisher(WrenchStamped, 'torque_cmd', 10)
def answer(m):
    w = WrenchStamped()
    w.header.stamp = m.header.stamp
    w.wrench.torque.z = -0.1 * m.twist.twist.angular.z
    pub.publish(w)
try:
    if role == 'executor':
        node.create_subscription(Odometry, 'odom', answer, 10)
        rclpy.spin(node)
    else:
        intake = Intake(node)
        intake.subscribe(Odometry, 'odom', 10)
        while True:
            if intake.wait('odom', 0.1):
                for raw in intake.take('odom'):
                    answer(deserialize_message(raw, Odometry))
except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
    pass
"""


def _peer(role):
    return subprocess.Popen([sys.executable, '-c', PEER, role], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)


def ping_pong(role, rounds=3000):
    """Round trip (us, p50 and p99) of Odometry -> WrenchStamped against a ``role`` peer."""
    from geometry_msgs.msg import WrenchStamped
    from nav_msgs.msg import Odometry
    from rclpy.serialization import deserialize_message  # noqa: F401
    from ros_harness import interrupt, Probe
    from rigid_body_dynamics.ros.intake import Intake
    peer = _peer(role)
    probe = Probe('bench_ping')
    try:
        pub = probe.publisher(Odometry, 'odom')
        intake = Intake(probe.node)
        intake.subscribe(WrenchStamped, 'torque_cmd', 10)
        probe.spin_for(1.0)
        times = []
        for k in range(rounds):
            msg = Odometry()
            msg.header.stamp.nanosec = k
            t0 = time.perf_counter()
            pub.publish(msg)
            while not intake.take('torque_cmd'):
                intake.wait('torque_cmd', 1.0)
            times.append(time.perf_counter() - t0)
        intake.destroy()
    finally:
        probe.close()
        interrupt(peer)
    us = np.array(times[200:]) * 1e6
    return np.percentile(us, 50), np.percentile(us, 99)


def closed_loop(controller, hogs=0, extra=()):
    """Lockstep run with ``controller`` ('example' or 'executor'); returns the figures."""
    from diagnostic_msgs.msg import DiagnosticArray
    from nav_msgs.msg import Odometry
    from ros_harness import interrupt, NodeProcess, Probe, status_count
    from rigid_body_dynamics.ros.conversions import time_ns
    sim = NodeProcess('rigid_body_dynamics.nodes.simulator', (
        '-p', 'lockstep:=true', '-p', 'publish_clock:=true',
        '-p', 'qos_overrides./odom.publisher.depth:=10000', *extra), name='bench_lockstep_sim')
    probe = Probe('bench_lockstep')
    arrivals = []
    probe.node.create_subscription(
        Odometry, 'odom', lambda m: arrivals.append((time_ns(m.header.stamp),
                                                     time.perf_counter())),
        __import__('ros_harness').DEEP)
    probe.subscribe(DiagnosticArray, '/diagnostics')
    busy = [subprocess.Popen([sys.executable, '-c', 'while True: pass']) for _ in range(hogs)]
    ctl = None
    try:
        probe.spin_until(lambda: arrivals, 30.0, 'the first state')
        if controller == 'example':
            ctl = NodeProcess('rigid_body_dynamics.nodes.controller', (
                '-p', 'target_orientation:=[0.0, 0.0, 0.3826834, 0.9238795]',
                '-p', 'natural_frequency:=2.0', '-p', 'max_torque:=2.0'), name='bench_ctl')
        else:
            ctl = _peer('executor')
        probe.spin_until(lambda: arrivals[-1][0] > 0, 60.0, 'the first answer')
        probe.spin_until(lambda: arrivals[-1][0] >= SIM_TIME * 1e9, 600.0, f'{SIM_TIME} s')
        probe.spin_for(1.2)
        wait = None
        found = probe.newest_status('attitude_simulator: integrator')
        if found:
            wait = float(found[2].get('mean wait per answered tick (ms)', 'nan'))
        misses = status_count(probe, 'integrator', 'missed ticks')
    finally:
        for b in busy:
            b.kill()
            b.wait()
        if ctl is not None:
            (ctl.stop() if hasattr(ctl, 'stop') else interrupt(ctl))
        sim.stop()
        probe.close()
    ticks = {}
    for stamp, t in arrivals:
        ticks.setdefault(stamp, t)
    stamps = sorted(s for s in ticks if s > 0)
    t = np.array([ticks[s] for s in stamps])
    period = np.diff(t) * 1e3
    throughput = (stamps[-1] - stamps[0]) * 1e-9 / (t[-1] - t[0])
    return throughput, np.percentile(period, 50), np.percentile(period, 99), wait, misses


def measure():
    """Floors, then the closed loops; returns Markdown lines."""
    import tempfile
    os.environ.setdefault('ROS_LOG_DIR', tempfile.mkdtemp(prefix='bench_lockstep_'))
    lines = ['| what | round trip / period p50 (ms) | p99 (ms) | simulated s per wall s at '
             '100 Hz | simulator wait per tick (ms) | missed ticks |', '|---|---|---|---|---|---|']
    for role, label in (('executor', 'floor: DDS ping-pong, executor callbacks'),
                        ('waitset', 'floor: DDS ping-pong, wait-set take')):
        p50, p99 = ping_pong(role)
        lines.append(f'| {label} | {p50 / 1e3:.3f} | {p99 / 1e3:.3f} | '
                     f'{10.0 / (p50 / 1e3):.1f} (if nothing else ran) | | |')
        print(lines[-1], flush=True)
    fast = ('-p', 'integration_rate:=100.0', '-p', 'publish_rate:=100.0')
    for controller, hogs, extra, label in (
            ('example', 0, (), 'lockstep + attitude_controller'),
            ('executor', 0, (), 'lockstep + executor-callback controller'),
            ('example', 2, (), 'lockstep + attitude_controller, 2 CPU hogs'),
            ('example', 0, fast, 'lockstep + attitude_controller, integration_rate 100 Hz'),
            ('example', 0, fast + ('-p', 'publish_imu:=false'),
             'the same, publish_imu false'),
            ('example', 0, ('-p', 'integration_rate:=100.0', '-p', 'publish_rate:=10.0'),
             'integration_rate 100 Hz, publish_rate 10 Hz (odom at every tick)')):
        thr, p50, p99, wait, misses = closed_loop(controller, hogs, extra)
        lines.append(f'| {label} | {p50:.3f} | {p99:.3f} | {thr:.1f} | '
                     f'{"n/a" if wait is None else f"{wait:.3f}"} | {misses} |')
        print(lines[-1], flush=True)
    return lines
