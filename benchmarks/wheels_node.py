"""
attitude_simulator with reaction wheels: CPU at the defaults, and the highest rate in real time.

The default body (1 kHz steps, 100 Hz publishing, real time) without wheels, with the four
pyramid wheels of ``doc/examples/wheels.yaml`` held at zero motor torque, and with the same
wheels driven (a wheel_cmd publisher at 100 Hz in the same process as the probe); CPU is the
simulator's share of one core over 8 s after 3 s of warm-up, each case twice, alternating,
on the idle machine and beside one CPU-bound process (``while 1: pass``, started and ended by
the benchmark). On this virtual machine a
figure holds for its run: the same code has measured up to three times more on another
day. With wheels every step is a Runge-Kutta step of the gyrostat (order 6 or 8; no exact
torque-free flow to skip
steps on), so the figure is the cost of the gyrostat in a node.

``./dev bench --only wheels-node``.
"""

import os
import statistics

from diagnostic_msgs.msg import DiagnosticArray
from nodes import measure_cpu, Probe, script, sim
from std_msgs.msg import Float64MultiArray

HERE = os.path.dirname(os.path.abspath(__file__))
WHEELS = os.path.join(HERE, '..', 'doc', 'examples', 'wheels.yaml')
ROUNDS = 2
#: The two conditions: the machine idle, and one CPU-bound process beside the node.
CONDITIONS = (('idle', ()), ('beside a CPU-bound process', (script('while 1: pass'),)))


def measure():
    """Return RESULTS.md lines: the simulator's CPU without, with idle and with driven wheels."""
    probe = Probe('bench_wheels')
    probe.subscribe(DiagnosticArray, '/diagnostics')
    pub = probe.node.create_publisher(Float64MultiArray, 'wheel_cmd', 10)
    driving = []
    probe.node.create_timer(0.01, lambda: driving and pub.publish(
        Float64MultiArray(data=[0.01, -0.01, 0.01, -0.01])))
    cases = {'no wheels': (sim(), False),
             'four wheels, motors at 0': (sim() + ['--params-file', WHEELS], False),
             'four wheels, driven at 100 Hz': (sim() + ['--params-file', WHEELS], True)}
    found = {(name, condition): [] for name in cases for condition, _ in CONDITIONS}
    try:
        for _ in range(ROUNDS):
            for condition, companions in CONDITIONS:
                for name, (cmd, drive) in cases.items():
                    driving[:] = [True] if drive else []
                    cpu, diag = measure_cpu(cmd, probe, companions=companions)
                    rtf = float(diag[1]['achieved real-time factor']) if diag else float('nan')
                    found[name, condition].append((cpu, rtf))
                    print(f'{name}, {condition}: {cpu:.3f} of a core, achieved {rtf:.3f}',
                          flush=True)
    finally:
        probe.close()
    lines = ['| simulator | machine | CPU (share of one core, each run) | achieved real-time '
             'factor |', '|---|---|---|---|']
    for (name, condition), runs in found.items():
        lines.append(f'| {name} | {condition} | {", ".join(f"{c:.3f}" for c, _r in runs)} '
                     f'(median {statistics.median(c for c, _r in runs):.3f}) | '
                     f'{", ".join(f"{r:.3f}" for _c, r in runs)} |')
    return lines


if __name__ == '__main__':
    print('\n'.join(measure()))
