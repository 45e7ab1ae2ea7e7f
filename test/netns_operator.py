"""
The operator's side of the several-hosts test and benchmark, run on a host of its own.

Waits for the analyzer's precession estimate and conservation status (the
analyzer on one host working from the odom of a simulator on another), counts
the odom messages arriving over a few seconds, then sends ``--rounds`` torque
commands and times each one until the simulator's applied_torque carries it
(a round trip: operator -> simulator -> operator). Prints one JSON object on
stdout: the analyzer's statuses, the odom rate and the round-trip times (s).
With ``--fleet a,b,...`` it checks the bodies of a fleet split over hosts instead:
each body's odom against the exact free motion of the default preset, and its pause
service.

``python test/netns_operator.py [--rounds N] [--period S] [--timeout S] [--fleet a,b]``
"""

import argparse
import json
import math

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import InertiaStamped
from nav_msgs.msg import Odometry
from rigid_body_dynamics.physics import presets
from rigid_body_dynamics.ros.conversions import time_ns
from ros_harness import command_round_trips, exact_errors, LATCHED, Probe, relative
from std_srvs.srv import SetBool


def analyzer_statuses(probe, timeout):
    """Wait for a precession estimate and every check; return {check: (level, message, values)}."""
    checks = ('precession', 'conservation', 'stability', 'input')

    def ready():
        found = probe.newest_status('attitude_analyzer: precession')
        rate = (probe.newest_status('attitude_analyzer: input') or (0, '', {}))[2].get('rate (Hz)')
        return found is not None and 'body rate error (rel.)' in found[2] and all(
            probe.newest_status(f'attitude_analyzer: {check}') for check in checks) and \
            rate is not None and math.isfinite(float(rate))
    probe.spin_until(ready, timeout, "the analyzer's precession estimate, input rate and checks")
    out = {}
    for check in checks:
        level, message, values = probe.newest_status(f'attitude_analyzer: {check}')
        out[check] = (ord(level), message, values)   # level: one byte, 0 = OK
    return out


def odom_rate(probe, seconds=3.0):
    """Odom messages per second arriving here."""
    before = len(probe.messages['odom'])
    probe.spin_for(seconds)
    return (len(probe.messages['odom']) - before) / seconds


def fleet_report(probe, names, timeout):
    """
    For each body of a fleet: 20 odom messages against the exact motion, and its pause.

    Returns {name: [attitude error (rad), rate error (rad/s), pause answered]}.
    """
    top = presets.get('symmetric_top')
    odom = {n: probe.subscribe(Odometry, f'/{n}/odom') for n in names}
    inertia = {n: probe.subscribe(InertiaStamped, f'/{n}/inertia', LATCHED) for n in names}
    out = {}
    for name in names:
        probe.wait_for(f'/{name}/odom', 20, timeout)
        probe.wait_for(f'/{name}/inertia', 1, timeout)
        start = time_ns(inertia[name][0].header.stamp)
        errors = exact_errors(relative(odom[name], start), top.moments, top.omega0, top.q0)
        answer = probe.call(SetBool, f'/{name}/attitude_simulator/pause',
                            SetBool.Request(data=True), timeout=timeout)
        out[name] = [*errors, bool(answer.success)]
    return out


def main():
    """Measure and print the JSON report."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[1])
    parser.add_argument('--rounds', type=int, default=50)
    parser.add_argument('--period', type=float, default=0.05)
    parser.add_argument('--timeout', type=float, default=60.0)
    parser.add_argument('--skip-analyzer', action='store_true',
                        help='only the odom rate and the round trips')
    parser.add_argument('--fleet', default='', help="check these fleet bodies' odom and pause")
    args = parser.parse_args()
    probe = Probe('operator')
    if args.fleet:
        try:
            print(json.dumps(fleet_report(probe, args.fleet.split(','), args.timeout)))
        finally:
            probe.close()
        return
    try:
        probe.subscribe(DiagnosticArray, '/diagnostics')
        probe.subscribe(Odometry, 'odom')
        report = {}
        if not args.skip_analyzer:
            report['analyzer'] = analyzer_statuses(probe, args.timeout)
        else:
            probe.wait_for('odom', 10, args.timeout)
        report['odom_rate'] = odom_rate(probe)
        report['round_trips'] = command_round_trips(probe, args.rounds, args.period)
        report['rounds'] = args.rounds
    finally:
        probe.close()
    print(json.dumps(report))


if __name__ == '__main__':
    main()
