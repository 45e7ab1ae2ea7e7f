"""
Odometry and torque messages -> attitude samples in the body frame, for every reader.

The live analyzer (rclpy) and the bag reader (rosbags) both take serialised
messages and go through these functions: the fields of a batch are read
straight into numpy by :mod:`rigid_body_dynamics.messages.cdr`; a batch whose layout
differs (frame ids of different lengths) is decoded message by message with
the caller's ``decode(raw)`` (rclpy's or rosbags' deserialiser: both messages
have the same field names), and the same frame rules apply. No ROS import.

nav_msgs/Odometry carries the pose in ``header.frame_id`` (the world frame)
and the twist in ``child_frame_id``: an empty child frame or the body frame
means a body-frame rate (REP 103, as attitude_simulator publishes);
``child_frame_id == header.frame_id`` means a world-frame rate, which is
rotated into the body with the sample's own attitude; any other child frame
is not the frame the inertia belongs to: those samples are dropped and counted.
"""

import numpy as np

from . import cdr
from ..physics import quaternions


def stamp_ns(stamp):
    """builtin_interfaces/Time -> integer ns (no float seconds since 1970 in between)."""
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def inertia_tensor(msg):
    """Return ([Ixx, Iyy, Izz, Ixy, Ixz, Iyz] kg m^2, frame id) of an InertiaStamped."""
    i = msg.inertia
    return [i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz], msg.header.frame_id


def _odometry_rule(t, q, w, world, child, body_frame):
    """Apply the twist frame rule to samples of one (world, child): (t, q, omega, dropped)."""
    if child and child == world:
        n = np.linalg.norm(q, axis=1)
        with np.errstate(invalid='ignore', divide='ignore'):   # NaN rows: dropped later
            w = quaternions.rotate_inverse(q / n[:, None], w)
    elif child and body_frame and child != body_frame:
        return t[:0], q[:0], w[:0], int(t.size)
    return t, q, w, 0


def _odometry_fields(msg):
    """(t_ns, q, omega, frame_id, child_frame_id) of one decoded Odometry, as 1-row arrays."""
    o, a = msg.pose.pose.orientation, msg.twist.twist.angular
    return (np.array([stamp_ns(msg.header.stamp)], dtype=np.int64),
            np.array([[o.x, o.y, o.z, o.w]], dtype=float),
            np.array([[a.x, a.y, a.z]], dtype=float), msg.header.frame_id, msg.child_frame_id)


def odometry_batch(raws, decode, body_frame=None):
    """
    Return (t_ns, q, omega body, dropped) from serialised nav_msgs/Odometry messages.

    ``t_ns`` (N,) int64 header stamps; q (N, 4) x-y-z-w as published (not
    normalised: the analysis drops zero and non-finite ones); omega (N, 3)
    rad/s in the body frame. ``body_frame``: the frame id the inertia belongs
    to, or None to accept any child frame but the world frame. ``dropped``
    counts the messages whose twist is in another frame.
    """
    if not raws:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 4)), np.zeros((0, 3)), 0
    try:
        return _odometry_rule(*cdr.odometry_arrays(raws), body_frame)
    except cdr.NotUniform:
        parts = [_odometry_rule(*_odometry_fields(decode(raw)), body_frame) for raw in raws]
    return (np.concatenate([p[0] for p in parts]).astype(np.int64),
            np.concatenate([p[1] for p in parts]).reshape(-1, 4),
            np.concatenate([p[2] for p in parts]).reshape(-1, 3), sum(p[3] for p in parts))


def _torque_rule(t, tau, frame, body_frame):
    """Keep torques in an empty or the body frame (any frame without one); drop the rest."""
    if frame and body_frame and frame != body_frame:
        return t[:0], tau[:0], int(t.size)
    return t, tau, 0


def torque_batch(raws, decode, body_frame=None):
    """Return (t_ns, torque body (N, 3) N m, dropped) from serialised WrenchStamped messages."""
    if not raws:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3)), 0
    try:
        return _torque_rule(*cdr.wrench_arrays(raws), body_frame)
    except cdr.NotUniform:
        parts = []
        for raw in raws:
            msg = decode(raw)
            v = msg.wrench.torque
            parts.append(_torque_rule(np.array([stamp_ns(msg.header.stamp)], dtype=np.int64),
                                      np.array([[v.x, v.y, v.z]], dtype=float),
                                      msg.header.frame_id, body_frame))
    return (np.concatenate([p[0] for p in parts]).astype(np.int64),
            np.concatenate([p[1] for p in parts]).reshape(-1, 3), sum(p[2] for p in parts))


def odometry_translation(raws, decode):
    """
    Return (t_ns, position m world, velocity m/s world) of serialised nav_msgs/Odometry.

    The velocity is the twist's linear part turned into the world frame by the pose's
    orientation (Odometry gives it in the child frame; unchanged where the child
    frame is the world frame). Decoded one by one: an orbit's analysis needs a
    few samples a second.
    """
    t, r, v = [], [], []
    for raw in raws:
        msg = decode(raw)
        p, o, lin = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist.linear
        vec = (lin.x, lin.y, lin.z)
        if msg.child_frame_id != msg.header.frame_id:
            vec = quaternions.rotate_components(_unit((o.x, o.y, o.z, o.w)), vec)
        t.append(stamp_ns(msg.header.stamp))
        r.append((p.x, p.y, p.z))
        v.append(vec)
    return (np.array(t, dtype=np.int64), np.array(r, dtype=float).reshape(-1, 3),
            np.array(v, dtype=float).reshape(-1, 3))


def pose_covariance_batch(raws, decode):
    """
    Return (t_ns, q (N, 4), orientation covariance (N, 3, 3)) of PoseWithCovarianceStamped.

    The orientation covariance is the message's lower right 3 x 3 block (rad^2,
    about the fixed axes of the header's frame). Decoded one by one.
    """
    t, q, cov = [], [], []
    for raw in raws:
        msg = decode(raw)
        o = msg.pose.pose.orientation
        t.append(stamp_ns(msg.header.stamp))
        q.append((o.x, o.y, o.z, o.w))
        cov.append(np.reshape(np.asarray(msg.pose.covariance, dtype=float), (6, 6))[3:, 3:])
    return (np.array(t, dtype=np.int64), np.array(q, dtype=float).reshape(-1, 4),
            np.array(cov, dtype=float).reshape(-1, 3, 3))


def _unit(q):
    n = float(np.linalg.norm(q))
    return tuple(c / n for c in q) if n > 0.0 and np.isfinite(n) else (0.0, 0.0, 0.0, 1.0)
