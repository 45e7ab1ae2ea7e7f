"""
The exact asymmetric flow one time at a time against numpy over many times.

The case of the fleet benchmarks: I = (1, 2, 3) kg m^2, omega0 = (0.3, 1.5, -0.4) rad/s, one
torque-free segment. Per state, least of five runs: ``FreeFlow.state`` at one float time (the
scalar path with math and scipy's special functions on floats), and at an array of N times in
one call (the numpy path; N states of one body, as the ``exact`` stepper evaluates ahead, cost
the same as one state of N bodies with the same formulas on arrays of parameters, since every
term is elementwise). The fixed cost of a numpy call decides where batching pays: over the 16
bodies of one phase of a fleet it would not; over the next 64 reads of one body it does.
``./dev bench --only flow-batch`` (seconds).
"""

import time

import numpy as np
from rigid_body_dynamics.physics.dynamics.free_motion import BodyShape


def _least(run, repeat, rounds=5):
    """Least time per call (us) of ``run()`` repeated ``repeat`` times, over ``rounds``."""
    best = float('inf')
    for _ in range(rounds):
        t0 = time.perf_counter()
        for _ in range(repeat):
            run()
        best = min(best, (time.perf_counter() - t0) / repeat)
    return best * 1e6


def measure():
    """Markdown lines of the table."""
    moments = (1.0, 2.0, 3.0)
    m0 = tuple(i * w for i, w in zip(moments, (0.3, 1.5, -0.4)))
    flow = BodyShape(moments).flow((0.0, 0.0, 0.0, 1.0), m0)
    scalar = _least(lambda: flow.state(0.37), 3000)
    lines = ['| evaluation | states per call | us per call | us per state | '
             'against one at a time |', '|---|---|---|---|---|',
             f'| one float time | 1 | {scalar:.1f} | {scalar:.1f} | 1.0x |']
    for n in (1, 4, 16, 64, 96, 256, 1024):
        times = 0.01 * np.arange(1, n + 1)
        call = _least(lambda: flow.state(times), max(20, 3000 // n))
        lines.append(f'| numpy, array of times | {n} | {call:.1f} | {call / n:.2f} | '
                     f'{scalar / (call / n):.1f}x |')
    return lines
