"""
One thread driving one body or many: integrate what is due, publish within a budget, sleep.

attitude_simulator runs a :class:`Loop` of one member, attitude_fleet one of
N on a shared thread. Each :class:`Member` is a pace (a
:class:`~.pacer.Pace` or :class:`~.lockstep.Lockstep`) with what to do with
its items (``publish(item)``: a Snapshot or ImuSample), its notes
(``log_notes()``) and, optionally, its diagnostics (``diagnostics()``, every
``diagnostics_period`` s on this thread, the members' spread evenly over the
period). Publishing goes through a queue:
at most ``publish_budget`` s of it between two integration passes, so that
with many bodies the steps stay on time while the last bodies' messages lag
by a few ms (a backlog beyond three items per member is published at once).
A cycle looks only at the members whose next step is due (a heap of due
times) or whose schedule moved (``Pace.anchor`` tells the Loop: reset, resume,
a new rate). No ROS here: the callables are the nodes'; tests drive it on a
fake clock.
"""

import collections
from dataclasses import dataclass
import functools
import heapq
import math
import time

#: Longest sleep of one cycle (s), so that diagnostics and stopping stay prompt.
LONGEST_WAIT = 0.05
#: attitude_fleet's budget (s) of publishing between integration passes: one body's tick
#: (7 messages and the imu) takes 0.05-0.15 ms to publish (prepacked; 0.5 ms as message
#: objects), a step 10-30 us to integrate, so publishing every body at one tick in a row
#: would make the last bodies' next steps several ms late.
FLEET_PUBLISH_BUDGET = 0.0005


@dataclass
class Member:
    """One body on the loop: its pace and the callables that take its output."""

    pace: object
    publish: object
    log_notes: object = lambda: None
    diagnostics: object = None


class Loop:
    """Step ``members`` on one thread; :meth:`cycle` returns how long to sleep (s)."""

    def __init__(self, members, publish_budget=math.inf, diagnostics_period=0.0,
                 clock=time.monotonic, perf=time.perf_counter):
        self.members = list(members)
        self.budget = float(publish_budget)
        self.period = float(diagnostics_period)
        self.clock, self.perf = clock, perf
        self.pending = collections.deque()     # (member, item or None = diagnostics)
        self._outbox = []
        # (when a member is to be looked at, its index): a heap, so that a cycle touches only
        # the members that are due, not all N (at 96 bodies that loop was 9 % of the thread).
        # An entry is current while it equals _next[k]; older ones are dropped when popped.
        self._due = [(-math.inf, k) for k in range(len(self.members))]
        self._next = [-math.inf] * len(self.members)
        # members whose schedule moved (reset, resume, new rate: Pace.anchor): look at once
        self._moved = collections.deque()
        for k, member in enumerate(self.members):
            member.pace.on_move(functools.partial(self._moved.append, k))
        # diagnostics one member at a time, spread evenly over the period: all of a fleet's at
        # once (0.5 ms each here) queued 20-50 ms of publishing at every period, the queue
        # overflowed its backlog limit and was published in one go, and every body's next
        # step came that late (seen as late steps once a second in fleets of 48-96)
        self._reporting = [m for m in self.members if m.diagnostics is not None]
        self._spacing = self.period / max(len(self._reporting), 1)
        self._next_diagnostics = clock() + self._spacing \
            if self.period and self._reporting else math.inf
        self._report_index = 0

    def cycle(self):
        """Integrate every member's due steps, publish within the budget; the wait (s)."""
        pending, outbox = self.pending, self._outbox
        now = self.clock()
        if now >= self._next_diagnostics:
            reporting = self._reporting
            # the members due by now (at most all of them, once, after a long stall)
            due_reports = min(int((now - self._next_diagnostics) / self._spacing) + 1,
                              len(reporting))
            for _ in range(due_reports):
                pending.append((reporting[self._report_index], None))
                self._report_index = (self._report_index + 1) % len(reporting)
            self._next_diagnostics = max(self._next_diagnostics + due_reports * self._spacing,
                                         now)
        due, members, looked, upcoming = self._due, self.members, [], self._next
        moved = self._moved
        while moved:                       # (appended by other threads: popped one by one)
            k = moved.popleft()
            upcoming[k] = now
            heapq.heappush(due, (now, k))
        while due and due[0][0] <= now:
            at, k = heapq.heappop(due)
            if at != upcoming[k]:
                continue                   # superseded by a move
            member = members[k]
            member_wait = member.pace.due(outbox)
            looked.append((now + member_wait, k))   # its next step (or at once, if 0)
            member.log_notes()
            if outbox:
                pending.extend((member, item) for item in outbox)
                outbox.clear()
        for entry in looked:
            upcoming[entry[1]] = entry[0]
            heapq.heappush(due, entry)
        wait = due[0][0] - now if due else math.inf
        end = self.perf() + self.budget
        backlog = 3 * len(self.members)
        while pending and (self.perf() < end or len(pending) > backlog):
            member, item = pending.popleft()
            if item is None:
                member.diagnostics()
            else:
                member.publish(item)
        if pending:
            return 0.0
        return max(0.0, min(wait, self._next_diagnostics - self.clock(), LONGEST_WAIT))

    def run(self, stop):
        """
        Begin every member's schedule now, then cycle until the event ``stop`` is set.

        Sleeps on ``stop`` between cycles.
        """
        for member in self.members:
            member.pace.begin()
        while not stop.is_set():
            wait = self.cycle()
            if wait > 0.0:
                stop.wait(wait)
