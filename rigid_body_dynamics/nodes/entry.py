"""
Console-script entry points that own SIGINT / SIGTERM from the first instant.

Importing numpy, scipy and rclpy takes about half a second; a Ctrl-C then
would raise KeyboardInterrupt in the middle of an import (a traceback, exit
code 130). These functions set their handlers before importing anything
heavy and pass on a signal that came early, so the node exits 0 at any
moment. (``python -m rigid_body_dynamics.nodes.<node>`` imports first and so
is only covered once ``main`` runs.)
"""

import importlib
import signal


def _guard():
    """Record SIGINT / SIGTERM from now on; returns the list the signals go into."""
    received = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda signum, _frame: received.append(signum))
    # a fleet's worker starts with both blocked (fleet_supervisor.py): one that came while
    # this interpreter started is delivered now, to the handler
    signal.pthread_sigmask(signal.SIG_UNBLOCK, (signal.SIGINT, signal.SIGTERM))
    return received


def exiting(code):
    """
    Ignore SIGINT and SIGTERM from now on, and return ``code``: the process is ending.

    A process on its way out that gets one more signal (a Ctrl-C reaches a fleet's
    parent and its workers at once, and the parent then stops each worker too) would
    otherwise die of it: Python's finalisation puts the default action back on the
    signals it handled, and Fast DDS's teardown can take a second. SIGKILL still works.
    Call it in a process's main only, never where the process goes on (a test).
    """
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_IGN)
    return code


def _entry(module, executable):
    """Make the console entry point of ``executable``: guard first, then import ``module``."""
    def entry():
        early = _guard()
        return exiting(importlib.import_module(f'{__package__}.{module}').main(early=early))
    entry.__doc__ = f'Entry point of {executable}.'
    return entry


simulator = _entry('simulator', 'attitude_simulator')
analyzer = _entry('analyzer', 'attitude_analyzer')
poinsot = _entry('poinsot', 'poinsot_visualizer')
fleet = _entry('fleet', 'attitude_fleet')
controller = _entry('controller', 'attitude_controller')
estimator = _entry('estimator', 'attitude_estimator')
