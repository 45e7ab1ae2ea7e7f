"""
The simulation engine without ROS: one body's state and rules, and its pacing.

:class:`~.body.BodySimulation` (integrator, held / clipped / timed-out
torque command, drift baseline, counters, reset and pause, snapshots at
integer-ns stamps) and :class:`~.pacer.Pace` (real-time or as-fast-as-possible
stepping on the steady clock). The nodes in ``nodes/`` are the ROS plumbing
around them.
"""

from .body import BodySimulation, ImuSample, Snapshot, TorqueCommand
from .pacer import Pace

__all__ = ['BodySimulation', 'ImuSample', 'Pace', 'Snapshot', 'TorqueCommand']
