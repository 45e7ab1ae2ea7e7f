"""
Command messages -> the engine's command values, and the frame rule of a torque, in one place.

The simulator's integration thread takes the serialised messages pending on
``torque_cmd`` (:class:`~.intake.Intake`) and :class:`TorqueDecoder` turns them
into one :class:`~rigid_body_dynamics.engine.commands.TorqueCommands`: read in one
go with :mod:`rigid_body_dynamics.messages.cdr` when they share a frame id (a flood costs
little), else deserialised one by one; :func:`decode_wheels` turns ``wheel_cmd``
(std_msgs/Float64MultiArray) into :class:`~rigid_body_dynamics.engine.commands.WheelCommands`
and :func:`decode_dipoles` ``magnetorquer_cmd`` into
:class:`~rigid_body_dynamics.engine.commands.DipoleCommands`.
Everything after that (checks, counts, the held command, its timing) is the engine's.
"""

import time

from geometry_msgs.msg import Vector3Stamped, WrenchStamped
from rclpy.serialization import deserialize_message
from std_msgs.msg import Float64MultiArray

from . import conversions as conv
from ..engine.commands import DipoleCommands, TorqueCommands, WheelCommands
from ..messages import cdr


def steady_times(received_system_ns):
    """
    Return receive times on the steady clock, none later than now (int ns).

    ``received_system_ns``: as the middleware stamps them (system clock; 0 = none).
    """
    now = time.monotonic_ns()
    offset = time.time_ns() - now
    return [min(r - offset, now) if r else now for r in received_system_ns]


class TorqueDecoder:
    """
    Decode WrenchStamped torque commands for a body with ``frames`` = (world, body) ids.

    The frame rule: ``''`` or the body frame is the body frame; the world frame
    is the world frame (unless it is also the body frame's name); any other
    frame id is refused.
    """

    def __init__(self, frames):
        self.world_frame, self.body_frame = frames

    def frame(self, frame_id):
        """Return 'body', 'world' or None (refused) for a command's ``frame_id``."""
        if frame_id in ('', self.body_frame):
            return 'body'
        if frame_id == self.world_frame:
            return 'world'
        return None

    def decode(self, raws, received_ns):
        """
        Return (TorqueCommands of the known frames, {refused frame id: count}).

        ``raws``: serialised WrenchStamped, oldest first; ``received_ns`` their
        steady receive times (int ns).
        """
        try:
            stamps, torques, frame_id, forces = cdr.wrench_arrays(raws, force=True)
        except cdr.NotUniform:
            return self._one_by_one(raws, received_ns)
        frame = self.frame(frame_id)
        if frame is None:
            return TorqueCommands([], []), {frame_id: len(raws)}
        return TorqueCommands(received_ns, torques, frame == 'world', stamps.tolist(),
                              forces), {}

    def _one_by_one(self, raws, received_ns):
        refused, kept = {}, []
        for raw, at in zip(raws, received_ns):
            msg = deserialize_message(raw, WrenchStamped)
            frame = self.frame(msg.header.frame_id)
            if frame is None:
                refused[msg.header.frame_id] = refused.get(msg.header.frame_id, 0) + 1
            else:
                kept.append((at, msg, frame == 'world'))
        return TorqueCommands(
            [k[0] for k in kept], [conv.vector_array(k[1].wrench.torque) for k in kept],
            [k[2] for k in kept], [conv.time_ns(k[1].header.stamp) for k in kept],
            [conv.vector_array(k[1].wrench.force) for k in kept]), refused


def decode_dipoles(raws, received_ns, body_frame):
    """
    Return (DipoleCommands, refused count) of serialised geometry_msgs/Vector3Stamped ``raws``.

    A magnetorquer command's frame_id must be ``body_frame`` or "" (the rods are
    fixed in the body); any other is refused and counted. ``received_ns``: steady
    receive times (int ns), oldest first.
    """
    kept, refused = [], 0
    for raw, at in zip(raws, received_ns):
        msg = deserialize_message(raw, Vector3Stamped)
        if msg.header.frame_id not in ('', body_frame):
            refused += 1
            continue
        kept.append((at, conv.vector_array(msg.vector).tolist(), conv.time_ns(msg.header.stamp)))
    return DipoleCommands([k[0] for k in kept], [k[1] for k in kept],
                          [k[2] for k in kept]), refused


def decode_wheels(raws, received_ns):
    """
    Return the WheelCommands of serialised std_msgs/Float64MultiArray ``raws``.

    Each message's ``data`` is one command (n motor torques, N m); its layout is not
    read. ``received_ns``: steady receive times (int ns), oldest first.
    """
    return WheelCommands(list(received_ns),
                         [tuple(deserialize_message(raw, Float64MultiArray).data)
                          for raw in raws])
