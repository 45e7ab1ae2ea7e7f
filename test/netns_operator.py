"""
The operator's side of the several-hosts test and benchmark, run on a host of its own.

Waits for the analyzer's precession estimate and conservation status (the
analyzer on one host working from the odom of a simulator on another), counts
the odom messages arriving over a few seconds, then sends ``--rounds`` torque
commands and times each one until the simulator's applied_torque carries it
(a round trip: operator -> simulator -> operator). Prints one JSON object on
stdout: the analyzer's statuses, the odom rate and the round-trip times (s).

``python test/netns_operator.py [--rounds N] [--period S] [--timeout S]``
"""

import argparse
import json
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
from rclpy.qos import QoSProfile, ReliabilityPolicy
from ros_harness import Probe

#: Torque per round-trip number (N m): small enough to leave the motion nearly free.
TORQUE_UNIT = 1e-9


def analyzer_statuses(probe, timeout):
    """Wait for a precession estimate; return {check: (level as int, message, values)}."""
    def ready():
        found = probe.newest_status('attitude_analyzer: precession')
        return found is not None and 'body rate error (rel.)' in found[2]
    probe.spin_until(ready, timeout, "the analyzer's precession estimate")
    probe.spin_for(2.0)
    out = {}
    for check in ('precession', 'conservation', 'stability', 'input'):
        level, message, values = probe.newest_status(f'attitude_analyzer: {check}')
        out[check] = (ord(level), message, values)   # level: one byte, 0 = OK
    return out


def odom_rate(probe, seconds=3.0):
    """Odom messages per second arriving here."""
    before = len(probe.messages['odom'])
    probe.spin_for(seconds)
    return (len(probe.messages['odom']) - before) / seconds


def round_trips(probe, rounds, period):
    """Seconds from publishing torque_cmd k to receiving applied_torque carrying it."""
    arrivals = {}

    def on_applied(msg):
        key = 'hello' if msg.wrench.torque.y else round(msg.wrench.torque.x / TORQUE_UNIT)
        arrivals.setdefault(key, time.monotonic())
    probe.node.create_subscription(WrenchStamped, 'applied_torque', on_applied,
                                   QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE))
    pub = probe.publisher(WrenchStamped, 'torque_cmd')
    hello = WrenchStamped()                            # until it comes back: matched both ways
    hello.wrench.torque.y = TORQUE_UNIT
    probe.handshake(pub, hello, lambda: 'hello' in arrivals)
    sent = {}
    for k in range(1, rounds + 1):
        msg = WrenchStamped()
        msg.wrench.torque.x = k * TORQUE_UNIT
        sent[k] = time.monotonic()
        pub.publish(msg)
        probe.spin_for(period)
    probe.spin_for(0.5)
    return [arrivals[k] - sent[k] for k in sent if k in arrivals]


def main():
    """Measure and print the JSON report."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[1])
    parser.add_argument('--rounds', type=int, default=50)
    parser.add_argument('--period', type=float, default=0.05)
    parser.add_argument('--timeout', type=float, default=60.0)
    parser.add_argument('--skip-analyzer', action='store_true',
                        help='only the odom rate and the round trips')
    args = parser.parse_args()
    probe = Probe('operator')
    try:
        probe.subscribe(DiagnosticArray, '/diagnostics')
        probe.subscribe(Odometry, 'odom')
        report = {}
        if not args.skip_analyzer:
            report['analyzer'] = analyzer_statuses(probe, args.timeout)
        else:
            probe.wait_for('odom', 10, args.timeout)
        report['odom_rate'] = odom_rate(probe)
        report['round_trips'] = round_trips(probe, args.rounds, args.period)
        report['rounds'] = args.rounds
    finally:
        probe.close()
    print(json.dumps(report))


if __name__ == '__main__':
    main()
