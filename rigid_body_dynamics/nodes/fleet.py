"""
attitude_fleet: many bodies in one process, each a full attitude_simulator in its own namespace.

Every body is an ``AttitudeSimulator`` node named ``attitude_simulator`` in
namespace ``/<name>``, so its topics, services, parameters and diagnostics are
exactly those of a separate ``ros2 run rigid_body_dynamics attitude_simulator
--ros-args -r __ns:=/<name>``: a controller cannot tell the difference.
Parameters given with ``--ros-args -p`` apply to every body; a parameters
file can set one body (key ``/<name>/attitude_simulator``) or all
(``/**/attitude_simulator``).

What the process saves: one interpreter and one DDS participant for all
bodies, and (by default) one integration thread that steps every body in
turn and sleeps until the earliest next deadline, instead of one thread per
body waking at the integration rate (``--threads per-body`` keeps those, for
comparison; benchmarks/bodies.py measures both against separate processes).
All bodies sample their state at the same publish ticks (equal stamps); the
shared thread publishes the ticks within a time budget between integration
passes, so the steps stay on time while the publishing of the last bodies
lags by a few ms.

One body at most may publish /clock (``publish_clock``). A body at
``real_time_factor`` 0 integrates in 5 ms batches on the shared thread, which
makes the other bodies' steps late: as-fast-as-possible runs belong in their
own process.

``attitude_fleet [--bodies N] [--prefix body] [--names a,b,...] [--threads
shared|per-body] [--ros-args ...]``
"""

import argparse
import collections
import math
import sys
import threading
import time

import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.utilities import remove_ros_args

from .parameters import ConfigurationError
from .runner import run
from .simulator import AttitudeSimulator, DIAGNOSTIC_PERIOD, integration_loop, NODE_NAME
from .simulator import SWITCH_INTERVAL


#: Wall time the shared thread spends publishing before it integrates the steps
#: that fell due meanwhile (s). Publishing one body's tick (7 messages) takes
#: about 0.5 ms, integrating one step 10-30 us: publishing every body at one
#: tick in a row would make the last bodies' next steps several ms late.
PUBLISH_BUDGET = 0.0005


def body_names(bodies, prefix, names):
    """Namespaces of the bodies: ``names`` (comma-separated) or prefix1 ... prefixN."""
    if names:
        out = [n.strip().strip('/') for n in names.split(',')]
    else:
        out = [f'{prefix}{k}' for k in range(1, bodies + 1)]
    if not out or any(not n for n in out):
        raise ConfigurationError(f'no valid body names in {names!r}')
    if len(set(out)) != len(out):
        raise ConfigurationError(f'body names must be unique: {out}')
    return out


class Fleet:
    """The bodies of one process and the thread that steps them (``shared``) or theirs."""

    def __init__(self, names, shared=True, **kwargs):
        self._logger = rclpy.logging.get_logger('attitude_fleet')
        self.nodes = []
        self.shared = shared
        self._stop = threading.Event()
        self._thread = None
        try:
            for name in names:
                self.nodes.append(AttitudeSimulator(namespace='/' + name, **kwargs))
            clocks = [n.get_namespace() for n in self.nodes if n.get_parameter(
                'publish_clock').value]
            if len(clocks) > 1:
                raise ConfigurationError(
                    f'publish_clock is set for {len(clocks)} bodies ({", ".join(clocks[:3])}'
                    f'{", ..." if len(clocks) > 3 else ""}); /clock must have one source, so '
                    'set it for one body only (key /<name>/attitude_simulator)')
        except Exception:
            for node in self.nodes:
                node.destroy_node()
            raise
        self._untangle_tf()
        self.context = self.nodes[0].context     # one context, shared by every body
        # Each executor wake-up rebuilds the wait set of every body (about 0.3 ms
        # per body, holding the GIL), so the bodies have no diagnostics timers of
        # their own: the shared thread publishes their diagnostics within its
        # publishing budget, or (thread per body) one timer serves them all.
        if not shared:
            self.nodes[0].create_timer(DIAGNOSTIC_PERIOD, self._publish_diagnostics,
                                       clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._logger.info(
            f'{len(self.nodes)} bodies in this process ({", ".join(names[:5])}'
            f'{", ..." if len(names) > 5 else ""}), '
            f'{"one shared integration thread" if shared else "one integration thread each"}')

    def _untangle_tf(self):
        """Stop /tf for bodies whose (world, body) frames another body also broadcasts."""
        frames = collections.Counter(
            n.state.world_frame + ' -> ' + n.state.body_frame
            for n in self.nodes if n.state.broadcasts_tf)
        shared = [n for n in self.nodes
                  if frames[n.state.world_frame + ' -> ' + n.state.body_frame] > 1]
        for node in shared:
            node.state.stop_tf(node)
        if shared:
            self._logger.warning(
                f'{len(shared)} bodies have the same frames ({", ".join(sorted(frames))}): '
                'they do not broadcast /tf, which would mix them; give each its own body_frame '
                '(key /<name>/attitude_simulator) to get TF')

    def _publish_diagnostics(self):
        for node in self.nodes:
            node.publish_diagnostics()

    def start(self):
        """Start stepping the bodies; with a thread each, every body sets the GIL interval."""
        if not self.shared:
            for node in self.nodes:
                node.start(diagnostics=False)
            return
        sys.setswitchinterval(SWITCH_INTERVAL)
        self._pending = collections.deque()   # (node, snapshot or None = diagnostics)
        self._outbox = []
        self._next_diagnostics = time.monotonic() + DIAGNOSTIC_PERIOD
        priority = max(node.thread_priority for node in self.nodes)
        self._thread = threading.Thread(
            target=integration_loop, name='fleet integration', daemon=True,
            args=(self._cycle, self._stop, priority, self._logger, self.context))
        self._thread.start()

    def stop(self):
        """Stop the integration thread(s) and wait for them."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        for node in self.nodes:
            node.stop()

    def _cycle(self):
        """Integrate every body's due steps, publish within the budget, sleep if nothing is due."""
        now = time.monotonic()
        pending = self._pending
        if now >= self._next_diagnostics:
            self._next_diagnostics = max(self._next_diagnostics + DIAGNOSTIC_PERIOD, now)
            pending.extend((node, None) for node in self.nodes)
        wait = math.inf
        outbox = self._outbox
        for node in self.nodes:
            wait = min(wait, node.pace.due(outbox))
            node.log_notes()
            if outbox:
                pending.extend((node, snapshot) for snapshot in outbox)
                outbox.clear()
        # publish within a budget, then look at the deadlines again; a backlog
        # beyond three items per body is published at once
        end = time.perf_counter() + PUBLISH_BUDGET
        while pending and (time.perf_counter() < end or len(pending) > 3 * len(self.nodes)):
            node, snapshot = pending.popleft()
            if snapshot is None:
                node.publish_diagnostics()
            else:
                node.state.publish(snapshot)
        if not pending and wait > 0.0:
            self._stop.wait(min(wait, self._next_diagnostics - time.monotonic(), 0.05))


def main(args=None, early=None):
    """Run the fleet until Ctrl-C / SIGTERM; exit 0, or 1 (2 for bad options) on bad input."""
    argv = sys.argv if args is None else args
    parser = argparse.ArgumentParser(
        prog='attitude_fleet',
        description='Many attitude_simulator bodies in one process, one namespace each.')
    parser.add_argument('--bodies', type=int, default=4,
                        help='number of bodies, named <prefix>1 ... <prefix>N (default 4)')
    parser.add_argument('--prefix', default='body', help='namespace prefix (default body)')
    parser.add_argument('--names', default='',
                        help='comma-separated namespaces instead of --bodies/--prefix')
    parser.add_argument('--threads', choices=['shared', 'per-body'], default='shared',
                        help='one integration thread for all bodies (default) or one each')
    options = parser.parse_args(remove_ros_args(argv)[1:])
    if options.bodies < 1 and not options.names:
        parser.error('--bodies must be at least 1')
    try:
        names = body_names(options.bodies, options.prefix, options.names)
    except ConfigurationError as err:
        parser.error(str(err))
    return run(lambda: Fleet(names, shared=options.threads == 'shared'), NODE_NAME, argv,
               early=early, on_start=lambda fleet: fleet.start(),
               on_stop=lambda fleet: fleet.stop())


if __name__ == '__main__':
    sys.exit(main())
