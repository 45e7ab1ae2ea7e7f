"""
Console-script entry points that own SIGINT / SIGTERM from the first instant.

Importing numpy, scipy and rclpy takes about half a second; a Ctrl-C then
would raise KeyboardInterrupt in the middle of an import (a traceback, exit
code 130). These functions set their handlers before importing anything
heavy and pass on a signal that came early, so the node exits 0 at any
moment. (``python -m rigid_body_dynamics.nodes.<node>`` imports first and so
is only covered once ``main`` runs.)
"""

import signal


def _guard():
    """Record SIGINT / SIGTERM from now on; returns the list the signals go into."""
    received = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda signum, _frame: received.append(signum))
    return received


def simulator():
    """Entry point of attitude_simulator."""
    early = _guard()
    from .simulator import main
    return main(early=early)


def analyzer():
    """Entry point of attitude_analyzer."""
    early = _guard()
    from .analyzer import main
    return main(early=early)


def poinsot():
    """Entry point of poinsot_visualizer."""
    early = _guard()
    from .poinsot import main
    return main(early=early)


def fleet():
    """Entry point of attitude_fleet."""
    early = _guard()
    from .fleet import main
    return main(early=early)
