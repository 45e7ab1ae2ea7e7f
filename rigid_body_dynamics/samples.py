"""
Odometry and torque messages -> attitude samples in the body frame, for every reader.

The live analyzer (rclpy messages) and the bag reader (rosbags' messages) both
go through these functions; they only read fields, which both kinds of
message have under the same names, so this module imports no ROS.

nav_msgs/Odometry carries the pose in ``header.frame_id`` (the world frame)
and the twist in ``child_frame_id``: an empty child frame or the body frame
means a body-frame rate (REP 103, as attitude_simulator publishes);
``child_frame_id == header.frame_id`` means a world-frame rate, which is
rotated into the body with the sample's own attitude; any other child frame
is not the frame the inertia belongs to and is refused (:class:`FrameError`).
"""

import math

import numpy as np

from . import cdr
from .physics import quaternions
from .physics.quaternions import rotate_components


class FrameError(ValueError):
    """A message in a frame the analysis cannot use; the text says which and why."""


def stamp_ns(stamp):
    """builtin_interfaces/Time -> integer ns (no float seconds since 1970 in between)."""
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def odometry_sample(msg, body_frame=None):
    """
    Return (t_ns, q, omega) from a nav_msgs/Odometry, omega in the body frame.

    ``t_ns`` the header stamp (int ns); q (x, y, z, w) as published (not
    normalised; the analysis drops zero and non-finite ones); omega (rad/s)
    body frame. ``body_frame``: the frame id the inertia belongs to, or None
    to accept any child frame other than the world frame. Raises FrameError
    for a twist in another frame.
    """
    o = msg.pose.pose.orientation
    a = msg.twist.twist.angular
    q = (float(o.x), float(o.y), float(o.z), float(o.w))
    w = (float(a.x), float(a.y), float(a.z))
    child, world = msg.child_frame_id, msg.header.frame_id
    if child and child == world:
        w = _to_body(q, w)
    elif child and body_frame and child != body_frame:
        raise FrameError(f'odom twist is in frame {child[:64]!r}, not in the body frame '
                         f'{body_frame!r} of the inertia nor in the world frame {world[:64]!r}')
    return stamp_ns(msg.header.stamp), q, w


def torque_sample(msg, body_frame=None):
    """
    Return (t_ns, torque) from a geometry_msgs/WrenchStamped in the body frame (N m).

    An empty frame id or ``body_frame`` (or any frame when ``body_frame`` is
    None) is taken as the body frame; anything else raises FrameError.
    """
    frame = msg.header.frame_id
    if frame and body_frame and frame != body_frame:
        raise FrameError(f'applied torque in frame {frame[:64]!r}, not in the body frame '
                         f'{body_frame!r}')
    t = msg.wrench.torque
    return stamp_ns(msg.header.stamp), (float(t.x), float(t.y), float(t.z))


def inertia_tensor(msg):
    """Return ([Ixx, Iyy, Izz, Ixy, Ixz, Iyz] kg m^2, frame id) of an InertiaStamped."""
    i = msg.inertia
    return [i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz], msg.header.frame_id


def _to_body(q, v):
    """R(q)^T v with q normalised here; NaN passes through for the analysis to drop."""
    n = math.sqrt(sum(c * c for c in q))
    if not n > 0.0:
        return (math.nan,) * 3
    return rotate_components((-q[0] / n, -q[1] / n, -q[2] / n, q[3] / n), v)


def odometry_batch(raws, decode, body_frame=None):
    """
    Return (t_ns, q, omega body, dropped) from serialised nav_msgs/Odometry messages.

    The frame rules of :func:`odometry_sample`, applied to a batch read with
    :func:`rigid_body_dynamics.cdr.odometry_arrays`; a batch whose layout
    differs is decoded message by message with ``decode(raw)``. ``dropped``
    counts the messages in another frame. Arrays (N,), (N, 4), (N, 3).
    """
    try:
        t, q, w, world, child = cdr.odometry_arrays(raws)
    except cdr.NotUniform:
        return _one_by_one(raws, decode, body_frame)
    if child and child == world:
        n = np.linalg.norm(q, axis=1)
        with np.errstate(invalid='ignore', divide='ignore'):
            w = quaternions.rotate_inverse(q / n[:, None], w)
    elif child and body_frame and child != body_frame:
        return t[:0], q[:0], w[:0], int(t.size)
    return t, q, w, 0


def _one_by_one(raws, decode, body_frame):
    t, q, w, dropped = [], [], [], 0
    for raw in raws:
        try:
            st, sq, sw = odometry_sample(decode(raw), body_frame)
        except FrameError:
            dropped += 1
            continue
        t.append(st)
        q.append(sq)
        w.append(sw)
    return (np.array(t, dtype=np.int64), np.array(q, dtype=float).reshape(-1, 4),
            np.array(w, dtype=float).reshape(-1, 3), dropped)


def torque_batch(raws, decode, body_frame=None):
    """Return (t_ns, torque body (N, 3) N m, dropped) from serialised WrenchStamped messages."""
    try:
        t, tau, frame = cdr.wrench_arrays(raws)
    except cdr.NotUniform:
        t, tau, dropped = [], [], 0
        for raw in raws:
            try:
                st, vec = torque_sample(decode(raw), body_frame)
            except FrameError:
                dropped += 1
                continue
            t.append(st)
            tau.append(vec)
        return np.array(t, dtype=np.int64), np.array(tau, dtype=float).reshape(-1, 3), dropped
    if frame and body_frame and frame != body_frame:
        return t[:0], tau[:0], int(t.size)
    return t, tau, 0
