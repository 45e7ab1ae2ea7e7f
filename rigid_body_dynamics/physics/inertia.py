"""
Principal moments and axes of a rigid body: validation and frame changes.

Units: kg m^2. The *body frame* is the frame the user describes the body in;
the *principal frame* is the frame of the principal axes. When the body is
given by three principal moments the two frames coincide; when it is given by a
full tensor, :meth:`Inertia.from_tensor` diagonalises it and keeps the proper
rotation between them so that results can be reported in the user's frame.
"""

from dataclasses import dataclass
import itertools
import math

import numpy as np
from scipy.spatial.transform import Rotation

from . import quaternions

#: Two moments closer than this (relative to the largest) count as equal.
EQUAL_MOMENT_RTOL = 1e-12


def validate_moments(moments):
    """
    Check three principal moments (kg m^2) and return them as a float array.

    Raises ValueError, saying why, for a wrong count, non-finite or
    non-positive values, or a violation of the triangle inequalities
    I1 + I2 >= I3 (and permutations; equality, a flat lamina, is allowed up to
    rounding).
    """
    try:
        m = np.array(moments, dtype=float).reshape(-1)
    except (TypeError, ValueError) as err:
        raise ValueError(f'principal moments must be three numbers, got {moments!r}') from err
    if m.size != 3:
        raise ValueError(f'principal moments must be three numbers, got {m.size}')
    if not np.all(np.isfinite(m)):
        raise ValueError(f'principal moments must be finite, got {m.tolist()}')
    if np.any(m <= 0.0):
        raise ValueError(f'principal moments must be positive, got {m.tolist()}')
    slack = 8.0 * np.finfo(float).eps * m.sum()
    for i in range(3):
        others = m.sum() - m[i]
        if others + slack < m[i]:
            raise ValueError(
                f'principal moments {m.tolist()} violate the triangle inequality: '
                f'I{(i + 1) % 3 + 1} + I{(i + 2) % 3 + 1} = {others:g} < I{i + 1} = {m[i]:g}; '
                'no real mass distribution has these moments')
    return m


def tensor_from_six(values):
    """
    Build the symmetric 3x3 tensor from [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (kg m^2).

    The six numbers are tensor *elements*, as in URDF and
    geometry_msgs/Inertia: Ixy = -sum(m x y), not the product of inertia.
    """
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.size != 6:
        raise ValueError('an inertia tensor needs 6 numbers [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], '
                         f'got {v.size}')
    ixx, iyy, izz, ixy, ixz, iyz = v
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


@dataclass(frozen=True)
class AxisPermutation:
    """
    A proper signed permutation taking a body frame to a frame whose moments ascend.

    ``v_sorted[i] = signs[i] * v[order[i]]``. The signs make the permutation a
    rotation (determinant +1), so handedness, cross products and quaternion
    kinematics are unchanged. ``quaternion`` (x, y, z, w) rotates
    sorted-frame vectors into the original frame.
    """

    order: tuple
    signs: tuple
    quaternion: tuple

    @classmethod
    def ascending(cls, moments):
        """Build the permutation that puts ``moments`` in ascending order (stable for ties)."""
        order = tuple(int(i) for i in np.argsort(np.asarray(moments, dtype=float), kind='stable'))
        parity = 1.0
        for a, b in itertools.combinations(range(3), 2):
            if order[a] > order[b]:
                parity = -parity
        signs = (1.0, 1.0, parity)
        matrix = np.zeros((3, 3))
        for i in range(3):
            matrix[i, order[i]] = signs[i]
        quat = Rotation.from_matrix(matrix.T).as_quat()
        return cls(order, signs, tuple(float(c) for c in quat))

    def sorted_moments(self, moments):
        """Return the moments (a tensor's diagonal, no signs) in ascending order."""
        return tuple(float(moments[i]) for i in self.order)

    def to_sorted(self, v):
        """Components of a vector (tuple) in the sorted frame."""
        o, s = self.order, self.signs
        return (s[0] * v[o[0]], s[1] * v[o[1]], s[2] * v[o[2]])

    def from_sorted(self, v):
        """Components in the original frame of a sorted-frame vector (tuple)."""
        out = [0.0, 0.0, 0.0]
        for i in range(3):
            out[self.order[i]] = self.signs[i] * v[i]
        return tuple(out)


class Inertia:
    """
    Principal moments of inertia (kg m^2) and principal axes of a rigid body.

    ``Inertia(moments)``: the body frame is the principal frame and
    ``moments`` keeps the order given. ``Inertia.from_tensor(matrix)``: the
    moments ascend and ``rotation`` is the proper rotation matrix taking
    principal-frame components to body-frame components
    (``v_body = rotation @ v_principal``).

    Invalid input raises ValueError with the reason.
    """

    def __init__(self, moments, rotation=None):
        self.moments = validate_moments(moments)
        self.moments.setflags(write=False)
        if rotation is None:
            rotation = np.eye(3)
        rotation = np.array(rotation, dtype=float)
        if rotation.shape != (3, 3) or np.linalg.det(rotation) < 0.0 \
                or not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-12):
            raise ValueError('rotation must be a proper 3x3 rotation matrix')
        #: Quaternion (x, y, z, w) of ``rotation``: principal -> body.
        self.quaternion = Rotation.from_matrix(rotation).as_quat()
        # Read-only from here on, so it is made read-only after the library
        # calls: scipy < 1.12 refuses read-only arrays (Cython memoryviews).
        rotation.setflags(write=False)
        self.rotation = rotation
        self._identity = bool(np.array_equal(rotation, np.eye(3)))

    @classmethod
    def from_tensor(cls, matrix):
        """
        Diagonalise a symmetric, positive-definite inertia tensor given in the body frame.

        ``matrix`` is 3x3 or the six elements [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]
        (see :func:`tensor_from_six`). Raises ValueError if it is not finite,
        not symmetric, not positive definite, or violates the triangle
        inequalities.
        """
        t = np.asarray(matrix, dtype=float)
        if t.size == 6:
            t = tensor_from_six(t)
        if t.shape != (3, 3):
            raise ValueError(f'an inertia tensor must be 3x3 or 6 numbers, got shape {t.shape}')
        if not np.all(np.isfinite(t)):
            raise ValueError('inertia tensor must be finite')
        scale = np.max(np.abs(t))
        if not np.allclose(t, t.T, rtol=0.0, atol=1e-12 * scale):
            raise ValueError(f'inertia tensor must be symmetric, got {t.tolist()}')
        values, vectors = np.linalg.eigh(0.5 * (t + t.T))
        if np.any(values <= 0.0):
            raise ValueError('inertia tensor must be positive definite; '
                             f'eigenvalues {values.tolist()}')
        if np.linalg.det(vectors) < 0.0:
            vectors[:, 2] *= -1.0
        return cls(values, vectors)

    @property
    def tensor(self):
        """Return the inertia tensor in the body frame (3x3, kg m^2)."""
        return self.rotation @ np.diag(self.moments) @ self.rotation.T

    @property
    def is_spherical(self):
        """Tell whether all three moments are equal (relative tolerance EQUAL_MOMENT_RTOL)."""
        lo, hi = min(self.moments), max(self.moments)
        return hi - lo <= EQUAL_MOMENT_RTOL * hi

    @property
    def symmetry_axis(self):
        """
        Index (0, 1, 2) of the principal axis of an axisymmetric body, else None.

        It is the axis whose moment differs from the two (near-)equal others.
        None for a spherical or a fully asymmetric body.
        """
        if self.is_spherical:
            return None
        m = self.moments
        tol = EQUAL_MOMENT_RTOL * max(m)
        for axis in range(3):
            a, b = (m[(axis + 1) % 3], m[(axis + 2) % 3])
            if abs(a - b) <= tol:
                return axis
        return None

    @property
    def kind(self):
        """'spherical', 'axisymmetric' or 'asymmetric'."""
        if self.is_spherical:
            return 'spherical'
        return 'asymmetric' if self.symmetry_axis is None else 'axisymmetric'

    @property
    def is_principal_frame(self):
        """Return True when the body frame is the principal frame (no rotation between them)."""
        return self._identity

    # Frame changes. Vectors (..., 3), quaternions (..., 4) scalar-last.
    def to_principal(self, v_body):
        """Body-frame vector components -> principal-frame components."""
        v = np.asarray(v_body, dtype=float)
        return v if self._identity else v @ self.rotation

    def to_body(self, v_principal):
        """Principal-frame vector components -> body-frame components."""
        v = np.asarray(v_principal, dtype=float)
        return v if self._identity else v @ self.rotation.T

    def attitude_to_principal(self, q_world_body):
        """Attitude of the body frame (body -> world) -> attitude of the principal frame."""
        q = np.asarray(q_world_body, dtype=float)
        return q if self._identity else quaternions.multiply(q, self.quaternion)

    def attitude_to_body(self, q_world_principal):
        """Attitude of the principal frame -> attitude of the body frame (body -> world)."""
        q = np.asarray(q_world_principal, dtype=float)
        if self._identity:
            return q
        return quaternions.multiply(q, quaternions.conjugate(self.quaternion))

    def __repr__(self):
        """Readable form with the moments, e.g. Inertia([1.0, 2.0, 3.0])."""
        extra = '' if self._identity else ', rotated'
        return f'Inertia({self.moments.tolist()}{extra})'


def as_inertia(value):
    """Return ``value`` if it is an Inertia, else ``Inertia(value)`` (three moments)."""
    return value if isinstance(value, Inertia) else Inertia(value)


def ellipsoid_semi_axes(moments, kinetic_energy):
    """
    Semi-axes (rad/s) of Shapiro's inertia ellipsoid omega . I omega = 2T.

    Along principal axis i the semi-axis is sqrt(2T / I_i): proportional to
    1/sqrt(I_i) (Poinsot construction, Shapiro section 4.4.1).
    """
    m = validate_moments(moments)
    return np.array([math.sqrt(2.0 * kinetic_energy / i) for i in m])


def equivalent_box(moments, mass=1.0):
    """
    Side lengths (m) of the uniform box of ``mass`` (kg) with these principal moments.

    I_1 = m (b^2 + c^2) / 12 and cyclic, so a^2 = 6 (I_2 + I_3 - I_1) / m and
    cyclic; the triangle inequality of valid moments keeps them real (a flat
    body, I_1 + I_2 = I_3, has c = 0). Used to draw a body "shaped like" its inertia.
    """
    i1, i2, i3 = validate_moments(moments)
    return np.sqrt(np.maximum(6.0 / mass * np.array([i2 + i3 - i1, i1 + i3 - i2,
                                                     i1 + i2 - i3]), 0.0))
