"""
Lockstep: the body waits for its controller at every control tick (no ROS, no wall pacing).

At each control tick t_k (every ``control_every`` integration steps from 0) the
state at t_k goes out (a full publish tick, or, between publish ticks, an
``odom_only`` snapshot: what a controller needs), then the body waits until a
torque command stamped at or after t_k has arrived; that command is held from
t_k on (zero-order hold) and the body integrates to t_{k+1} as fast as it can. Stamps and state are
then a function of the commands only: the same controller gives the same
trajectory, bit for bit, however loaded the machine is.

Before the first command the wait has no limit (the state and sensor samples at
t_0 go out again every ``REPEAT`` s, so a late controller finds them). After it, a tick
whose command does not come within ``timeout`` (wall s; 0 = wait for ever)
is a miss: counted, noted for the log, and the last command is held. A
command stamped before the current tick (an answer that came too late) is
counted as ``stale`` and not used: using it would make the run depend on
timing. Interface as :class:`~.pacer.Pace` (``due(outbox)`` returns the wall
time to wait, commands come from ``inbox()`` as the same values), so the node's
integration thread drives either.
"""

import time

from .pacer import Pace, PAUSED_WAIT

_NS = 1_000_000_000
#: Period (wall s) at which the state at t_0 is published again until the first command.
REPEAT = 1.0
#: The command topic of each kind of answer, for the log.
TOPICS = {'torque': 'torque_cmd', 'dipole': 'magnetorquer_cmd', 'wheels': 'wheel_cmd'}
#: Longest single wait inside due() (s), so that stopping the thread is prompt.
WAIT_SLICE = 0.1


def _at_or_after(stamp_ns, tick_ns):
    """Whether a held command's stamp (int ns, or None without one) answers the tick."""
    return stamp_ns is not None and stamp_ns >= tick_ns


class Lockstep(Pace):
    """
    Lockstep schedule of one body: ``control_every`` steps per tick, ``timeout`` (s).

    ``answer``: the kinds of command a tick waits for, all of them: 'torque' (a
    torque_cmd stamped at or after the tick), 'dipole' (a magnetorquer_cmd stamped
    at or after the tick) and/or 'wheels' (a valid wheel command
    that came during the tick's wait: Float64MultiArray has no stamp); default
    'wheels' for a body with wheels, else 'torque'.

    Counters: ``ticks`` answered, ``misses``, ``wait_ns`` (total wall time
    spent waiting for answered ticks after the first) and ``max_wait_ns`` since
    :meth:`take_wait`. Commands come from ``inbox()`` as in :class:`~.pacer.Pace`
    (default: the pace's ``mailbox``); ``wait(timeout_s)`` blocks until one is
    pending (default: the mailbox's; a node passes its subscription's wait).
    """

    def __init__(self, body, control_every, timeout, clock=time.monotonic_ns,
                 perf=time.perf_counter, inbox=None, wait=None, answer=None):
        super().__init__(body, 0.0, clock=clock, perf=perf, inbox=inbox)
        self.wait = wait if wait is not None else self.mailbox.wait
        # the kinds of command that answer a tick, all of them: a torque stamped at or after
        # the tick, a valid wheel command that came during its wait
        self.answer = frozenset(answer or (('wheels',) if body.wheels is not None
                                           else ('torque',)))
        if not self.answer <= {'torque', 'wheels', 'dipole'}:
            raise ValueError(f'answer must be made of torque, dipole and wheels, got {answer!r}')
        self._stamped = tuple(self.answer & {'torque', 'dipole'})
        self._awaited = ' and '.join(TOPICS[kind] for kind in sorted(self.answer))
        self.control_every = int(control_every)
        if self.control_every < 1:
            raise ValueError(f'control_every must be >= 1, got {control_every!r}')
        self.timeout_ns = int(timeout * _NS)
        self.restart()

    def restart(self):
        """From the body's current tick (after start-up or a reset): waiting, no command yet."""
        super().restart()
        self.ticks = self.misses = 0
        self.wait_ns = self.max_wait_ns = 0
        self._first = True
        self._streak = 0
        self._wheel_answer = False
        self._wait_start = self._last_repeat = self.clock()

    def set_rtf(self, rtf):
        """Lockstep runs as fast as the controller answers: the real-time factor is unused."""

    def _take(self):
        """
        Take the inbox's commands; drop those stamped before the current tick.

        A dropped command is counted ``stale`` (an answer that came after its tick
        was closed: using it would make the run depend on timing); one without a
        stamp is held as in real time. A valid wheel command (std_msgs/Float64MultiArray:
        no stamp) answers the tick during whose wait it comes.
        """
        body, taken = self.body, []
        now = body.stamp_now()
        for value in self.inbox():
            if value.stamps_ns is not None:
                fresh = [s >= now for s in value.stamps_ns]
                if not all(fresh):
                    body.reject('stale', fresh.count(False), value.kind)
                    value = value.select(fresh)
            if len(value):
                checked = body.check(value)
                if checked.kind == 'wheels' and checked.newest[-1] >= 0:
                    self._wheel_answer = True
                taken.append([checked, 0])
        return taken

    def due(self, outbox):
        """
        Publish the tick's state, or wait for its command, or integrate to the next tick.

        Returns 0.0 (call again at once) or PAUSED_WAIT; waits inside for at most
        WAIT_SLICE s with the body's lock released.
        """
        body = self.body
        with body.lock:
            if body.paused:
                return PAUSED_WAIT
            now = self.clock()
            self._hold_all()
            tick = body.stamp_now()
            answered = all(_at_or_after(body.held_stamp(kind), tick) for kind in self._stamped) \
                and ('wheels' not in self.answer or self._wheel_answer)
            waited = now - self._wait_start
            if answered or (not self._first and self.timeout_ns and waited > self.timeout_ns):
                self._close_tick(answered, waited)
                self._wheel_answer = False
                for _ in range(self.control_every):
                    body.advance(now, outbox)
                if body.steps % body.publish_every:     # the state at the tick always goes out
                    outbox.append(body.snapshot(odom_only=True))
                self._wait_start = self.clock()
                return 0.0
            if self._first and now - self._last_repeat >= REPEAT * _NS:
                self._last_repeat = now
                # for a controller that comes late: the state and samples of t_0 again
                outbox.extend(self.start_items or [body.snapshot()])
                return 0.0
            left = (self.timeout_ns - waited) / _NS if self.timeout_ns and not self._first \
                else WAIT_SLICE
        self.wait(min(max(left, 0.0), WAIT_SLICE))
        return 0.0

    def _close_tick(self, answered, waited):
        body = self.body
        if answered:
            self.ticks += 1
            if not self._first:       # the first wait is the controller's start-up
                self.wait_ns += waited
                self.max_wait_ns = max(self.max_wait_ns, waited)
            if self._streak:
                body.note(f'lockstep: the controller answered again after '
                          f'{self._streak} missed ticks')
            self._first, self._streak = False, 0
            return
        self.misses += 1
        if not self._streak:
            body.note(
                f'lockstep: no {self._awaited} for the tick at t = {body.steps * body.dt:.6g} s '
                f'within {self.timeout_ns / _NS:g} s; holding the last command and going on '
                '(said once until the controller answers again)')
        self._streak += 1

    def take_wait(self):
        """Return (mean, max) wall wait per answered tick (ms) since the last call; start over."""
        with self.body.lock:
            mean = self.wait_ns / (self.ticks - 1) / 1e6 if self.ticks > 1 else 0.0
            result = (mean, self.max_wait_ns / 1e6)
            self.max_wait_ns = 0
        return result
