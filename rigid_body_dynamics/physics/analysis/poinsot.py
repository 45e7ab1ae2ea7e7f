"""
The Poinsot construction at one instant, in the world frame.

Shapiro, *Classical Mechanics*, section 4.4.1.

The inertia ellipsoid omega . I omega = 2T (semi-axes sqrt(2T / I_i) along the
principal axes, rad/s) is fixed in the body; omega's tip lies on it and on the
invariant plane omega . L_hat = 2T / |L|, which it touches there (the
ellipsoid's normal at omega is along I omega = L). The ellipsoid rolls on the
plane without slipping; omega traces the polhode on the ellipsoid (body frame)
and the herpolhode on the plane (world frame).
"""

from dataclasses import dataclass

import numpy as np

from .. import quaternions
from ..dynamics import equations


@dataclass(frozen=True)
class PoinsotConstruction:
    """
    Geometry at one instant; vectors in the world frame, lengths in rad/s.

    ``semi_axes`` along the principal axes, ``orientation`` (x, y, z, w) of the
    ellipsoid (= the principal frame's attitude), ``omega`` and ``normal``
    (L_hat) world vectors, ``distance`` = 2T / |L| of the plane from the origin.
    """

    semi_axes: np.ndarray
    orientation: np.ndarray
    omega: np.ndarray
    normal: np.ndarray
    distance: float


def construction(moments, q, omega):
    """
    Poinsot geometry from principal moments (kg m^2), attitude q and body omega (rad/s).

    ``q`` (x, y, z, w) is the principal frame's attitude (body -> world) and
    ``omega`` is in that frame. Raises ValueError for a body at rest (no
    ellipsoid: T = 0).
    """
    m = np.asarray(moments, dtype=float)
    w = np.asarray(omega, dtype=float)
    energy = float(equations.kinetic_energy(m, w))
    if energy <= 0.0:
        raise ValueError('a body at rest has no Poinsot construction (T = 0)')
    l_world = quaternions.rotate(q, m * w)
    g = float(np.linalg.norm(l_world))
    return PoinsotConstruction(semi_axes=np.sqrt(2.0 * energy / m),
                               orientation=np.asarray(q, dtype=float),
                               omega=quaternions.rotate(q, w), normal=l_world / g,
                               distance=2.0 * energy / g)


def ellipsoid_surface(semi_axes, n=30):
    """
    Mesh (x, y, z), each (n // 2, n), of the ellipsoid with these semi-axes along x, y, z.

    For drawing: the inertia ellipsoid (``construction(...).semi_axes``, rad/s, body
    frame) or a sphere of radius |L| (three equal semi-axes).
    """
    a = np.asarray(semi_axes, dtype=float)
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n), np.linspace(0, np.pi, n // 2))
    return a[0] * np.cos(u) * np.sin(v), a[1] * np.sin(u) * np.sin(v), a[2] * np.cos(v)


def plane_orientation(normal):
    """Quaternion (x, y, z, w) turning +z onto the unit vector ``normal`` (minimal rotation)."""
    n = np.asarray(normal, dtype=float)
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(z, n)
    s = np.linalg.norm(axis)
    angle = np.arctan2(s, float(n @ z))
    if s < 1e-15:
        return np.array([1.0, 0.0, 0.0, 0.0]) if n[2] < 0.0 else np.array([0.0, 0.0, 0.0, 1.0])
    return quaternions.from_axis_angle(axis / s, angle)
