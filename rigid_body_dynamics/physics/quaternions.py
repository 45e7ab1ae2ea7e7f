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
