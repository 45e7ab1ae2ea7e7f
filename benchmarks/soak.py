"""
Soak: 1e7 integration steps of attitude_simulator with the analyzer watching.

Two runs, both nodes as processes. ``fast``: 1e4 s at 1 kHz as fast as
possible, publishing every 10 ms of simulated time (``./dev bench --only soak``,
about 5 minutes). ``real time``: 1e3 s at 10 kHz integration, real-time factor
1, publishing at 100 Hz, counting missed deadlines (``./dev bench --only
soak-rt``, about 17 minutes; run it on a quiet machine). Every 10 s of wall
time the resident memory of both and their diagnostics are sampled: simulated
steps, the drift of T, |L| and L direction (simulator), missed deadlines and
the latest step's lateness, the analyzer's conservation status.
"""

import os
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'test'))
from nodes import ANALYZER, Process, sim  # noqa: E402, I100 (after the path set-up)
from ros_harness import Probe  # noqa: E402

STEPS = 10_000_000
MISSED = 'missed deadlines (> 5 ms late)'


def rss_mb(pid):
    """Resident memory (MB) of a process, from /proc."""
    with open(f'/proc/{pid}/status') as f:
        for line in f:
            if line.startswith('VmRSS:'):
                return int(line.split()[1]) / 1024.0
    return float('nan')


def measure(steps=STEPS, period=10.0, real_time=False):
    """Run the soak (as fast as possible, or in real time at 10 kHz); returns Markdown lines."""
    probe = Probe('soak')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    if real_time:
        simulator = Process(sim('real_time_factor:=1.0', 'integration_rate:=10000.0',
                                'publish_rate:=100.0'))
    else:
        simulator = Process(sim('real_time_factor:=0.0', 'publish_rate:=100.0'))
    analyzer = Process(ANALYZER + ['-p', 'window:=10.0'])
    rows = []
    start = time.monotonic()
    try:
        done, late_max = 0, 0.0
        while done < steps and time.monotonic() - start < 2400.0:
            probe.spin_for(period)
            sim_status = probe.newest_status('integrator')
            cons = probe.newest_status('conservation')
            if sim_status is None:
                continue
            sim_values, an_values = sim_status[2], (cons[2] if cons else {})
            done = int(sim_values['steps'])
            rows.append((time.monotonic() - start, done, rss_mb(simulator.proc.pid),
                         rss_mb(analyzer.proc.pid),
                         float(sim_values['energy drift since last torque (rel.)']),
                         float(sim_values['|L| drift since last torque (rel.)']),
                         float(sim_values['L direction drift since last torque (rad)']),
                         int(sim_values[MISSED]),
                         float(sim_values['latest step lateness in the last period (ms)']),
                         cons[1] if cons else 'n/a',
                         an_values.get('energy drift since baseline (rel.)', 'n/a')))
            late_max = max(late_max, rows[-1][8])
    finally:
        analyzer.close()
        simulator.close()
        probe.close()
    lines = ['| wall (s) | steps | simulator RSS (MB) | analyzer RSS (MB) | T drift | |L| drift '
             '| L direction (rad) | missed deadlines | lateness (ms) | analyzer conservation '
             '| analyzer T drift |',
             '|---|---|---|---|---|---|---|---|---|---|---|']
    keep = rows if len(rows) <= 12 else rows[::max(1, len(rows) // 10)] + [rows[-1]]
    for r in keep:
        lines.append(f'| {r[0]:.0f} | {r[1]:.3g} | {r[2]:.1f} | {r[3]:.1f} | {r[4]:.1e} | '
                     f'{r[5]:.1e} | {r[6]:.1e} | {r[7]} | {r[8]:.2f} | {r[9]} | {r[10]} |')
    if rows:
        growth = (rows[-1][2] - rows[len(rows) // 4][2], rows[-1][3] - rows[len(rows) // 4][3])
        lines += ['', f'{rows[-1][1]:.3g} steps in {rows[-1][0]:.0f} s of wall time. Memory '
                  f'growth over the last three quarters of the run: simulator '
                  f'{growth[0]:+.1f} MB, analyzer {growth[1]:+.1f} MB. Missed deadlines: '
                  f'{rows[-1][7]}; the latest step was at most {late_max:.2f} ms late.']
    return lines
