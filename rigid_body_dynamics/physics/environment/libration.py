"""
Gravity-gradient libration and the Jacobi integral of a body in a circular orbit (no ROS).

Frames. LVLH (:mod:`.orbit`): z nadir, y minus the orbit normal, x = y x z; roll,
pitch and yaw are small rotations about LVLH x, y and z. The body's principal
axes 1, 2, 3 are taken along LVLH x, y, z at equilibrium (the body turning with
the orbit at rate n), ``moments`` = (I_x, I_y, I_z) in that order (kg m^2); n
the orbit rate (rad/s).

Linearised about that equilibrium (Wie, Space Vehicle Dynamics and Control,
section 6.3), pitch decouples:

    I_y theta'' + 3 n^2 (I_x - I_z) theta = 0  ->  omega_pitch = n sqrt(3 (I_x - I_z) / I_y)

and roll-yaw are coupled, with characteristic equation

    s^4 + (1 + 3 k1 + k1 k3) n^2 s^2 + 4 k1 k3 n^4 = 0,
    k1 = (I_y - I_z) / I_x,  k3 = (I_y - I_x) / I_z,

so omega^2 = n^2 (b +- sqrt(b^2 - 16 k1 k3)) / 2 with b = 1 + 3 k1 + k1 k3. The
attitude is stable (to first order) when I_x > I_z (pitch) and k1 k3 > 0, b > 0,
b^2 > 16 k1 k3 (roll-yaw). The Lagrange region I_y > I_x > I_z (k1 > k3 > 0) is
stable in the strict sense (the Jacobi integral below is a Lyapunov function
there); the DeBra-Delp region (k1 < 0, k3 < 0 and the roll-yaw conditions) is
stable only to first order.

The Jacobi integral (Hughes, Spacecraft Attitude Dynamics) is constant under
the gravity gradient alone in a circular orbit, at any attitude:

    E = 1/2 w_r . I w_r - 1/2 n^2 h_B . I h_B + 3/2 n^2 r_B . I r_B,   w_r = omega - n h_B

with h_B the orbit normal (r x v / norm(r x v)) and r_B the radial unit vector, both in
the body frame, omega (rad/s) the body's angular velocity in the body frame.
"""

from dataclasses import dataclass
import math

import numpy as np


@dataclass(frozen=True)
class LibrationModes:
    """
    The small-angle libration of a gravity-gradient body about LVLH, by theory.

    ``pitch`` (rad/s; None if pitch is unstable), ``roll_yaw`` (two rad/s, the
    slower first; None if roll-yaw is unstable), ``k1``, ``k3``, and ``region``:
    'Lagrange', 'DeBra-Delp' or 'unstable'.
    """

    pitch: object
    roll_yaw: object
    k1: float
    k3: float
    region: str

    @property
    def stable(self):
        """Whether both pitch and roll-yaw are stable to first order."""
        return self.pitch is not None and self.roll_yaw is not None


def libration_modes(moments, n):
    """Return the :class:`LibrationModes` of principal ``moments`` (I_x, I_y, I_z) at rate n."""
    ix, iy, iz = (float(i) for i in moments)
    k1, k3 = (iy - iz) / ix, (iy - ix) / iz
    pitch = n * math.sqrt(3.0 * (ix - iz) / iy) if ix > iz else None
    b = 1.0 + 3.0 * k1 + k1 * k3
    disc = b * b - 16.0 * k1 * k3
    roll_yaw = None
    if k1 * k3 > 0.0 and b > 0.0 and disc > 0.0:
        root = math.sqrt(disc)
        roll_yaw = (n * math.sqrt(0.5 * (b - root)), n * math.sqrt(0.5 * (b + root)))
    if pitch is None or roll_yaw is None:
        region = 'unstable'
    elif k1 > k3 > 0.0:
        region = 'Lagrange'
    else:
        region = 'DeBra-Delp'
    return LibrationModes(pitch, roll_yaw, k1, k3, region)


def jacobi_integral(moments, n, omega, normal_body, radial_body):
    """
    Return the Jacobi integral E (J) at each sample; arrays broadcast over leading axes.

    ``moments`` principal (kg m^2), ``n`` (rad/s), ``omega`` (rad/s), the unit orbit
    normal ``normal_body`` and radial ``radial_body`` vectors, all in the principal frame.
    """
    i = np.asarray(moments, dtype=float)
    h = np.asarray(normal_body, dtype=float)
    r = np.asarray(radial_body, dtype=float)
    w_r = np.asarray(omega, dtype=float) - n * h
    return 0.5 * np.sum(i * w_r * w_r, axis=-1) - 0.5 * n * n * np.sum(i * h * h, axis=-1) \
        + 1.5 * n * n * np.sum(i * r * r, axis=-1)


def oscillation_frequencies(t, signals, modes):
    """
    Return the ``modes`` angular frequencies (rad/s, ascending) in uniformly sampled signals.

    ``t`` (N,) s, equally spaced; ``signals`` (K, N), each a sum of the same ``modes``
    undamped sinusoids (different amplitudes and phases). By the shift invariance of
    the signals' Hankel matrix (ESPRIT): exact for noise-free sums of sinusoids, whatever
    the window's length against their periods. None if the data cannot carry them.
    """
    x = np.atleast_2d(np.asarray(signals, dtype=float))
    t = np.asarray(t, dtype=float)
    n = x.shape[1]
    rank = 2 * modes
    if n < 4 * rank:
        return None
    dt = (t[-1] - t[0]) / (n - 1)
    pencil = min(n // 3, 200)
    cols = n - pencil + 1
    hankel = np.hstack([np.lib.stride_tricks.sliding_window_view(row, cols) for row in x])
    u = np.linalg.svd(hankel, full_matrices=False)[0][:, :rank]
    phi = np.linalg.lstsq(u[:-1], u[1:], rcond=None)[0]
    angles = np.abs(np.angle(np.linalg.eigvals(phi))) / dt
    return np.sort(angles)[::2][:modes] if modes else np.array([])
