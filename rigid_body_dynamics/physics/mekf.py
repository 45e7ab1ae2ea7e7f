"""
A multiplicative extended Kalman filter of the attitude and the gyro bias (no ROS).

The filter of Markley and Crassidis, *Fundamentals of Spacecraft Attitude
Determination and Control*, chapter 6: the attitude q (x, y, z, w, body ->
world) and the gyro bias b (rad/s, body) are estimated; the filter's state is
the error x = (dtheta, db), with the true attitude q = q_est (x) dq(dtheta),
dtheta a small rotation vector in the body frame, and its covariance P (6 x 6,
rad^2 and (rad/s)^2). After each update the error is moved into q and b and
reset to zero: the multiplicative step that keeps q a unit quaternion.

Propagation over dt with the gyro's rate omega_m (the reading at the start of
the interval, held: each reading's white noise then enters one interval, as the
process noise Q counts it), omega = omega_m - b:

    q <- q (x) exp(omega dt / 2)
    Phi = [[R(omega dt)^T, -(I dt - [omega x] dt^2 / 2)], [0, I]]
    Q = [[(N^2 dt + K^2 dt^3 / 3) I, -(K^2 dt^2 / 2) I], [-(K^2 dt^2 / 2) I, K^2 dt I]]

with N the gyro's noise density (rad/s/sqrt(Hz)) and K its bias random walk
(rad/s^2/sqrt(Hz)), the simulator's ``gyro_noise_density`` and
``gyro_bias_random_walk`` (the book's sigma_v and sigma_u, equation 6.93).

Updates: an attitude measurement q_m with covariance R (body frame) has the
residual dtheta_m = 2 vec(q_est^-1 (x) q_m) (as a rotation vector) and H = [I, 0];
a unit vector b_m measured in the body frame of a known world vector r has the
residual b_m - A^T r and H = [[A^T r x], 0], with R = sigma^2 I. P is updated in
Joseph's form, which stays symmetric and positive.
"""

import math

import numpy as np

from . import quaternions as quat


def _cross(v):
    """Return the 3 x 3 matrix [v x] of the cross product."""
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def process_noise(dt, noise_density, bias_walk):
    """Return the 6 x 6 discrete process noise Q over dt (s) (module docstring)."""
    n2, k2 = noise_density ** 2, bias_walk ** 2
    eye = np.eye(3)
    return np.block([[(n2 * dt + k2 * dt ** 3 / 3.0) * eye, -(k2 * dt ** 2 / 2.0) * eye],
                     [-(k2 * dt ** 2 / 2.0) * eye, k2 * dt * eye]])


class MEKF:
    """
    The attitude and gyro-bias filter: start it with :meth:`start`, then propagate and update.

    ``noise_density`` N (rad/s/sqrt(Hz)) and ``bias_walk`` K (rad/s^2/sqrt(Hz))
    are the gyro's, as the filter believes them.
    """

    def __init__(self, noise_density, bias_walk):
        for name, value in (('gyro_noise_density', noise_density),
                            ('gyro_bias_random_walk', bias_walk)):
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f'{name} must be a finite number >= 0, got {value!r}')
        self.noise_density, self.bias_walk = float(noise_density), float(bias_walk)
        self.q = None
        self.bias = np.zeros(3)
        self.P = None

    @property
    def started(self):
        """Whether the filter has an estimate (after :meth:`start`)."""
        return self.q is not None

    def start(self, q, attitude_covariance, bias=(0.0, 0.0, 0.0), bias_sigma=0.0):
        """
        Start from the attitude q (x, y, z, w) and its covariance (3 x 3, rad^2, body frame).

        ``bias`` (rad/s, body) and ``bias_sigma`` (rad/s, 1 sigma per axis) start the
        bias estimate.
        """
        self.q = np.asarray(quat.normalize(np.asarray(q, dtype=float)))
        self.bias = np.array(bias, dtype=float)
        self.P = np.zeros((6, 6))
        self.P[:3, :3] = np.asarray(attitude_covariance, dtype=float)
        self.P[3:, 3:] = np.eye(3) * bias_sigma ** 2

    def propagate(self, omega_measured, dt):
        """Propagate over dt (s) with the measured rate (rad/s, body; bias not removed)."""
        if dt <= 0.0:
            return
        w = np.asarray(omega_measured, dtype=float) - self.bias
        turn = quat.from_rotation_vector(w * dt)
        self.q = np.asarray(quat.normalize(quat.multiply(self.q, np.array(turn))))
        phi = np.eye(6)
        phi[:3, :3] = quat.matrix(turn).T
        phi[:3, 3:] = -(np.eye(3) * dt - _cross(w) * (dt * dt / 2.0))
        self.P = phi @ self.P @ phi.T + process_noise(dt, self.noise_density, self.bias_walk)

    def _update(self, residual, H, R):
        """Apply one update with ``residual`` (m,), ``H`` (m, 6) and ``R`` (m, m)."""
        P = self.P
        S = H @ P @ H.T + R
        K = np.linalg.solve(S, H @ P).T         # P H^T S^-1 (S and P symmetric)
        dx = K @ residual
        ikh = np.eye(6) - K @ H
        self.P = ikh @ P @ ikh.T + K @ R @ K.T
        self.P = 0.5 * (self.P + self.P.T)
        self.q = np.asarray(quat.normalize(quat.multiply(
            self.q, np.array(quat.from_rotation_vector(dx[:3])))))
        self.bias = self.bias + dx[3:]

    def update_attitude(self, q_measured, covariance_body):
        """Update with a measured attitude (x, y, z, w) and its covariance (3 x 3, rad^2, body)."""
        dq = quat.multiply(quat.conjugate(self.q), np.asarray(q_measured, dtype=float))
        residual = quat.to_rotation_vector(dq)
        H = np.hstack([np.eye(3), np.zeros((3, 3))])
        self._update(residual, H, np.asarray(covariance_body, dtype=float))

    def update_vector(self, measured_body, reference_world, variance):
        """
        Update with a direction measured in the body frame of a known world direction.

        ``measured_body`` and ``reference_world``: vectors (normalised here);
        ``variance`` (rad^2) per axis of the measurement's small rotation.
        """
        b = np.asarray(measured_body, dtype=float)
        r = np.asarray(reference_world, dtype=float)
        b, r = b / np.linalg.norm(b), r / np.linalg.norm(r)
        predicted = quat.rotate_inverse(self.q, r)
        H = np.hstack([_cross(predicted), np.zeros((3, 3))])
        self._update(b - predicted, H, np.eye(3) * variance)

    def attitude_covariance_world(self):
        """Return the attitude covariance (3 x 3, rad^2) about the world's fixed axes."""
        a = quat.matrix(self.q)
        return a @ self.P[:3, :3] @ a.T
