"""
Late steps in one fleet process: what the integration thread was waiting for.

attitude_fleet ``--processes 1`` with asymmetric bodies at the defaults (1 kHz steps, 7 state
topics and the imu at 100 Hz), started through a probe that records, inside the fleet
process, for a window after 5 s of warm-up:

- every wake more than 5 ms after its deadline (a missed deadline of the diagnostics), with
  the interval from the deadline to the wake;
- every garbage collection (its generation and duration, ``gc.callbacks``);
- every pass of the integration thread's loop that took more than 1 ms, and every sleep that
  ended more than 1 ms after it was meant to (the thread wanted to run and could not: the
  GIL held by another thread, or no core).

A late wake is put down to a collection when one ran within its interval, else to a long
pass, else to a late sleep. ``./dev bench --only late-steps`` (about 3 minutes).
"""

import json
import os
import statistics
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
before = os.environ.get('LATE_STEPS_BEFORE') == '1'
if before:                                   # the fleet as it was: no settling of the heap
    from rigid_body_dynamics.ros import runner
    runner.settle_heap = lambda: None
clock = time.monotonic_ns
events = {'gc': [], 'late': [], 'long': [], 'oversleep': []}
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
last = {}

def recorded_cycle(self):
    start = clock()
    if 'until' in last and recording.is_set() and start - last['until'] > 1_000_000:
        events['oversleep'].append((last['until'], start))
    wait = cycle(self)
    end = clock()
    if recording.is_set() and end - start > 1_000_000:
        events['long'].append((start, end))
    last['until'] = end + int(wait * 1e9) if wait > 0.0 else end
    return wait

loop.Loop.cycle = recorded_cycle

def record():
    time.sleep(warmup)
    recording.set()
    t0 = clock()
    time.sleep(window)
    recording.clear()
    events['window'] = (t0, clock())
    events['objects'] = len(gc.get_objects())
    events['frozen'] = gc.get_freeze_count()
    with open(out, 'w') as f:
        json.dump(events, f)

threading.Thread(target=record, daemon=True).start()
from rigid_body_dynamics.nodes.fleet import main
sys.argv[0] = 'attitude_fleet'
main()
"""
COUNTS = (48, 64)
WARMUP, WINDOW = 5.0, 10.0


def _overlaps(a, b, spans):
    """Return the spans (start, end) that overlap [a, b]."""
    return [s for s in spans if s[0] < b and s[1] > a]


def run(n, before, warmup=WARMUP, window=WINDOW):
    """Run ``n`` bodies with the probe; return its events (dict), or raise RuntimeError."""
    fd, out = tempfile.mkstemp(suffix='.json')
    os.close(fd)
    os.unlink(out)
    env = dict(os.environ, LATE_STEPS_BEFORE='1' if before else '0')
    cmd = [sys.executable, '-c', PROBE, out, str(warmup), str(window), '--bodies', str(n),
           '--processes', '1', '--ros-args', *ASYMMETRIC]
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


def summarise(events):
    """Return a dict of counts and times (ms) from one run's events."""
    late, gcs = events['late'], events['gc']
    by_gc = by_long = by_sleep = 0
    for a, b in late:
        if _overlaps(a, b, gcs):
            by_gc += 1
        elif _overlaps(a, b, events['long']):
            by_long += 1
        elif _overlaps(a, b, events['oversleep']):
            by_sleep += 1
    full = [(e - s) / 1e6 for s, e, g in gcs if g == 2]
    young = [(e - s) / 1e6 for s, e, g in gcs if g < 2]
    long_ms = [(e - s) / 1e6 for s, e in events['long']]
    sleep_ms = [(e - s) / 1e6 for s, e in events['oversleep']]
    return {'late': len(late), 'by_gc': by_gc, 'by_long': by_long, 'by_sleep': by_sleep,
            'full': len(full), 'full_ms': max(full, default=0.0),
            'young': len(young), 'young_ms': max(young, default=0.0),
            'long': len(long_ms), 'long_ms': max(long_ms, default=0.0),
            'sleep': len(sleep_ms), 'sleep_ms': max(sleep_ms, default=0.0),
            'sleep_median': statistics.median(sleep_ms) if sleep_ms else 0.0,
            'objects': events['objects'], 'frozen': events['frozen']}


def measure(counts=COUNTS):
    """Before and after for each count; Markdown lines."""
    lines = ['| bodies | heap | late wakes (> 5 ms) | during a collection / a long pass / '
             'a late sleep | full collections (longest, ms) | young collections (longest, '
             'ms) | passes > 1 ms (longest, ms) | sleeps > 1 ms late (median, longest, ms) | '
             'objects tracked (frozen) |', '|---|---|---|---|---|---|---|---|---|']
    for n in counts:
        for before in (True, False):
            s = summarise(run(n, before))
            lines.append(
                f'| {n} | {"as before" if before else "settled"} | {s["late"]} | '
                f'{s["by_gc"]} / {s["by_long"]} / {s["by_sleep"]} | '
                f'{s["full"]} ({s["full_ms"]:.1f}) | {s["young"]} ({s["young_ms"]:.1f}) | '
                f'{s["long"]} ({s["long_ms"]:.1f}) | {s["sleep"]} ({s["sleep_median"]:.1f}, '
                f'{s["sleep_ms"]:.1f}) | {s["objects"]} ({s["frozen"]}) |')
            print(lines[-1], flush=True)
    return lines


if __name__ == '__main__':
    print('\n'.join(measure()))
