"""
Hamilton quaternion algebra, scalar-last (x, y, z, w).

Conventions (REP 103, as geometry_msgs and scipy): quaternions are Hamilton (i j = k), unit,
and *active*: q rotates body-frame vectors into the world frame,
``v_world = q (x) v_body (x) conj(q)``. This is scipy's
``Rotation.from_quat`` convention, which the tests use as ground truth.

Every function works on arrays of shape ``(..., 4)`` / ``(..., 3)`` and
broadcasts. Hot loops use the component kernels ``mul_components`` and
``rotate_components``, which take and return plain tuples of floats (or of
equally shaped arrays) and so avoid numpy's per-call overhead on 3-vectors.
"""

import math

import numpy as np


def mul_components(a, b):
    """
    Hamilton product a (x) b on component tuples (x, y, z, w).

    Components may be floats or broadcastable arrays. Returns a 4-tuple.
    """
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by + ay * bw + az * bx - ax * bz,
            aw * bz + az * bw + ax * by - ay * bx,
            aw * bw - ax * bx - ay * by - az * bz)


def rotate_components(q, v):
    """
    Rotate vector components v = (vx, vy, vz) by the unit quaternion q.

    Returns R(q) v as a 3-tuple (body -> world when q is an attitude).
    Uses v' = v + 2 w (u x v) + 2 u x (u x v), u = vector part of q.
    """
    x, y, z, w = q
    vx, vy, vz = v
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (vx + w * tx + y * tz - z * ty,
            vy + w * ty + z * tx - x * tz,
            vz + w * tz + x * ty - y * tx)


def multiply(a, b):
    """Hamilton product of quaternion arrays (..., 4), scalar-last."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return np.stack(mul_components(np.moveaxis(a, -1, 0), np.moveaxis(b, -1, 0)), axis=-1)


def conjugate(q):
    """Conjugate (inverse of a unit quaternion), arrays (..., 4)."""
    q = np.array(q, dtype=float)
    q[..., :3] *= -1.0
    return q


def rotate(q, v):
    """
    Rotate vectors v (..., 3) by unit quaternions q (..., 4).

    For an attitude q (body -> world) this maps body-frame components to
    world-frame components: returns R(q) v.
    """
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    out = rotate_components(np.moveaxis(q, -1, 0), np.moveaxis(v, -1, 0))
    return np.stack(np.broadcast_arrays(*out), axis=-1)


def rotate_inverse(q, v):
    """Rotate vectors v (..., 3) by the inverse of q: returns R(q)^T v (world -> body)."""
    return rotate(conjugate(q), v)


def normalize(q):
    """Return q / |q| for arrays (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q / np.sqrt(np.sum(q * q, axis=-1, keepdims=True))


def from_axis_angle(axis, angle):
    """
    Quaternion of a rotation by ``angle`` (rad) about the unit vector ``axis``.

    ``axis`` has shape (3,) or (..., 3); ``angle`` broadcasts against it.
    """
    axis = np.asarray(axis, dtype=float)
    half = 0.5 * np.asarray(angle, dtype=float)
    s = np.sin(half)[..., None]
    return np.concatenate([axis * s, np.cos(half)[..., None]], axis=-1)


def angle_between(q1, q2):
    """
    Rotation angle (rad, in [0, pi]) of q1^-1 q2, i.e. the attitude error.

    Insensitive to the sign ambiguity q ~ -q. Uses atan2 for accuracy near 0.
    """
    d = multiply(conjugate(q1), q2)
    vec = np.sqrt(np.sum(d[..., :3] ** 2, axis=-1))
    return 2.0 * np.arctan2(vec, np.abs(d[..., 3]))


def from_rotation_vector(v):
    """
    Quaternion (x, y, z, w) of the rotation vector ``v`` (rad; axis times angle), as a tuple.

    exp(v / 2) for one vector (3,), in scalar arithmetic (a sensor draws one per
    reading); accurate to round-off at small angles (the sinc is a series there).
    """
    x, y, z = (float(c) for c in v)
    angle2 = x * x + y * y + z * z
    if angle2 < 1e-12:          # sin(a/2)/a = 1/2 - a^2/48 + ..., cos(a/2) = 1 - a^2/8 + ...
        s, c = 0.5 - angle2 / 48.0, 1.0 - angle2 / 8.0 + angle2 * angle2 / 384.0
    else:
        angle = angle2 ** 0.5
        s, c = math.sin(0.5 * angle) / angle, math.cos(0.5 * angle)
    return (s * x, s * y, s * z, c)


def to_rotation_vector(q):
    """
    Rotation vector (rad; axis times angle, angle in [0, pi]) of quaternions q (..., 4).

    The inverse of :func:`from_rotation_vector`, insensitive to the sign q ~ -q.
    """
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., 3:4] < 0.0, -q, q)
    vec = np.sqrt(np.sum(q[..., :3] ** 2, axis=-1, keepdims=True))
    angle = 2.0 * np.arctan2(vec, q[..., 3:4])
    scale = np.where(vec > 1e-300, angle / np.where(vec > 1e-300, vec, 1.0), 2.0)
    return q[..., :3] * scale


def matrix(q):
    """Return the 3 x 3 rotation R of a unit quaternion (x, y, z, w): v_world = R v_body."""
    x, y, z, w = (float(c) for c in q)
    return np.array([
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)]])
