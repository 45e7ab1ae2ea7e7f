"""
attitude_fleet: many bodies, each a full attitude_simulator in its own namespace.

Every body is an ``AttitudeSimulator`` in ``/<name>``, with the topics, services, parameters
and diagnostics of ``attitude_simulator --ros-args -r __ns:=/<name>``. ``-p`` sets every body,
a parameters file one (``/<name>/attitude_simulator``) or all (``/**/attitude_simulator``).
The bodies go round-robin to ``--processes`` worker processes (default: one per core this
process may use; fleet_supervisor.py starts, watches and stops them); with one, this process
hosts them all. In a process, one interpreter, one executor and one engine Loop thread serve
its bodies (benchmarks/bodies.py), spread over one DDS participant per
BODIES_PER_PARTICIPANT (Fast DDS tears a participant's entities down in a time that grows
with the square of their number). Each body's frame ids carry its name (``frame_prefix``
``<name>/``: body1/odom -> body1/base_link), so every body broadcasts a TF tree of its own;
bodies that still share frames (a ``frame_prefix`` given to all), in any of the processes,
do not broadcast /tf. One body at most publishes /clock; an as-fast-as-possible body makes the
others of its process late (run it in its own process). ROS 2's standard simulator services
(``simulation_interfaces``) are off unless set, for a body or for all: their endpoints made
128 bodies start and exit 2.5-3 times slower.

``attitude_fleet [--bodies N] [--prefix body] [--first K] [--names a,b,...]
[--processes P] [--ros-args ...]``
"""

import argparse
import sys
import threading

import rclpy
from rclpy.context import Context
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args

from . import fleet_supervisor
from .simulator import AttitudeSimulator, DIAGNOSTIC_PERIOD, integration_loop, NODE_NAME
from .simulator import SWITCH_INTERVAL
from ..engine.loop import FLEET_PUBLISH_BUDGET, Loop
from ..engine.pacer import spread_phases
from ..ros.parameters import ConfigurationError
from ..ros.runner import run


def body_names(bodies, prefix, names, first=1):
    """
    Return the namespaces of the bodies.

    ``names`` (comma-separated), else <prefix><first> ... <prefix><first + bodies - 1>.
    """
    out = ([n.strip().strip('/') for n in names.split(',')] if names else
           [f'{prefix}{k}' for k in range(first, first + bodies)])
    if not names and bodies < 1:
        raise ConfigurationError('--bodies must be at least 1')
    if not names and first < 0:
        raise ConfigurationError('--first must be at least 0')
    if not out or any(not n for n in out):
        raise ConfigurationError(f'no valid body names in {names!r}')
    if len(set(out)) != len(out):
        raise ConfigurationError(f'body names must be unique: {out}')
    return out


#: Bodies per DDS participant (rclpy Context). Destroying a participant's entities one by one
#: costs Fast DDS time that grows with the square of their number: 96 bodies (5376 entities)
#: took 4.1-4.4 s to tear down in one participant, 1.3 s in six (measured 2026-12-02; RESULTS.md
#: at commit 345c04f, "The Jazzy stack, start-up and a fleet's exit"), so a
#: fleet did not exit within the 5 s that ros2 launch waits after SIGINT.
BODIES_PER_PARTICIPANT = 16


class Fleet:
    """The bodies of one process and the thread that steps them."""

    def __init__(self, names, args=None, untangle=True, **kwargs):
        self._logger = rclpy.logging.get_logger('attitude_fleet')
        self.nodes, self._stop, self._thread = [], threading.Event(), None
        self._contexts = []          # participants after the first (the default context)
        try:
            for k, name in enumerate(names):
                if k and k % BODIES_PER_PARTICIPANT == 0:
                    context = Context()
                    rclpy.init(args=args, context=context,
                               signal_handler_options=SignalHandlerOptions.NO)
                    self._contexts.append(context)
                    kwargs['context'] = context
                self.nodes.append(AttitudeSimulator(frame_prefix_default=name + '/',
                                                    simulation_interfaces_default=False,
                                                    defer_first_state=True,
                                                    namespace='/' + name, **kwargs))
            fleet_supervisor.one_clock_source(
                [n.get_namespace() for n in self.nodes if n.publishes_clock])
        except Exception:
            self._destroy()
            raise
        if untangle:                # a worker's parent does it for the whole fleet
            self._untangle_tf()
        self.context = self.nodes[0].context     # the first participant's: rclpy.init's
        self._logger.info(f'{len(names)} bod{"y" if len(names) == 1 else "ies"} in this '
                          'process, one integration thread, '
                          f'{1 + len(self._contexts)} DDS participants')

    def tf_frames(self):
        """Return {namespace: 'world -> body'} of the bodies that broadcast /tf."""
        return {n.get_namespace(): f'{n.state.world_frame} -> {n.state.body_frame}'
                for n in self.nodes if n.state.broadcasts_tf}

    def stop_tf(self, namespaces):
        """Stop /tf for the bodies in ``namespaces`` (they share frames with another body)."""
        for node in self.nodes:
            if node.get_namespace() in namespaces:
                node.state.stop_tf(node)

    def _untangle_tf(self):
        """Stop /tf for bodies whose (world, body) frames another body also broadcasts."""
        shared = fleet_supervisor.shared_frames(self.tf_frames(), self._logger)
        self.stop_tf(shared)

    def start(self):
        """Start the thread that steps every body (diagnostics too: no timer per body)."""
        for node in self.nodes:         # now that the fleet has decided who broadcasts /tf
            node.publish_first_state()
        sys.setswitchinterval(SWITCH_INTERVAL)
        spread_phases(node.pace for node in self.nodes)     # a few bodies due at a time
        loop = Loop([node.member(diagnostics=True) for node in self.nodes],
                    publish_budget=FLEET_PUBLISH_BUDGET, diagnostics_period=DIAGNOSTIC_PERIOD)
        priority = max(node.thread_priority for node in self.nodes)
        self._thread = threading.Thread(
            target=integration_loop, name='fleet integration', daemon=True,
            args=(loop, self._stop, priority, self._logger, self.context))
        self._thread.start()

    def stop(self):
        """Stop the integration thread and wait for it; destroy the bodies and participants."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        self._destroy()

    def _destroy(self):
        """Destroy every body, then the participants beyond the default one (run() ends that)."""
        nodes, self.nodes = self.nodes, []
        for node in nodes:
            node.destroy_node()
        for context in self._contexts:
            context.try_shutdown()
        self._contexts = []


def main(args=None, early=None):
    """Run the fleet until Ctrl-C / SIGTERM; exit 0, or 1 (2 for bad options) on bad input."""
    argv = sys.argv if args is None else args
    parser = argparse.ArgumentParser(
        prog='attitude_fleet',
        description='Many attitude_simulator bodies, one namespace each, over one or more '
                    'processes.')
    parser.add_argument('--bodies', type=int, default=4,
                        help='number of bodies, named <prefix>1 ... <prefix>N (default 4)')
    parser.add_argument('--prefix', default='body', help='namespace prefix (default body)')
    parser.add_argument('--first', type=int, default=1,
                        help='number of the first body (default 1): with --bodies N, '
                             '<prefix><first> ... <prefix><first+N-1>, a range of a fleet split '
                             'over hosts')
    parser.add_argument('--names', default='',
                        help='comma-separated namespaces instead of --bodies/--prefix')
    parser.add_argument('--processes', type=int, default=0,
                        help='worker processes, bodies assigned round-robin (default: the '
                             'cores this process may use, at most the number of bodies; '
                             '1: every body in this process)')
    parser.add_argument('--report-fd', type=int, default=-1, help=argparse.SUPPRESS)
    options = parser.parse_args(remove_ros_args(argv)[1:])
    try:
        names = body_names(options.bodies, options.prefix, options.names, options.first)
        if options.processes < 0:
            raise ConfigurationError('--processes must be at least 1 (0: one per core)')
    except ConfigurationError as err:
        parser.error(str(err))
    processes = min(len(names), options.processes or fleet_supervisor.default_processes(
        len(names)))
    if processes > 1:
        return fleet_supervisor.supervise(fleet_supervisor.assign(names, processes), argv,
                                          early=early)
    if options.report_fd >= 0:         # a worker of a fleet over processes
        def worker():
            return _reported(Fleet(names, args=argv, untangle=False), options.report_fd)
        return run(worker, NODE_NAME, argv, early=early, on_start=_start_when_told,
                   on_stop=Fleet.stop)
    return run(lambda: Fleet(names, args=argv), NODE_NAME, argv, early=early,
               on_start=Fleet.start, on_stop=Fleet.stop)


def _reported(fleet, fd):
    """Worker: tell the parent which bodies publish /clock and /tf here; return the fleet."""
    fleet_supervisor.worker_report(fd, [n.get_namespace() for n in fleet.nodes
                                        if n.publishes_clock], fleet.tf_frames())
    return fleet


def _start_when_told(fleet):
    """Worker: start stepping when the parent says go; stop when it closes the lifeline."""
    go = fleet_supervisor.wait_for_go()
    if go is not None:
        fleet.stop_tf(go['no_tf'])
        fleet.start()
    fleet_supervisor.watch_lifeline()


if __name__ == '__main__':
    from .entry import exiting
    sys.exit(exiting(main()))
