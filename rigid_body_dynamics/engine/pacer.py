"""
Pacing of simulated bodies on the steady clock, without ROS.

A :class:`Pace` keeps one body's schedule: the anchor (a steady time and
the step count at it), the real-time factor, missed deadlines and lateness.
:meth:`Pace.due` integrates every step that is due now (or a batch of steps
as fast as possible when the factor is 0) and returns the wall time until it
wants to be called again; one thread can drive one body or many
(attitude_fleet) with it. The clock is passed in (``clock()`` -> int ns,
``perf()`` -> s), so tests run it on a fake clock.

In real time a body is woken at its *ticks*, not at every step: when a step
produces something to publish (a state or an IMU sample), and at least every
COMMAND_LOOK s, to take the torque commands that came meanwhile. The steps
in between are integrated at the wake, each with the command that was the
newest at its deadline (commands carry their steady-clock receive time), so
the motion is the one that stepping at every deadline gives, at a tenth of
the wake-ups for the defaults (1 kHz steps, 100 Hz publishing).
"""

import math
import time

from .commands import Mailbox

_NS = 1_000_000_000
#: Wall time the pacing may fall behind before the backlog is dropped (s).
MAX_LAG = 0.25
#: A step computed more than this after its deadline counts as a missed deadline (s).
LATE_LIMIT = 0.005
#: In as-fast-as-possible mode, wall time per batch of steps (s), and the pause
#: after each batch that lets other threads take the body's lock (services,
#: parameters, torque commands, diagnostics); without it the lock is re-taken
#: at once and the executor starves.
AFAP_BATCH = 0.005
AFAP_YIELD = 0.0002
#: Wait (s) while the body is paused.
PAUSED_WAIT = 0.05
#: Longest wall time between two wakes of a body in real time (s): commands that came
#: meanwhile are taken then (at 10 kHz, 200 of them; the node's queue holds 1000). Each
#: still acts from the step during which it came, so this bounds only the queue and the
#: steps integrated in one wake: at 10 ms a body publishing at 50 Hz woke twice per tick,
#: which cost a fleet of 96 such bodies a tenth of a core.
COMMAND_LOOK = 0.02
#: Bodies of one thread due at one instant (:func:`spread_phases`): a body's step and its
#: publishing cost 40-50 us in a fleet of 96, so 16 at once keep a burst near 1 ms; all 96
#: at once took 4-5 ms and made the last ones late.
PHASE_BODIES = 16


class Pace:
    """
    The schedule of one :class:`~rigid_body_dynamics.engine.body.BodySimulation`.

    ``rtf``: simulated s per wall s (0 = as fast as possible). ``missed``
    counts wakes more than LATE_LIMIT after their deadline (the deadline of
    the tick they were for), ``max_late_ns`` the worst lateness since
    :meth:`take_max_late`; ``on_backlog(steps)`` is called when a backlog
    over MAX_LAG is dropped.

    Commands come from ``inbox()`` (default: a :class:`~.commands.Mailbox`, kept
    as ``mailbox``), called at every wake before the due steps: a list of command
    values (:mod:`.commands`), each N commands oldest first with their steady
    receive times. The body checks each value at once; a command is held
    (:meth:`~.body.BodySimulation.hold`) before the first due step whose deadline
    is at or after its receive time, so it acts from the step during which it
    came, as if the body had been stepped at every deadline; one that came after
    the last due deadline, after them. This is the one path of a command in every
    mode: as fast as possible it is held at once, and :class:`~.lockstep.Lockstep`
    takes the same values.
    """

    def __init__(self, body, rtf, clock=time.monotonic_ns, perf=time.perf_counter,
                 on_backlog=None, inbox=None):
        self.body = body
        self.mailbox = Mailbox() if inbox is None else None
        self.inbox = self.mailbox.take if inbox is None else inbox
        self.rtf = float(rtf)
        self.clock, self.perf = clock, perf
        self.on_backlog = on_backlog or (lambda steps: None)
        self.missed = 0
        self.start_items = None    # the items of the current start (first_items)
        self.max_late_ns = 0
        self.phase = 0.0
        self._on_move = []          # called by anchor(): see on_move
        self._target = 0            # the step the next wake is for (0: the next one)
        self.anchor()
        self._stats = self._woke = (clock(), body.steps)

    def anchor(self):
        """
        Restart the schedule: the next step is due at the next slot of the clock.

        Steps fall on whole periods of the steady clock, shifted by ``phase``
        periods (0 <= phase < 1), so the bodies of one thread with the same
        period and phase are due at the same instants and one wake-up steps
        them all: a wake-up per body and step cost a fleet of 96 bodies more
        than their steps, and all 96 at one instant made the last ones late
        (attitude_fleet spreads its bodies over a few phases). The first step
        comes at most 1 + ``phase`` periods after this call.
        """
        now = self.clock()
        period = self.body.dt_ns / self.rtf if self.rtf > 0.0 else self.body.dt_ns
        # the last whole period of the clock, then the phase (the first step may be later)
        self.anchor_ns = now - now % period + self.phase * period
        self.anchor_steps = self.body.steps
        self._target = 0
        for callback in self._on_move:
            callback()                   # e.g. tell the Loop: the next step may be earlier now

    def on_move(self, callback):
        """Call ``callback()`` whenever the schedule moves (:meth:`anchor`: reset, resume...)."""
        self._on_move.append(callback)

    def set_phase(self, phase):
        """
        Shift the step instants by ``phase`` step periods (>= 0; re-anchors).

        The fraction moves the steps off the whole periods of the clock; the
        whole part delays the next step by that many periods, which moves the
        body's ticks (its wakes) against those of bodies with another phase.
        """
        if not 0.0 <= phase < math.inf:
            raise ValueError(f'phase must be a number >= 0, got {phase!r}')
        self.phase = float(phase)
        self.anchor()

    @property
    def wake_steps(self):
        """Return the steps from one wake to the next in real time: a tick, or COMMAND_LOOK."""
        return min(self.body.shortest_tick, self._look_steps())

    def _look_steps(self):
        """Return the steps in COMMAND_LOOK s of wall time (at least 1)."""
        return max(1, int(COMMAND_LOOK * _NS * self.rtf / self.body.dt_ns)) if self.rtf else 1

    def begin(self):
        """
        Start the schedule now: a new anchor, no lateness and no achieved rate counted so far.

        The thread that keeps the schedule calls it when it starts (:meth:`Loop.run`), so
        the time a node takes to get ready (DDS entities, imports, a busy machine at
        start-up) is not a missed deadline: anchored at construction, a first run of
        ``./dev demo`` began by dropping a "backlog" of 1346 steps (0.34 s at 4x).
        """
        with self.body.lock:
            self.missed = 0
            self.max_late_ns = 0
            self._stats = self._woke = (self.clock(), self.body.steps)
            self.anchor()

    def restart(self):
        """After a reset of the body: as :meth:`begin`."""
        self.begin()

    def first_items(self):
        """
        Return the body's items at its current time (state, sensor samples; under its lock).

        Kept, so that lockstep can send them again to a controller that comes late
        without drawing the sensors' noise a second time.
        """
        self.start_items = self.body.first_items()
        return self.start_items

    def set_rtf(self, rtf):
        """Change the real-time factor (re-anchors)."""
        self.rtf = float(rtf)
        self.anchor()

    def due(self, outbox):
        """
        Integrate the body's due steps (its ticks' snapshots go to ``outbox``).

        Returns the wall time (s) until the next wake: the next step that
        publishes, or COMMAND_LOOK s of steps, whichever comes first.
        """
        body = self.body
        with body.lock:
            if body.paused:
                return PAUSED_WAIT
            if self.rtf == 0.0:
                self._hold_all()
                end = self.perf() + AFAP_BATCH
                while self.perf() < end:
                    body.advance(self.clock(), outbox)
                self._woke = (self.clock(), body.steps)
                return AFAP_YIELD
            now = self.clock()
            period = body.dt_ns / self.rtf
            due_steps = self.anchor_steps + int((now - self.anchor_ns) / period)
            if due_steps > body.steps:
                target = self._target if self._target > body.steps else body.steps + 1
                if target <= due_steps:           # the wake this tick asked for is here
                    late = now - self.deadline(target)
                    self.max_late_ns = max(self.max_late_ns, late)
                    if late > LATE_LIMIT * _NS:
                        self.missed += 1
                    if late > MAX_LAG * _NS:
                        self.on_backlog(due_steps - body.steps)
                        self.anchor()
                        due_steps = body.steps + 1
                self._steps_to(due_steps, outbox)
                self._woke = (now, due_steps)
            else:
                self._hold_all()
            return max(0.0, (self.deadline(self._next_target()) - self.clock()) / _NS)

    def step_paused(self, count, outbox):
        """
        Integrate ``count`` steps now, while the body is paused (call under the body's lock).

        The commands that came are held first, as a wake holds them; the steps
        are the ones a run would make (what ROS 2's StepSimulation asks).
        """
        self._hold_all()
        now = self.clock()
        body = self.body
        for _ in range(count):
            body.advance(now, outbox)

    def deadline(self, step):
        """Steady time (int ns) at which step number ``step`` (the one ending there) is due."""
        period = self.body.dt_ns / self.rtf
        return self.anchor_ns + int((step - self.anchor_steps) * period)

    def _steps_to(self, due_steps, outbox):
        """Integrate up to step ``due_steps``, each with the commands newest at its deadline."""
        body = self.body
        pending = self._take()
        coming = self._next_arrival(pending) if pending else math.inf
        # (self.deadline(step), inlined: this loop runs at every step of every body)
        anchor_ns, anchor_steps, period = self.anchor_ns, self.anchor_steps, body.dt_ns / self.rtf
        for step in range(body.steps + 1, due_steps + 1):
            at = anchor_ns + int((step - anchor_steps) * period)
            if coming <= at:
                coming = self._hold_until(pending, at)
            rest = due_steps - step + 1
            if not pending and rest > 1 and body.advance_free(rest, at, outbox):
                break        # the rest torque-free and no command to come in between: at once
            body.advance(at, outbox)
        if pending:
            self._hold_until(pending, math.inf)

    def _hold_until(self, pending, at_ns):
        """
        Hold the commands of ``pending`` received by ``at_ns``.

        ``pending``: [checked value, index of its next command] entries, updated in
        place (finished ones removed). Returns the next receive time still to come
        (int ns), or inf.
        """
        hold, coming, k = self.body.hold, math.inf, 0
        while k < len(pending):
            entry = pending[k]
            checked, i = entry
            received = checked.received_ns
            n, j = len(received), i
            while j < n and received[j] <= at_ns:
                j += 1
            if j > i:
                hold(checked, i, j)
            if j == n:
                del pending[k]
                continue
            entry[1] = j
            if received[j] < coming:
                coming = received[j]
            k += 1
        return coming

    @staticmethod
    def _next_arrival(pending):
        """Return the earliest receive time (int ns) still to hold (``pending`` not empty)."""
        return min(checked.received_ns[i] for checked, i in pending)

    def _hold_all(self):
        """Hold every pending command at once (no step due, or as fast as possible)."""
        pending = self._take()
        if pending:
            self._hold_until(pending, math.inf)

    def _take(self):
        """Take the inbox's command values, checked by the body: [[checked, 0], ...]."""
        body = self.body
        return [[body.check(value), 0] for value in self.inbox() if len(value)]

    def _next_target(self):
        """Return the step the next wake is for: the next that publishes, or COMMAND_LOOK s on."""
        body = self.body
        self._target = body.steps + min(body.steps_to_tick(), self._look_steps())
        return self._target

    def achieved(self):
        """
        Return the achieved real-time factor (simulated s per wall s) since the last call.

        Measured from wake to wake (the time of the body's latest wake and the steps
        done then), not to the time of the call: in real time the steps due since a
        wake are integrated at the next one, so counting them at the call made a body
        woken every 20 ms read 0.98-1.02 in a 1 s period while exactly on time. With
        no wake since the last call (paused, stalled) it is 0, and the time without a
        wake counts in the next reading.
        """
        with self.body.lock:
            then, steps_then = self._stats
            now, steps = self._woke
            if now <= then:
                return 0.0        # no wake since the last call (paused, or stalled)
            self._stats = (now, steps)
            return (steps - steps_then) * self.body.dt_ns / (now - then)

    def take_max_late(self):
        """Return the worst lateness (ms) since the previous call and start over."""
        with self.body.lock:
            late, self.max_late_ns = self.max_late_ns, 0
        return late / 1e6


def spread_phases(paces, per_phase=PHASE_BODIES):
    """
    Spread ``paces`` over ceil(N / per_phase) equally spaced phases of their wake period.

    So that one thread's N bodies wake in groups of at most ``per_phase``: one
    wake-up per group and tick, not per body, and no burst of all N at once.
    The wake period is :attr:`Pace.wake_steps` step periods (10 at 1 kHz steps
    and 100 Hz publishing), so the groups' ticks fall apart, not just their steps.
    """
    paces = list(paces)
    phases = max(1, -(-len(paces) // per_phase))
    for k, pace in enumerate(paces):
        pace.set_phase((k % phases) / phases * pace.wake_steps)
