"""
attitude_fleet over several processes: the parent that starts, watches and stops the workers.

Each worker is ``attitude_fleet --names <its bodies> --processes 1`` with the user's
``--ros-args``: its own interpreter, integration thread and DDS participants. The bodies
go round-robin (worker k of P has bodies k, k + P, ...). The start is in two phases, so
that a configuration the fleet as a whole refuses starts nothing: every worker builds its
bodies and reports them on a pipe (which of them publish /clock, and their TF frames), and
only when all have reported does the parent tell them to go (a line on their stdin, with
the bodies whose /tf must stop). The parent's own node
``attitude_fleet`` publishes one /diagnostics status per worker (ERROR once it has died,
with its exit code and its bodies) every second and at once on a death. The fleet's rules
hold across the workers: one /clock source at most, and no /tf from bodies that share frames.

Each worker's status carries its CPU (cores, over the last period, and seconds since it
started, from /proc), and an ``attitude_fleet: fleet`` status the sum over the workers
and the parent, so that what the fleet costs is seen on the graph; the exit log says
the same over the whole run. The worker's stdin is its lifeline: when it closes (the
parent stops, or dies even by
SIGKILL) the worker stops cleanly as on SIGINT, so no worker outlives its fleet.
"""

import collections
import json
import os
import selectors
import signal
import subprocess
import sys
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
import rclpy
from rclpy.signals import SignalHandlerOptions

from ..ros.client import dump_and_kill
from ..ros.conversions import status
from ..ros.parameters import ConfigurationError
from ..ros.runner import stop_on_signals

#: The parent's node name (its /diagnostics statuses are ``attitude_fleet: worker k``).
NODE_NAME = 'attitude_fleet'
#: Period of the parent's /diagnostics (s).
DIAGNOSTIC_PERIOD = 1.0
#: How often the parent looks at the stop flag and at its workers (s).
WATCH_PERIOD = 0.05
#: Longest wait for the workers to exit after the stop before they are killed (s): within
#: the 10 s after which ros2 launch sends SIGKILL to the parent.
EXIT_WAIT = 8.0
#: The command that starts a worker: the console entry point (it owns SIGINT from its first
#: instant), then the fleet's own options and the user's ROS arguments.
WORKER = ('import sys; from rigid_body_dynamics.nodes.entry import fleet; sys.exit(fleet())',)


def cpu_seconds(pid):
    """
    Return the user + system CPU time (s) of process ``pid`` (all its threads), or None.

    From /proc/<pid>/stat (Linux); None where it cannot be read (another system, or the
    process has been reaped).
    """
    try:
        with open(f'/proc/{pid}/stat') as f:
            fields = f.read().rsplit(')', 1)[1].split()
    except (OSError, IndexError):
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


class CpuMeter:
    """The CPU of one process: seconds since it started, and cores over the last reading."""

    def __init__(self, pid):
        self.pid, self.started = pid, time.monotonic()
        self.total, self.cores = 0.0, None
        self._last = (self.started, 0.0)

    def read(self):
        """Take a reading (keeps the last one if the process is gone); return the cores."""
        used = cpu_seconds(self.pid)
        now = time.monotonic()
        if used is not None:
            then, before = self._last
            if now > then:
                self.cores = (used - before) / (now - then)
            self.total, self._last = used, (now, used)
        return self.cores

    def average(self):
        """Return the cores averaged since the process started (to the last reading)."""
        span = self._last[0] - self.started
        return self.total / span if span > 0.0 else None


def default_processes(bodies):
    """Return the cores this process may use (its CPU affinity), at most ``bodies``."""
    return max(1, min(bodies, len(os.sched_getaffinity(0))))


def assign(names, processes):
    """Round-robin: the names of worker k are names[k::processes] (k = 0 ... processes - 1)."""
    return [names[k::processes] for k in range(processes)]


def shared_frames(frames, logger):
    """
    Return the namespaces whose TF frames another body also broadcasts, and say so.

    ``frames``: {namespace: 'world -> body'} of the bodies that broadcast /tf. Their /tf
    must stop, as it would mix the bodies (a ``frame_prefix`` given to all).
    """
    count = collections.Counter(frames.values())
    shared = sorted(ns for ns, pair in frames.items() if count[pair] > 1)
    if shared:
        logger.warning(
            f'{len(shared)} bodies have the same frames '
            f'({", ".join(sorted({frames[ns] for ns in shared}))}): they do not broadcast '
            '/tf, which would mix them; give each its own body_frame '
            '(key /<name>/attitude_simulator) to get TF')
    return shared


def one_clock_source(clocks):
    """Refuse (ConfigurationError) a fleet where more than one body (``clocks``) has /clock."""
    if len(clocks) > 1:
        raise ConfigurationError(
            f'publish_clock is set for {len(clocks)} bodies ({", ".join(clocks[:3])}'
            f'{", ..." if len(clocks) > 3 else ""}); /clock must have one source, so '
            'set it for one body only (key /<name>/attitude_simulator)')


def worker_report(fd, clocks, frames):
    """
    Worker side: report to the parent on pipe ``fd``.

    ``clocks``: the namespaces of the bodies that publish /clock; ``frames``: {namespace:
    'world -> body'} of those that broadcast /tf.
    """
    with os.fdopen(fd, 'w') as pipe:
        pipe.write(json.dumps({'clocks': clocks, 'frames': frames}) + '\n')


def wait_for_go():
    """Worker side: wait for the parent's go on stdin: its orders, or None if stdin closed."""
    line = sys.stdin.readline()
    return json.loads(line) if line.strip() else None


def watch_lifeline():
    """Worker side: SIGTERM this process when stdin closes (the parent stopped or died)."""
    def watch():
        while sys.stdin.readline():
            pass
        os.kill(os.getpid(), signal.SIGTERM)
    threading.Thread(target=watch, name='fleet lifeline', daemon=True).start()


class Worker:
    """One worker process: its bodies, its Popen and what it reported."""

    def __init__(self, index, names, argv):
        self.index, self.names = index, names
        read, write = os.pipe()
        # the user's arguments, an empty ROS section (it closes one they left open), then
        # this worker's own options, which win over the user's (argparse keeps the last)
        command = [sys.executable, '-c', *WORKER, *argv[1:], '--ros-args', '--',
                   '--names', ','.join(names), '--processes', '1', '--report-fd', str(write)]
        self.proc = subprocess.Popen(command, stdin=subprocess.PIPE, pass_fds=(write,),
                                     text=True)
        os.close(write)
        self.report_pipe = os.fdopen(read)
        self.report = None
        self.death = None           # the exit code of a death before the stop
        self.cpu = CpuMeter(self.proc.pid)

    @property
    def pid(self):
        """Return the worker's process id."""
        return self.proc.pid

    def read_report(self):
        """Read the report (after the selector said it is there); None at EOF."""
        line = self.report_pipe.readline()
        self.report_pipe.close()
        self.report = json.loads(line) if line else {}
        return self.report

    def tell(self, line):
        """Write ``line`` to the worker's stdin (ignored once it has gone)."""
        try:
            self.proc.stdin.write(line + '\n')
            self.proc.stdin.flush()
        except (BrokenPipeError, ValueError):
            pass

    def release(self):
        """Close the lifeline: the worker stops as on SIGINT."""
        try:
            self.proc.stdin.close()
        except BrokenPipeError:
            pass

    def status(self, hardware_id):
        """Return the worker's DiagnosticStatus: OK while it runs, ERROR once it has died."""
        code = self.proc.poll()
        bodies = ', '.join(self.names)
        values = [('pid', self.pid), ('bodies', bodies), ('body count', len(self.names))]
        if code is None:
            self.cpu.read()
        values += _cpu_values(self.cpu, len(self.names))
        if code is None:
            level, message = DiagnosticStatus.OK, f'running {len(self.names)} bodies'
        else:
            level = DiagnosticStatus.ERROR
            message = f'exited with {describe(code)}: bodies {bodies} are gone'
            values.append(('exit code', code))
        return status(f'{NODE_NAME}: worker {self.index + 1}', level, message, values,
                      hardware_id)


def _cores(cores, bodies=None):
    """Say ``cores`` (or their share per body, % of a core): 'not measured yet' for None."""
    if cores is None:
        return 'not measured yet'
    return f'{cores:.3f}' if bodies is None else f'{100.0 * cores / max(1, bodies):.2f}'


def _cpu_values(meter, bodies):
    """Return the CPU keys of a status: cores over the last period, per body, seconds in all."""
    return [('CPU (cores)', _cores(meter.cores)),
            ('CPU per body (% of a core)', _cores(meter.cores, bodies)),
            ('CPU time (s)', f'{meter.total:.2f}')]


def describe(code):
    """Say an exit code: 'code 1', or 'signal SIGKILL' for a negative one."""
    if code < 0:
        try:
            return f'signal {signal.Signals(-code).name}'
        except ValueError:
            return f'signal {-code}'
    return f'code {code}'


class Supervisor:
    """The parent of a fleet of ``len(groups)`` workers (``groups``: their body names)."""

    def __init__(self, groups, argv, stop):
        self.stop, self.workers = stop, []
        self.own_cpu = CpuMeter(os.getpid())
        self.node = rclpy.create_node(NODE_NAME)
        self.logger = self.node.get_logger()
        self._pub = self.node.create_publisher(DiagnosticArray, '/diagnostics', 10)
        blocked = {signal.SIGINT, signal.SIGTERM}
        # a worker inherits this mask and unblocks after setting its handlers (entry.py):
        # a Ctrl-C while its interpreter starts waits for them instead of killing it
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, blocked)
        try:
            for k, names in enumerate(groups):
                self.workers.append(Worker(k, names, argv))
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)
        self.logger.info(
            f'{sum(map(len, groups))} bodies over {len(groups)} processes (pids '
            f'{", ".join(str(w.pid) for w in self.workers)})')

    def start(self):
        """Wait for every worker's report, check the whole fleet, then tell them all to go."""
        waiting = {w.report_pipe: w for w in self.workers}
        with selectors.DefaultSelector() as selector:
            for pipe in waiting:
                selector.register(pipe, selectors.EVENT_READ)
            while waiting and not self.stop.is_set():
                for key, _ in selector.select(timeout=WATCH_PERIOD):
                    worker = waiting.pop(key.fileobj)
                    selector.unregister(key.fileobj)
                    if not worker.read_report():
                        code = worker.proc.wait()
                        raise ConfigurationError(
                            f'worker {worker.index + 1} (bodies {", ".join(worker.names)}) '
                            f'exited with {describe(code)} before its bodies started')
        if self.stop.is_set():
            return
        one_clock_source([n for w in self.workers for n in w.report['clocks']])
        frames = {ns: pair for w in self.workers for ns, pair in w.report['frames'].items()}
        go = json.dumps({'no_tf': shared_frames(frames, self.logger)})
        for worker in self.workers:
            worker.tell(go)

    def watch(self):
        """Until the stop or every worker's death: report deaths, publish /diagnostics."""
        next_diagnostics = time.monotonic()
        while not self.stop.is_set():
            died = [w for w in self.workers if w.death is None and w.proc.poll() is not None]
            for worker in died:
                worker.death = worker.proc.returncode
                self.logger.error(
                    f'worker {worker.index + 1} (pid {worker.pid}) exited with '
                    f'{describe(worker.death)}: bodies {", ".join(worker.names)} are gone')
            if died or time.monotonic() >= next_diagnostics:
                self.publish_diagnostics()
                next_diagnostics = time.monotonic() + DIAGNOSTIC_PERIOD
            if all(w.death is not None for w in self.workers):
                self.logger.error('every worker has exited: the fleet stops')
                return
            self.stop.wait(WATCH_PERIOD)

    def publish_diagnostics(self):
        """One DiagnosticArray: a status per worker, and the fleet's (CPU of all together)."""
        msg = DiagnosticArray()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        hardware_id = self.node.get_fully_qualified_name()
        msg.status = [w.status(hardware_id) for w in self.workers]
        self.own_cpu.read()
        running = [w for w in self.workers if w.death is None]
        cores = [w.cpu.cores for w in running] + [self.own_cpu.cores]
        bodies = sum(len(w.names) for w in self.workers)
        total = None if None in cores else sum(cores)
        values = [('workers', len(self.workers)), ('workers running', len(running)),
                  ('bodies', bodies),
                  ('CPU of the workers and the parent (cores)', _cores(total)),
                  ('CPU per body (% of a core)', _cores(total, bodies)),
                  ('CPU of the parent (cores)', _cores(self.own_cpu.cores))]
        level = DiagnosticStatus.OK if len(running) == len(self.workers) else \
            DiagnosticStatus.ERROR
        msg.status.append(status(f'{NODE_NAME}: fleet', level,
                                 f'{len(running)} of {len(self.workers)} workers running '
                                 f'{bodies} bodies, {_cores(total)} cores', values, hardware_id))
        self._pub.publish(msg)

    def cpu_summary(self):
        """Say what the fleet cost over its run: each worker's cores and all together."""
        for worker in self.workers:
            if worker.death is None:
                worker.cpu.read()
        self.own_cpu.read()
        averages = [w.cpu.average() for w in self.workers]
        own = self.own_cpu.average() or 0.0
        bodies = sum(len(w.names) for w in self.workers)
        every = ', '.join(f'worker {k + 1} {_cores(c)}' for k, c in enumerate(averages))
        total = sum(c for c in averages if c is not None) + own
        return (f'CPU over the run: {total:.3f} cores for {bodies} bodies '
                f'({100.0 * total / max(1, bodies):.2f} % of a core each): {every}, '
                f'the parent {own:.3f}')

    def finish(self):
        """
        Stop every worker (lifeline closed, and SIGINT) and wait; kill one that does not exit.

        Returns the fleet's exit code: 0 if every worker ran until the stop and exited 0,
        else 1.
        """
        summary = self.cpu_summary()
        for worker in self.workers:
            worker.release()
            if worker.proc.poll() is None:
                worker.proc.send_signal(signal.SIGINT)
        deadline = time.monotonic() + EXIT_WAIT
        failed = [w for w in self.workers if w.death is not None]
        for worker in self.workers:
            try:
                code = worker.proc.wait(max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                code = dump_and_kill(worker.proc)
                self.logger.error(f'worker {worker.index + 1} (pid {worker.pid}) did not exit '
                                  f'within {EXIT_WAIT:g} s of the stop: killed (the stacks of its '
                                  'threads are printed above)')
            if worker.death is None and code != 0:
                self.logger.error(f'worker {worker.index + 1} (pid {worker.pid}) exited with '
                                  f'{describe(code)}')
                failed.append(worker)
        self.logger.info(summary)
        self.node.destroy_node()
        return 1 if failed else 0


def supervise(groups, argv, early=None):
    """
    Run a fleet of ``len(groups)`` worker processes until SIGINT / SIGTERM; the exit code.

    0 when every worker ran until the stop and exited 0; 1 when the fleet refused its
    configuration (the reason is logged) or a worker died or failed (each is logged and
    was on /diagnostics).
    """
    stop, restore = stop_on_signals(early)
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    supervisor, code = None, 0
    try:
        if stop.is_set():
            return 0
        supervisor = Supervisor(groups, argv, stop)
        supervisor.start()
        supervisor.watch()
    except ConfigurationError as err:
        rclpy.logging.get_logger(NODE_NAME).fatal(f'cannot start: {err}')
        code = 1
    finally:
        if supervisor is not None:
            code = max(code, supervisor.finish())
        rclpy.try_shutdown()
        restore()
    return code
