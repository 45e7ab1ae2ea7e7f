"""
Run a node as a process: clean exit on Ctrl-C / SIGTERM, exit code 1 on bad configuration.

rclpy's own SIGINT handling raises KeyboardInterrupt wherever the main
thread happens to be, inside a garbage-collector finalizer included ("Exception
ignored in Task.__del__" on stderr), and can race a message take against the
context shutdown. Here the signals only set a flag; the main thread sleeps and
checks it, then wakes the executor thread and waits for it, so shutdown always
happens between callbacks.
"""

import faulthandler
import gc
import signal
import threading
import time

import rclpy
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions

from .parameters import ConfigurationError

#: Longest time between two looks at the stop flag (s).
SLICE = 0.1
#: Longest time the executor waits for work before it looks at the flag itself (s): none.
#: Every wake rebuilds the executor's wait set in Python (0.3 ms per node), and in a fleet
#: of 48 bodies each 2 s timeout cost the integration thread 20-40 ms of steps (late steps
#: on every body, every 2 s); stopping wakes it through a guard condition instead.
IDLE_TIMEOUT = None


def _spin(nodes, stop):
    """
    Spin ``nodes`` on an executor thread until ``stop`` is set; the main thread waits.

    The main thread sleeps in SLICE steps (a signal handler runs at once and
    only sets ``stop``), then wakes the executor through a guard condition;
    the executor itself waits for work without a timeout, so an idle node
    does not rebuild its wait set ten times a second (0.3 ms per node each
    time, holding the interpreter). An exception raised in a callback ends
    the spinning and is raised here.
    """
    executor = SingleThreadedExecutor()
    for each in nodes:
        executor.add_node(each)
    wake = nodes[0].create_guard_condition(lambda: None)
    failure = []

    def spin():
        try:
            while not stop.is_set() and rclpy.ok():
                executor.spin_once(timeout_sec=IDLE_TIMEOUT)
        except BaseException as err:  # handed to the main thread
            failure.append(err)
        finally:
            stop.set()
    thread = threading.Thread(target=spin, name='executor')
    thread.start()
    while not stop.is_set():
        time.sleep(SLICE)
    wake.trigger()
    thread.join()
    nodes[0].destroy_guard_condition(wake)
    # destroy the executor's guard conditions now, while the context is alive: left to
    # its __del__ they may be collected after the shutdown ("Exception ignored in
    # Executor.__del__", seen at SIGTERM)
    executor.shutdown(timeout_sec=1.0)
    if failure:
        raise failure[0]


class Stop:
    """
    The stop flag of a process: set by a signal handler, by another thread, or both at once.

    A signal handler runs in the main thread between two bytecodes, possibly inside a
    ``threading.Event.set()`` that the main thread is already running (its condition's lock
    held): a second signal that called ``set()`` there waited for that lock for ever (a fleet
    worker stopped by SIGINT and, at once, by its closed lifeline's SIGTERM did not exit).
    So the handler only stores an attribute; :meth:`is_set` and :meth:`wait` see it.
    """

    def __init__(self):
        self._event = threading.Event()
        self.signalled = False

    def on_signal(self, *_):
        """Signal handler: no lock, no call into threading."""
        self.signalled = True

    def set(self):  # noqa: A003 (the threading.Event interface)
        """Stop (from a thread, not a signal handler)."""
        self._event.set()

    def is_set(self):
        """Return whether the stop came (a signal or :meth:`set`)."""
        return self.signalled or self._event.is_set()

    def wait(self, timeout):
        """Wait up to ``timeout`` s for the stop (a signal is seen within SLICE s); is_set()."""
        end = time.monotonic() + timeout
        while not self.is_set():
            left = end - time.monotonic()
            if left <= 0.0:
                return False
            self._event.wait(min(left, SLICE))
        return True


def stop_on_signals(early=None):
    """
    Make SIGINT / SIGTERM set the returned :class:`Stop` (set already if ``early`` holds one).

    Returns (stop, restore): ``restore()`` puts the previous handlers back. SIGUSR1 prints
    the Python stack of every thread to stderr (faulthandler), so a process that does not
    stop can say where it is (``ros.client.dump_and_kill``); that stays after ``restore()``,
    for a process that hangs on its way out.
    """
    faulthandler.register(signal.SIGUSR1, all_threads=True)
    stop = Stop()
    previous = {sig: signal.signal(sig, stop.on_signal)
                for sig in (signal.SIGINT, signal.SIGTERM)}
    if early:
        stop.set()

    def restore():
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return stop, restore


def settle_heap():
    """
    Collect once, then keep what start-up made out of every later collection (gc.freeze).

    A full collection traverses every object the collector tracks, with every thread of
    the process stopped: in a 48-body fleet (120 000 objects after start-up: modules,
    nodes, message types) one took 70-90 ms, and every body's steps in it were late. The
    objects made at start-up live as long as the process, so they are frozen after one
    collection; later collections traverse only what was made since.
    """
    gc.collect()
    gc.freeze()


def run(make_node, name, args=None, on_start=None, on_stop=None, early=None):
    """
    Create the node with ``make_node()`` and spin it until SIGINT / SIGTERM.

    ``make_node()`` may also return an object whose ``nodes`` attribute lists
    several nodes (attitude_fleet); one executor then serves them all.
    ``on_start(node)`` / ``on_stop(node)`` run after creation / before
    destruction. ``early``: signals already received by an entry point (see
    ``entry.py``); if any, the node stops at once. Returns the process exit
    code: 0, or 1 when the node refused its configuration (the reason is
    logged).
    """
    stop, restore = stop_on_signals(early)
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = None
    code = 0
    try:
        if stop.is_set():
            return code
        node = make_node()
        settle_heap()
        if on_start and not stop.is_set():
            on_start(node)
        _spin(getattr(node, 'nodes', [node]), stop)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except (ConfigurationError, InvalidParameterValueException,
            InvalidParameterTypeException) as err:
        rclpy.logging.get_logger(name).fatal(f'cannot start: {err}')
        code = 1
    finally:
        if node is not None:
            if on_stop:
                on_stop(node)
            for each in getattr(node, 'nodes', [node]):
                each.destroy_node()
        rclpy.try_shutdown()
        restore()
    return code
