"""
Attitude control laws (ROS-free), so a closed loop can run offline and in the node.

A law is a callable ``law(q, omega) -> torque``: q (x, y, z, w) body -> world,
omega (rad/s, body frame), torque (N m, body frame) as a 3-tuple. In
:func:`~rigid_body_dynamics.physics.simulate` it closes the loop with
``torque=lambda t, q, w: law(q, w)``.
"""

import math


class QuaternionPD:
    """
    Quaternion-feedback PD to a fixed target attitude, vector-saturated.

    tau_i = -kp_i s e_i - kd_i omega_i with e the vector part of the body-frame
    error q_target^-1 (x) q and s = sign(e_w) (the shorter way round), gains
    kp_i = 2 I_i wn^2 and kd_i = 2 zeta wn I_i per principal axis (for small
    errors each axis is a second-order system of natural frequency ``wn``
    rad/s and damping ratio ``zeta``, as e_i ~ angle_i / 2). If |tau| exceeds
    ``max_torque`` (N m; 0 = no limit) the vector is scaled down to it,
    keeping its direction. ``moments`` (kg m^2) are those of the body axes.
    """

    def __init__(self, moments, target, natural_frequency, damping_ratio, max_torque=0.0):
        moments = tuple(float(i) for i in moments)
        if len(moments) != 3 or not all(i > 0.0 and math.isfinite(i) for i in moments):
            raise ValueError(f'moments must be three positive numbers, got {moments}')
        norm = math.sqrt(sum(float(c) ** 2 for c in target))
        if not (norm > 0.0 and math.isfinite(norm)):
            raise ValueError(f'target must be a finite non-zero quaternion, got {target}')
        if not (natural_frequency > 0.0 and damping_ratio >= 0.0 and max_torque >= 0.0):
            raise ValueError('natural_frequency must be > 0, damping_ratio and max_torque >= 0')
        self.target = tuple(float(c) / norm for c in target)
        wn, zeta = float(natural_frequency), float(damping_ratio)
        self.kp = tuple(2.0 * i * wn * wn for i in moments)
        self.kd = tuple(2.0 * zeta * wn * i for i in moments)
        self.max_torque = float(max_torque)

    def __call__(self, q, omega):
        """Body torque (N m) for attitude q (x, y, z, w) and body rate omega (rad/s)."""
        tx, ty, tz, tw = self.target
        x, y, z, s = (float(c) for c in q)
        ex = tw * x - tx * s - ty * z + tz * y
        ey = tw * y - ty * s - tz * x + tx * z
        ez = tw * z - tz * s - tx * y + ty * x
        sign = 1.0 if tw * s + tx * x + ty * y + tz * z >= 0.0 else -1.0
        (p1, p2, p3), (d1, d2, d3) = self.kp, self.kd
        w1, w2, w3 = (float(c) for c in omega)
        tau = (-p1 * sign * ex - d1 * w1, -p2 * sign * ey - d2 * w2, -p3 * sign * ez - d3 * w3)
        size = math.sqrt(tau[0] ** 2 + tau[1] ** 2 + tau[2] ** 2)
        if self.max_torque > 0.0 and size > self.max_torque:
            scale = self.max_torque / size
            tau = (tau[0] * scale, tau[1] * scale, tau[2] * scale)
        return tau
