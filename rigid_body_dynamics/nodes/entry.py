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


def _entry(module, executable):
    """Make the console entry point of ``executable``: guard first, then import ``module``."""
    def entry():
        early = _guard()
        return importlib.import_module(f'{__package__}.{module}').main(early=early)
    entry.__doc__ = f'Entry point of {executable}.'
    return entry


simulator = _entry('simulator', 'attitude_simulator')
analyzer = _entry('analyzer', 'attitude_analyzer')
poinsot = _entry('poinsot', 'poinsot_visualizer')
fleet = _entry('fleet', 'attitude_fleet')
controller = _entry('controller', 'attitude_controller')
estimator = _entry('estimator', 'attitude_estimator')
