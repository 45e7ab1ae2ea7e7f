"""
The command path in the engine, A/B: the code of a git revision against the working tree.

Per-step wall time of an asymmetric body (I = 1, 2, 3 kg m^2, the exact integrator
at 1 kHz, publishing every 10 steps) paced on a fake clock woken every 10 ms, so
the time is the engine's own (no DDS): (hold) a body torque held, no new command;
(flood) 10 new torque commands every ms, checked and held as they arrive;
(lockstep) 10 steps per control tick, one stamped command per tick. Each case runs
in a fresh interpreter per revision, alternating A and B, and the median of the
rounds is kept. ``python benchmarks/command_path.py [REV]`` (default REV: the
commit before the one command path, 68c4864); ``./dev bench --only command-path``.
"""

import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
#: The last revision with the old command path (closures built by the node).
BEFORE = '68c4864'
ROUNDS = 5
STEPS = 20_000

#: Run in a fresh interpreter with the revision's package first on sys.path; prints us/step.
CASE = r"""
import sys, time
import numpy as np
from rigid_body_dynamics.engine import BodySimulation, Pace, Lockstep
from rigid_body_dynamics.physics import Inertia
new = hasattr(Pace, '_hold_until')
if new:
    from rigid_body_dynamics.engine import TorqueCommands
case, steps = sys.argv[1], int(sys.argv[2])
class Clock:
    ns = 10 ** 12
    def __call__(self):
        return self.ns
clock = Clock()
body = BodySimulation(Inertia((1.0, 2.0, 3.0)), 'exact', 1000.0,
                      ((0.0, 0.0, 0.0, 1.0), (0.3, 1.5, -0.4)), torque_timeout=0.0,
                      publish_every=10)
rng = np.random.default_rng(1)
pending = []          # (receive ns, vector) of the flood

def inbox():
    came = [p for p in pending if p[0] <= clock.ns]
    del pending[:len(came)]
    return [TorqueCommands([c[0] for c in came], [c[1] for c in came])] if came else []

def take():
    came = [p for p in pending if p[0] <= clock.ns]
    del pending[:len(came)]
    if not came:
        return None
    batch = body.batch([c[1] for c in came], False)
    return [c[0] for c in came], batch.apply

outbox = []
if case == 'lockstep':
    pace = Lockstep(body, 10, 0.0, clock=clock)
    def answer():
        stamp = body.stamp_now()
        v = tuple(rng.normal(scale=0.01, size=3))
        if new:
            pace.mailbox.put(TorqueCommands.one(v, False, clock.ns, stamp_ns=stamp))
        else:
            pace.command(v, False, clock.ns, stamp)
    answer()
    pace.due(outbox)
    start = time.perf_counter()
    while body.steps < steps:
        answer()
        pace.due(outbox)
        outbox.clear()
else:
    kwargs = {'inbox': inbox} if new else {'take_commands': take}
    pace = Pace(body, 1.0, clock=clock, **kwargs)
    body.command((0.01, -0.02, 0.005), False, clock.ns)
    pace.begin()
    start = time.perf_counter()
    while body.steps < steps:
        if case == 'flood':
            base = clock.ns
            pending.extend((base + k * 100_000, tuple(v))
                           for k, v in enumerate(rng.normal(scale=0.01, size=(100, 3))))
        clock.ns += 10_000_000
        pace.due(outbox)
        outbox.clear()
import rigid_body_dynamics
print(rigid_body_dynamics.__file__, (time.perf_counter() - start) / body.steps * 1e6)
"""


def _tree(rev):
    """Check ``rev`` out into a temporary folder (git worktree); returns its path."""
    path = tempfile.mkdtemp(prefix='rbd-ab-')
    subprocess.run(['git', '-C', ROOT, 'worktree', 'add', '--detach', '-f', path, rev],
                   check=True, capture_output=True)
    return path


def _run(tree, case):
    env = dict(os.environ, PYTHONPATH=tree)
    out = subprocess.run([sys.executable, '-c', CASE, case, str(STEPS)], env=env, cwd=tree,
                         check=True, capture_output=True, text=True, timeout=300)
    where, per_step = out.stdout.split()[-2:]
    if not where.startswith(tree):
        raise RuntimeError(f'{case}: imported {where}, not the tree {tree}')
    return float(per_step)


def measure(before=BEFORE):
    """Return RESULTS.md lines: median us per step of each case, before and after."""
    old = _tree(before)
    try:
        rows = []
        for case in ('hold', 'flood', 'lockstep'):
            a, b = [], []
            for _ in range(ROUNDS):
                a.append(_run(old, case))
                b.append(_run(ROOT, case))
            ma, mb = statistics.median(a), statistics.median(b)
            rows.append(f'| {case} | {ma:.2f} ({min(a):.2f}-{max(a):.2f}) | '
                        f'{mb:.2f} ({min(b):.2f}-{max(b):.2f}) | {mb / ma:.3f} |')
            print(rows[-1], flush=True)
    finally:
        subprocess.run(['git', '-C', ROOT, 'worktree', 'remove', '--force', old],
                       capture_output=True)
    return [f'us per step, median of {ROUNDS} alternating runs of {STEPS} steps (range): '
            f'{before} (the node built closures) against the working tree (one command path).',
            '', '| case | before | after | after / before |', '|---|---|---|---|'] + rows


if __name__ == '__main__':
    print('\n'.join(measure(*sys.argv[1:2])))
