"""
Euler's equations, quaternion kinematics, kinetic energy and angular momentum.

All vectors are in the principal body frame unless named ``_world``; the
principal moments are ``moments = (I1, I2, I3)`` in kg m^2 in the order of the
body axes. Angular velocity omega is in rad/s, torque in N m, energy in J,
angular momentum in kg m^2/s. Quaternions are Hamilton, scalar-last
(x, y, z, w), body -> world. Arrays broadcast over leading axes.
"""

import numpy as np

from .. import quaternions


def euler_rhs(moments, omega, torque=(0.0, 0.0, 0.0)):
    """
    Angular acceleration d(omega)/dt (rad/s^2, body frame) from Euler's equations.

    Shapiro (4.26): tau_1 = I1 dw1/dt + (I3 - I2) w2 w3 and cyclic, i.e.
    (4.25) tau = I dw/dt + w x (I w) in the principal frame.
    """
    i1, i2, i3 = moments
    w = np.asarray(omega, dtype=float)
    tau = np.asarray(torque, dtype=float)
    w1, w2, w3 = w[..., 0], w[..., 1], w[..., 2]
    return np.stack(np.broadcast_arrays(
        (tau[..., 0] - (i3 - i2) * w2 * w3) / i1,
        (tau[..., 1] - (i1 - i3) * w3 * w1) / i2,
        (tau[..., 2] - (i2 - i1) * w1 * w2) / i3), axis=-1)


def quaternion_rate(q, omega):
    """
    Quaternion derivative dq/dt = 1/2 q (x) (omega, 0) for body-frame omega (rad/s).

    q is body -> world, scalar-last; returns the same shape as q.
    """
    w = np.asarray(omega, dtype=float)
    pure = np.concatenate([w, np.zeros(w.shape[:-1] + (1,))], axis=-1)
    return 0.5 * quaternions.multiply(q, pure)


def angular_momentum_body(moments, omega):
    """Body-frame angular momentum L_b = I omega (kg m^2/s)."""
    return np.asarray(moments, dtype=float) * np.asarray(omega, dtype=float)


def angular_momentum_world(moments, q, omega):
    """World-frame angular momentum L_w = R(q) I omega (kg m^2/s); constant when torque-free."""
    return quaternions.rotate(q, angular_momentum_body(moments, omega))


def kinetic_energy(moments, omega):
    """Rotational kinetic energy T = 1/2 omega . I omega (J), seed (4.13)."""
    w = np.asarray(omega, dtype=float)
    return 0.5 * np.sum(np.asarray(moments, dtype=float) * w * w, axis=-1)


def state_rhs(moments, y, torque=(0.0, 0.0, 0.0)):
    """
    Time derivative of the stacked state y = (omega_1..3, q_x, q_y, q_z, q_w).

    omega is body-frame (rad/s), q body -> world; torque body-frame (N m).
    Used by the ODE-solver paths (DOP853) and as a reference in tests.
    """
    y = np.asarray(y, dtype=float)
    return np.concatenate([euler_rhs(moments, y[..., :3], torque),
                           quaternion_rate(y[..., 3:7], y[..., :3])], axis=-1)
