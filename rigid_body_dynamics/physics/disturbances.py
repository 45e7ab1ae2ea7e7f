"""
Disturbance torques a spacecraft feels (no ROS): the gravity gradient of a circular orbit.

Frames. The world frame is inertial (the simulator's ``world_frame``); the
orbit is a circle in it with rate n (rad/s) about the unit ``orbit_normal``
(world), and ``nadir0`` (world, perpendicular to it) is the direction from
the body to the planet's centre at t = 0. The nadir direction at time t is
``nadir0`` turned by n t about ``orbit_normal``:

    r_w(t) = cos(n t) nadir0 + sin(n t) (orbit_normal x nadir0)

The gravity-gradient torque on a body of inertia I (body frame) whose
attitude is q (body -> world) is

    tau = 3 n^2 r x (I r),    r = R(q)^T r_w(t), the nadir unit vector in the body frame

(n^2 = mu / a^3 for a circular orbit of radius a; Wie, Space Vehicle Dynamics
and Control, section 6.3). It vanishes when a principal axis points at nadir.

Pitch libration (derived for the tests): a body whose principal axes are
aligned with the orbit frame (z along nadir, y along the orbit normal, x along
the velocity) and which turns with it (omega = n about y) is in equilibrium.
Tilt it by a small pitch angle theta about y: r = (-sin theta, 0, cos theta)
in the body, tau_y = -3 n^2 (I_x - I_z) sin theta cos theta, and since the
orbit frame turns at the constant rate n about the same axis,

    I_y theta'' = -3 n^2 (I_x - I_z) theta   ->   omega_pitch = n sqrt(3 (I_x - I_z) / I_y)

stable for I_x > I_z (the axis of least inertia along nadir).
"""

import math

import numpy as np


class GravityGradient:
    """
    The gravity-gradient torque of a circular orbit, as an integrator ``field``.

    ``moments`` (principal, kg m^2); ``orbit_rate`` n (rad/s, > 0);
    ``orbit_normal`` and ``nadir0`` (world frame; normalised, and nadir0 made
    perpendicular to the normal; ValueError if they are parallel or zero).
    Calling it with (t, qx, qy, qz, qw) (s; principal frame -> world) returns
    the principal-frame torque (N m); ``epoch`` (s) is added to t (the
    simulated time at an integrator's time 0).
    """

    def __init__(self, moments, orbit_rate, orbit_normal=(0.0, 1.0, 0.0),
                 nadir0=(0.0, 0.0, 1.0), epoch=0.0):
        if not (orbit_rate > 0.0 and math.isfinite(orbit_rate)):
            raise ValueError(f'orbit_rate must be positive and finite, got {orbit_rate!r}')
        normal = np.asarray(orbit_normal, dtype=float).reshape(3)
        nadir = np.asarray(nadir0, dtype=float).reshape(3)
        if not (np.all(np.isfinite(normal)) and np.linalg.norm(normal) > 0.0):
            raise ValueError(f'orbit_normal must be a finite non-zero vector, got {orbit_normal}')
        normal = normal / np.linalg.norm(normal)
        nadir = nadir - normal * float(normal @ nadir)
        if not (np.all(np.isfinite(nadir)) and np.linalg.norm(nadir) > 1e-9):
            raise ValueError('nadir0 must be finite and not parallel to orbit_normal, got '
                             f'{nadir0}')
        nadir = nadir / np.linalg.norm(nadir)
        self.moments = tuple(float(i) for i in moments)
        self.n = float(orbit_rate)
        self.k = 3.0 * self.n * self.n
        self.nadir0 = tuple(float(c) for c in nadir)
        self.along = tuple(float(c) for c in np.cross(normal, nadir))
        self.normal = tuple(float(c) for c in normal)
        self.epoch = float(epoch)

    def nadir_world(self, t):
        """Return the unit nadir vector in the world frame at time t (s, without the epoch)."""
        c, s = math.cos(self.n * t), math.sin(self.n * t)
        a, b = self.nadir0, self.along
        return (c * a[0] + s * b[0], c * a[1] + s * b[1], c * a[2] + s * b[2])

    def __call__(self, t, qx, qy, qz, qw):
        """Principal-frame torque (N m) at time t (s) and attitude q (principal -> world)."""
        gx, gy, gz = self.nadir_world(t + self.epoch)
        # r = R(q)^T r_w: rotate by the conjugate; q need not be exactly unit (RK stages)
        s = 1.0 / (qx * qx + qy * qy + qz * qz + qw * qw)
        ux = 2.0 * (-qy * gz + qz * gy)
        uy = 2.0 * (-qz * gx + qx * gz)
        uz = 2.0 * (-qx * gy + qy * gx)
        rx = gx + s * (qw * ux - qy * uz + qz * uy)
        ry = gy + s * (qw * uy - qz * ux + qx * uz)
        rz = gz + s * (qw * uz - qx * uy + qy * ux)
        i1, i2, i3 = self.moments
        k = self.k
        return (k * (i3 - i2) * ry * rz, k * (i1 - i3) * rz * rx, k * (i2 - i1) * rx * ry)
