"""
96 asymmetric bodies at the defaults, watched as a user watches them: late steps, CPU, exit.

``attitude_fleet --bodies 96`` (two worker processes on 2 cores), I = (1, 2, 3) kg m^2,
every default (1 kHz steps, 7 state topics and the imu at 100 Hz), beside a checker: a
second process that reads /diagnostics and the odom of four bodies. After every body has
reported and 3 s more, a 10 s window: each body's steps more than 5 ms late (the target is
at most 3 for every body), the CPU of the workers and of the parent as the fleet's own
``attitude_fleet: fleet`` status reports it (and, to check it, from /proc), then SIGINT:
the exit code and the seconds to exit (the target: 0 within 5 s). Three runs.
``./dev bench --only fleet-check`` (about 3 minutes).
"""

import os
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'test'))
from bodies import ASYMMETRIC, integrator_statuses, MISSED  # noqa: E402, I100
from nodes import cpu_seconds, Process, script  # noqa: E402
from rigid_body_dynamics.ros.client import interrupt  # noqa: E402
from rigid_body_dynamics.ros.conversions import status_values  # noqa: E402
from ros_harness import Probe  # noqa: E402

FLEET = [sys.executable, '-m', 'rigid_body_dynamics.nodes.fleet']
BODIES = 96
WINDOW = 10.0
#: The checker: /diagnostics and the odom of four bodies, in a process of its own.
CHECKER = """
import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from nav_msgs.msg import Odometry
rclpy.init()
node = rclpy.create_node('fleet_checker')
node.create_subscription(DiagnosticArray, '/diagnostics', lambda m: None, 100)
for k in (1, 2, 95, 96):
    node.create_subscription(Odometry, f'/body{k}/odom', lambda m: None, 100)
try:
    rclpy.spin(node)
except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
    pass
"""


def fleet_status(probe, since):
    """Return the newest attitude_fleet statuses from ``since`` on: {name: values}."""
    found = {}
    for array in probe.messages['/diagnostics'][since:]:
        for status in array.status:
            if status.name.startswith('attitude_fleet: '):
                found[status.name] = status_values(status)
    return found


def one_run(probe):
    """Run the fleet once; return a Markdown row."""
    diags = probe.messages['/diagnostics']
    diags.clear()
    checker = Process(script(CHECKER))
    fleet = Process(FLEET + ['--bodies', str(BODIES), '--ros-args', *ASYMMETRIC])
    try:
        deadline = time.monotonic() + 120.0
        while len(integrator_statuses(probe)) < BODIES and time.monotonic() < deadline:
            probe.spin_for(0.5)
        if len(integrator_statuses(probe)) < BODIES:
            return f'| only {len(integrator_statuses(probe))} of {BODIES} reported | | | | | |'
        probe.spin_for(3.0)
        first = len(diags)
        c0, t0 = cpu_seconds(fleet.proc.pid), time.monotonic()
        probe.spin_for(WINDOW)
        proc_cpu = (cpu_seconds(fleet.proc.pid) - c0) / (time.monotonic() - t0)
        seen = integrator_statuses(probe, max(first - 1, 0))
        late = [int(v[-1][MISSED]) - int(v[0][MISSED]) for v in seen.values()]
        status = fleet_status(probe, first)
        workers = [status[n]['CPU (cores)'] for n in sorted(status) if 'worker' in n]
        total = status['attitude_fleet: fleet']['CPU of the workers and the parent (cores)']
        start = time.monotonic()
        code = interrupt(fleet.proc, timeout=30.0)
        seconds = time.monotonic() - start
        over = sum(1 for n in late if n > 3)
        return (f'| {max(late)} / {sum(late)} | {over} of {len(late)} | {total} '
                f'({", ".join(workers)}) | {proc_cpu:.2f} | {code} | {seconds:.1f} |')
    finally:
        fleet.close()
        checker.close()


def measure(runs=3):
    """Three runs; Markdown lines."""
    probe = Probe('bench_fleet_check')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    lines = ['| late steps > 5 ms in 10 s (worst body / all) | bodies over 3 | CPU on the '
             "fleet's status, cores (workers) | CPU from /proc (cores) | exit code on SIGINT | "
             'seconds to exit |', '|---|---|---|---|---|---|']
    try:
        for _ in range(runs):
            lines.append(one_run(probe))
            print(lines[-1], flush=True)
    finally:
        probe.close()
    return lines
