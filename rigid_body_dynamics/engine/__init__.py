"""
The simulation engine without ROS: one body's state and rules, and its pacing.

:class:`~.body.BodySimulation` (integrator, held / clipped / timed-out
torque command, drift baseline, counters, reset and pause, snapshots at
integer-ns stamps) and :class:`~.pacer.Pace` (real-time or as-fast-as-possible
stepping on the steady clock), or :class:`~.lockstep.Lockstep` (waiting for
the controller's command at every control tick), and :class:`~.loop.Loop`,
one thread driving one pace or many. Commands are values (:mod:`.commands`)
that a pace takes from its inbox and the body checks and holds: one path in
every mode. The nodes in ``nodes/`` (with the
plumbing in ``ros/``) are the ROS side around them.
"""

from .body import BodySimulation, Disturbances, SensorSample, Snapshot, TorqueCommand
from .commands import DipoleCommands, Mailbox, TorqueCommands, WheelCommands
from .lockstep import Lockstep
from .loop import Loop, Member
from .pacer import Pace

__all__ = ['BodySimulation', 'DipoleCommands', 'Disturbances', 'Lockstep', 'Loop', 'Mailbox',
           'Member', 'Pace', 'SensorSample', 'Snapshot', 'TorqueCommand', 'TorqueCommands',
           'WheelCommands']
