"""
Many bodies on one machine: how many run in real time at 1 kHz integration and 100 Hz publishing.

Three ways, all with the defaults of the symmetric top (exact integrator, 7 state topics per
body): one ``attitude_simulator`` process per body (a namespace each), ``attitude_fleet
--processes 1`` (every body in one process, sharing one integration thread), and
``attitude_fleet --processes 2`` (the bodies round-robin over two worker processes, one per
core; the CPU counts the parent and both workers). For each count N the bodies start, run until
every one has reported, and then for a window the CPU of all processes is summed and every
body's diagnostics are read. N runs in real time when every body achieved a real-time factor of
at least 0.99 and at most 2 of its steps were more than 5 ms late in the window (the criterion
of the single-node rate sweep, per body; in one process a single 5 ms stall of the machine
makes every body late at once, so the total counts each stall N times). Each sweep ends after
two failures in a row. ``./dev bench --only bodies`` (about 25 minutes).
"""

import os
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'test'))
from nodes import cpu_seconds, MAX_MISSED, Process, sim  # noqa: E402, I100 (after the path set-up)
from rigid_body_dynamics.ros.conversions import status_values  # noqa: E402
from ros_harness import Probe  # noqa: E402

FLEET = [sys.executable, '-m', 'rigid_body_dynamics.nodes.fleet']
COUNTS = (1, 2, 4, 8, 12, 16, 24, 32, 48, 64)
MISSED = 'missed deadlines (> 5 ms late)'


ONE, TWO = 'attitude_fleet, 1 process', 'attitude_fleet, 2 processes'
WAYS = ('processes', ONE, TWO)


def commands(way, n):
    """Process command lines that run ``n`` bodies ``way``."""
    if way == 'processes':
        return [sim() + ['-r', f'__ns:=/body{k}'] for k in range(1, n + 1)]
    processes = '2' if way == TWO else '1'
    return [FLEET + ['--bodies', str(n), '--processes', processes, '--ros-args']]


def integrator_statuses(probe, since=0):
    """Map each body's node name to its integrator statuses (oldest first) from ``since`` on."""
    found = {}
    for array in probe.messages['/diagnostics'][since:]:
        for status in array.status:
            if status.name.endswith(': integrator'):
                found.setdefault(status.hardware_id, []).append(status_values(status))
    return found


def run_bodies(probe, way, n, window, extra=()):
    """Run ``n`` bodies; returns (CPU in cores, (missed total, worst body), slowest RTF, why)."""
    diags = probe.messages['/diagnostics']
    diags.clear()
    procs = [Process(c + list(extra)) for c in commands(way, n)]
    try:
        deadline = time.monotonic() + 30.0 + 2.0 * n
        while len(integrator_statuses(probe)) < n and time.monotonic() < deadline:
            probe.spin_for(0.5)
        if len(integrator_statuses(probe)) < n:
            return float('nan'), (0, 0), 0.0, f'only {len(integrator_statuses(probe))} reported'
        probe.spin_for(3.0)
        first = len(diags)
        pids = [p.proc.pid for p in procs]
        c0, t0 = sum(cpu_seconds(p) for p in pids), time.monotonic()
        probe.spin_for(window)
        cpu = (sum(cpu_seconds(p) for p in pids) - c0) / (time.monotonic() - t0)
        seen = integrator_statuses(probe, max(first - 1, 0))
        per_body = [int(v[-1][MISSED]) - int(v[0][MISSED]) for v in seen.values()]
        missed = (sum(per_body), max(per_body))
        slowest = min(float(v[-1]['achieved real-time factor']) for v in seen.values())
        return cpu, missed, slowest, '' if len(seen) == n else f'{len(seen)} of {n} reported'
    finally:
        for p in procs:
            p.close()


def measure(window=8.0, counts=COUNTS):
    """Sweep the body count for each way; returns Markdown lines."""
    probe = Probe('bench_bodies')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    lines = ['| way | bodies | CPU (cores) | CPU per body (% of a core) | missed deadlines '
             '(all bodies / worst body) | slowest achieved real-time factor | real time |',
             '|---|---|---|---|---|---|---|']
    best = {}
    try:
        for way in WAYS:
            failures = 0
            for n in counts:
                cpu, missed, slowest, why = run_bodies(probe, way, n, window)
                ok = not why and missed[1] <= MAX_MISSED and slowest >= 0.99
                lines.append(f'| {way} | {n} | {cpu:.2f} | {100 * cpu / n:.1f} | '
                             f'{missed[0]} / {missed[1]} | '
                             f'{slowest:.3f} | {"yes" if ok else "no"}{", " + why if why else ""}'
                             ' |')
                print(lines[-1], flush=True)
                if ok:
                    best[way] = n
                failures = 0 if ok else failures + 1
                if failures == 2:
                    break
    finally:
        probe.close()
    summary = ', '.join(f'{way}: {best.get(way, 0)}' for way in WAYS)
    return lines + ['', f'Most bodies in real time: {summary}.']


#: The asymmetric body a new user tries (three different moments), and what they can switch off.
ASYMMETRIC = ('-p', 'inertia:=[1.0, 2.0, 3.0]', '-p', 'initial_angular_velocity:=[0.3, 1.5, -0.4]')
ODOM_ONLY = ('-p', 'state_topics:=none', '-p', 'publish_imu:=false')
ASYMMETRIC_SETUPS = (
    ('defaults (1 kHz steps, 7 state topics + imu at 100 Hz)', ONE, ()),
    ('defaults (1 kHz steps, 7 state topics + imu at 100 Hz)', TWO, ()),
    ('state_topics none, publish_imu false (odom only, 100 Hz)', ONE, ODOM_ONLY),
    ('state_topics none, publish_imu false (odom only, 100 Hz)', TWO, ODOM_ONLY),
    ('the same, publish_rate 50 Hz', ONE, ODOM_ONLY + ('-p', 'publish_rate:=50.0')),
)


def measure_asymmetric(window=8.0, counts=(32, 48, 64, 96, 128, 160),
                       setups=ASYMMETRIC_SETUPS):
    """
    Fleets of asymmetric bodies: what limits the count, what to switch off.

    Every setup keeps the default 1 kHz integration (torque-free steps between two
    ticks cost one count) and publishes odom of every body; returns Markdown lines.
    """
    probe = Probe('bench_bodies_asymmetric')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    lines = ['| setup | processes | bodies | CPU (cores) | CPU per body (% of a core) | '
             'missed deadlines (all / worst body) | slowest achieved real-time factor | '
             'real time |', '|---|---|---|---|---|---|---|---|']
    best = {}
    try:
        for label, way, extra in setups:
            failures = 0
            for n in counts:
                cpu, missed, slowest, why = run_bodies(probe, way, n, window, ASYMMETRIC + extra)
                ok = not why and missed[1] <= MAX_MISSED and slowest >= 0.99
                lines.append(f'| {label} | {way.split()[-2]} | {n} | {cpu:.2f} | '
                             f'{100 * cpu / n:.1f} | {missed[0]} / {missed[1]} | {slowest:.3f} | '
                             f'{"yes" if ok else "no"}{", " + why if why else ""} |')
                print(lines[-1], flush=True)
                if ok:
                    best[label, way] = max(n, best.get((label, way), 0))
                failures = 0 if ok else failures + 1
                if failures == 2:
                    break
    finally:
        probe.close()
    summary = '; '.join(f'{label}, {way.split(", ")[-1]}: {best.get((label, way), 0)}'
                        for label, way, _ in setups)
    return lines + ['', f'Most asymmetric bodies in real time: {summary}.']
