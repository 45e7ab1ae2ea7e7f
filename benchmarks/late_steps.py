"""
Late steps in one fleet process: where the integration thread was when a body was late.

attitude_fleet ``--processes 1`` with asymmetric bodies at the defaults (I = (1, 2, 3) kg m^2,
1 kHz steps, 7 state topics and the imu at 100 Hz), started through a probe that records,
inside the fleet process, over 10 s after 5 s of warm-up:

- every wake more than 5 ms after its deadline (a missed deadline of the diagnostics), with
  the interval from the deadline to the wake (bodies of one phase group are late together:
  "instants" counts the distinct milliseconds);
- every garbage collection (its generation and duration, ``gc.callbacks``);
- every pass of the integration thread's loop that took more than 1 ms of wall time, with the
  thread's own CPU time in it (``time.thread_time_ns``): wall minus CPU is the time the
  thread was ready and did not run (another thread holding the GIL, or no core for it).

A late wake is put down to a collection when one ran within its interval, else to a pass
off the CPU for more than 2 ms, else to a long pass on the CPU (integrating and publishing
a group of bodies). Each count runs with normal scheduling and with the integration thread
under SCHED_FIFO (``thread_priority``; the probe runs as root here). ``./dev bench --only
late-steps`` (about 3 minutes).
"""

import json
import os
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'test'))
from bodies import ASYMMETRIC  # noqa: E402, I100 (after the path set-up)
from nodes import Process  # noqa: E402

#: The probe: the fleet's main() with recorders around Pace.due, Loop.cycle and the collector.
PROBE = r"""
import gc, json, os, sys, threading, time
from rigid_body_dynamics.engine import loop, pacer

out, warmup, window = sys.argv.pop(1), float(sys.argv.pop(1)), float(sys.argv.pop(1))
if os.environ.get('LATE_STEPS_NO_FREEZE') == '1':   # the fleet as before: nothing frozen
    from rigid_body_dynamics.ros import runner
    runner.settle_heap = lambda: None
clock = time.monotonic_ns
events = {'gc': [], 'late': [], 'long': []}
recording = threading.Event()
started = {}

def on_gc(phase, info):
    if phase == 'start':
        started['gc'] = clock()
    elif recording.is_set():
        events['gc'].append((started.get('gc', clock()), clock(), info['generation']))

gc.callbacks.append(on_gc)
due = pacer.Pace.due

def recorded_due(self, outbox):
    body, missed = self.body, self.missed
    deadline = None
    if self.rtf > 0.0 and not body.paused:
        target = self._target if self._target > body.steps else body.steps + 1
        deadline = self.deadline(target)
    entered = clock()
    result = due(self, outbox)
    if recording.is_set() and self.missed > missed and deadline is not None:
        events['late'].append((deadline, entered))
    return result

pacer.Pace.due = recorded_due
cycle = loop.Loop.cycle

spent = {'due': 0, 'out': 0, 'items': 0}
thread_time = time.thread_time_ns

def recorded_cycle(self):
    start, cpu = clock(), thread_time()
    spent.update(due=0, out=0, items=0)
    wait = cycle(self)
    end = clock()
    if recording.is_set() and end - start > 1_000_000:
        # (start, end, this thread's CPU in the pass, in Pace.due, in publishing, items)
        events['long'].append((start, end, thread_time() - cpu, spent['due'], spent['out'],
                               spent['items']))
    return wait

loop.Loop.cycle = recorded_cycle
due_timed = pacer.Pace.due

def timed_due(self, outbox):
    start = clock()
    try:
        return due_timed(self, outbox)
    finally:
        spent['due'] += clock() - start

pacer.Pace.due = timed_due
member_init = loop.Member.__init__

def timed_member(self, pace, publish, *args, **kwargs):
    def timed_publish(item):
        start = clock()
        try:
            return publish(item)
        finally:
            spent['out'] += clock() - start
            spent['items'] += 1
    member_init(self, pace, timed_publish, *args, **kwargs)

loop.Member.__init__ = timed_member

def record():
    time.sleep(warmup)
    recording.set()
    t0 = clock()
    time.sleep(window)
    recording.clear()
    events['window'] = (t0, clock())
    events['objects'] = len(gc.get_objects())
    events['frozen'] = gc.get_freeze_count()
    start = clock()
    gc.collect()                    # what one full collection costs now (after the window)
    events['full_ms'] = (clock() - start) / 1e6
    with open(out, 'w') as f:
        json.dump(events, f)

threading.Thread(target=record, daemon=True).start()
from rigid_body_dynamics.nodes.fleet import main
sys.argv[0] = 'attitude_fleet'
main()
"""
COUNTS = (48,)
WARMUP, WINDOW = 5.0, 10.0


def _overlaps(a, b, spans):
    """Return the spans (start, end) that overlap [a, b]."""
    return [s for s in spans if s[0] < b and s[1] > a]


def run(n, extra=(), warmup=WARMUP, window=WINDOW, env=None, processes=True):
    """
    Run ``n`` bodies (``extra``: more --ros-args) with the probe; return its events (dict).

    ``env``: the fleet's environment (default: this one's); ``processes`` False for a fleet
    from before ``--processes`` (always one process).
    """
    fd, out = tempfile.mkstemp(suffix='.json')
    os.close(fd)
    os.unlink(out)
    cmd = [sys.executable, '-c', PROBE, out, str(warmup), str(window), '--bodies', str(n),
           *(('--processes', '1') if processes else ()), '--ros-args', *ASYMMETRIC, *extra]
    proc = Process(cmd, env)
    try:
        deadline = time.monotonic() + warmup + window + 60.0 + n
        while not os.path.exists(out) and time.monotonic() < deadline:
            if proc.proc.poll() is not None:
                raise RuntimeError(f'the fleet ended with {proc.proc.returncode}')
            time.sleep(0.5)
        time.sleep(0.5)                      # (the probe's file is written in one go)
        with open(out) as f:
            return json.load(f)
    finally:
        proc.close()
        if os.path.exists(out):
            os.unlink(out)


#: A pass that lost this long off the CPU (wall time minus the thread's CPU time, ns).
OFF_CPU = 2_000_000


def summarise(events):
    """Return a dict of counts and times (ms) from one run's events."""
    late, gcs, passes = events['late'], events['gc'], events['long']
    off = [p for p in passes if (p[1] - p[0]) - p[2] > OFF_CPU]
    long_gcs = [g[:2] for g in gcs if g[1] - g[0] > OFF_CPU]
    by = dict.fromkeys(('gc', 'off', 'busy', 'other'), 0)
    for a, b in late:
        if _overlaps(a, b, long_gcs):
            by['gc'] += 1
        elif _overlaps(a, b, [p[:2] for p in off]):
            by['off'] += 1
        elif _overlaps(a, b, [p[:2] for p in passes]):
            by['busy'] += 1
        else:
            by['other'] += 1
    return {'late': len(late), 'by': by,
            'instants': len({round(a / 1e6) for a, _b in late}),
            'full': sum(1 for g in gcs if g[2] == 2),
            'gc_ms': max(((e - s) / 1e6 for s, e, _g in gcs), default=0.0),
            'passes': len(passes),
            'pass_ms': max(((p[1] - p[0]) / 1e6 for p in passes), default=0.0),
            'cpu_ms': max((p[2] / 1e6 for p in passes), default=0.0),
            'off': len(off),
            'off_ms': max((((p[1] - p[0]) - p[2]) / 1e6 for p in passes), default=0.0),
            'full_after_ms': events['full_ms'], 'objects': events['objects'],
            'frozen': events['frozen']}


#: (label, environment of the probe): the fleet without and with gc.freeze after start-up.
SETUPS = (('without gc.freeze', {'LATE_STEPS_NO_FREEZE': '1'}),
          ('gc.freeze after start-up', {}))


def measure(counts=COUNTS, rounds=2):
    """Each count without and with the frozen start-up heap, alternating; Markdown lines."""
    lines = ['| bodies | start-up heap | late wakes > 5 ms (instants) | in a collection > 2 ms / '
             'in a pass off the CPU > 2 ms / in a long pass on it / other | full collections '
             'in the window (longest collection, ms) | one full collection after it (ms) | '
             'objects tracked (frozen) | passes > 1 ms (longest wall, longest CPU, ms) |',
             '|---|---|---|---|---|---|---|---|']
    for n in counts:
        for _ in range(rounds):
            for label, env in SETUPS:
                s = summarise(run(n, env=dict(os.environ, **env)))
                by = s['by']
                lines.append(
                    f'| {n} | {label} | {s["late"]} ({s["instants"]}) | {by["gc"]} / '
                    f'{by["off"]} / {by["busy"]} / {by["other"]} | {s["full"]} '
                    f'({s["gc_ms"]:.1f}) | {s["full_after_ms"]:.1f} | {s["objects"]} '
                    f'({s["frozen"]}) | {s["passes"]} ({s["pass_ms"]:.1f}, '
                    f'{s["cpu_ms"]:.1f}) |')
                print(lines[-1], flush=True)
    return lines


if __name__ == '__main__':
    print('\n'.join(measure()))
