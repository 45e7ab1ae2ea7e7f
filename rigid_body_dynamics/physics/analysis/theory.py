"""
Closed-form predictions for the free rigid body.

Each function cites where its formula comes from: Shapiro's textbook (J. A. Shapiro,
Classical Mechanics, section 4.4, equation numbers as there) or is derived
in its docstring from the exact solution of ``free_motion``. Units: kg m^2, rad/s, s, J,
kg m^2/s; vectors in the principal body frame unless named ``_world``.
"""

from dataclasses import dataclass
import math

import numpy as np

from ..dynamics.free_motion import BodyShape, polhode_parameters, SEPARATRIX_THRESHOLD
from ..inertia import EQUAL_MOMENT_RTOL, validate_moments

SIDEREAL_DAY = 86164.0905
"""Length of the sidereal day (s)."""


def body_precession_rate(i_perp, i_axis, omega_axis):
    """
    Body-frame precession rate Omega = omega_3 (I3 - I1) / I1 (rad/s), Shapiro after (4.26).

    For an axisymmetric body (I1 = I2 = ``i_perp``, symmetry moment ``i_axis``)
    omega's component perpendicular to the symmetry axis turns about +axis at
    Omega; negative for a prolate body (i_axis < i_perp).
    """
    return omega_axis * (i_axis - i_perp) / i_perp


def lab_precession_rate(i_perp, angular_momentum_norm):
    """
    Lab-frame precession rate |L| / I_perp (rad/s) of the symmetry axis and of omega about L.

    Equal to :func:`herpolhode_rate` (Shapiro's Omega sin(phi_b) / sin(phi_L)):
    the contact line's speed is the same seen from either cone.
    """
    return angular_momentum_norm / i_perp


@dataclass(frozen=True)
class ConeAngles:
    """Half-angles (rad) of an axisymmetric body's free motion."""

    body: float
    """phi_b: between omega and the symmetry axis (body cone), Shapiro: tan phi_b = A / omega_3."""
    lab: float
    """phi_L: between omega and L (lab cone), Shapiro: cos phi_L = 2T / (|omega| |L|)."""
    nutation: float
    """theta: between L and the symmetry axis, tan theta = I_perp omega_perp / (I3 |omega_3|)."""


def cone_angles(i_perp, i_axis, omega_perp, omega_axis):
    """
    Body-cone, lab-cone and nutation half-angles (rad) of an axisymmetric body.

    ``omega_perp`` >= 0 is the magnitude of omega perpendicular to the
    symmetry axis (Shapiro's amplitude A), ``omega_axis`` the component along
    it. Angles via atan2 (no acos precision floor).
    """
    w_axis = abs(omega_axis)
    body = math.atan2(omega_perp, w_axis)
    nutation = math.atan2(i_perp * omega_perp, i_axis * w_axis)
    return ConeAngles(body=body, lab=abs(body - nutation), nutation=nutation)


def herpolhode_rate(i_perp, i_axis, omega_perp, omega_axis):
    """
    Rate (rad/s) at which the herpolhode turns about L: Omega sin(phi_b) / sin(phi_L).

    Shapiro's rolling-without-slipping expression (Poinsot construction); it
    equals |L| / I_perp (:func:`lab_precession_rate`) whenever phi_L > 0.
    """
    cones = cone_angles(i_perp, i_axis, omega_perp, omega_axis)
    omega_body = abs(body_precession_rate(i_perp, i_axis, omega_axis))
    return omega_body * math.sin(cones.body) / math.sin(cones.lab)


def invariant_plane_distance(kinetic_energy, angular_momentum_norm):
    """
    Distance (rad/s) of the invariant plane from the origin in omega-space: 2T / |L|.

    omega . L_hat = 2T / |L| is constant (Shapiro, Poinsot construction).
    """
    return 2.0 * kinetic_energy / angular_momentum_norm


@dataclass(frozen=True)
class AxisStability:
    """
    Linear stability of a spin about one principal axis.

    ``kind``: 'stable' (wobble at ``rate`` rad/s), 'unstable' (perturbations
    grow as exp(``rate`` t)), 'marginal' (an equal moment: linear growth,
    ``rate`` 0) or 'rest' (no spin).
    """

    axis: int
    kind: str
    rate: float


def axis_stability(moments, axis, spin):
    """
    Stability of a spin ``spin`` (rad/s) about principal axis ``axis`` (0, 1 or 2).

    Shapiro, "Stability of rotation about an axis": the perturbation obeys
    eps'' = s2 eps with s2 = -omega^2 (I_j - I_k)(I_j - I_l) / (I_k I_l);
    s2 < 0 is a wobble at sqrt(-s2), s2 > 0 growth at sqrt(s2) (intermediate
    axis), an equal moment the marginal case of linear growth.
    """
    i = validate_moments(moments)
    j, k, ll = axis, (axis + 1) % 3, (axis + 2) % 3
    if spin == 0.0:
        return AxisStability(axis, 'rest', 0.0)
    tol = EQUAL_MOMENT_RTOL * max(i)
    if abs(i[j] - i[k]) <= tol or abs(i[j] - i[ll]) <= tol:
        if abs(i[k] - i[ll]) <= tol:
            return AxisStability(axis, 'stable', 0.0)
        return AxisStability(axis, 'marginal', 0.0)
    product = (i[j] - i[k]) * (i[j] - i[ll]) / (i[k] * i[ll])
    rate = abs(spin) * math.sqrt(abs(product))
    return AxisStability(axis, 'stable' if product > 0.0 else 'unstable', rate)


def stability(moments, omega):
    """Apply :func:`axis_stability` to the principal axis nearest omega (body frame)."""
    axis = int(np.argmax(np.abs(np.asarray(omega, dtype=float))))
    return axis_stability(moments, axis, float(omega[axis]))


@dataclass(frozen=True)
class Polhode:
    """
    Which family the polhode belongs to and how far it is from the separatrix.

    ``family``: 'max-axis' (circles the largest-moment axis), 'min-axis'
    (circles the smallest), 'separatrix' (L^2 = 2 T I2), 'symmetric' (an
    axisymmetric or spherical body: circles the symmetry axis) or 'rest'.
    ``circled_axis``: body-axis index or None. ``separatrix_distance`` =
    (L^2 - 2 T I2) / L^2 (0 on the separatrix; NaN if not asymmetric).
    """

    family: str
    circled_axis: object
    separatrix_distance: float


def _sorted_parameters(moments, omega):
    shape = BodyShape(validate_moments(moments))
    if shape.kind != 'asymmetric':
        return shape, None
    m = tuple(i * w for i, w in zip(shape.moments, np.asarray(omega, dtype=float)))
    return shape, polhode_parameters(shape.sorted_moments, shape.permutation.to_sorted(m))


def polhode(moments, omega):
    """Polhode family of the free motion with angular velocity ``omega`` (body frame)."""
    shape, par = _sorted_parameters(moments, omega)
    if not np.any(np.asarray(omega, dtype=float)):
        return Polhode('rest', None, math.nan)
    if par is None:
        return Polhode('symmetric', shape.axis if shape.axis is not None else None, math.nan)
    order = shape.permutation.order
    if par.family == 'A':
        return Polhode('max-axis', order[2], par.separatrix_distance)
    if par.family == 'B':
        return Polhode('min-axis', order[0], par.separatrix_distance)
    if par.family == 'principal':
        axis = int(np.argmax(np.abs(np.asarray(omega, dtype=float))))
        return Polhode('separatrix' if axis == order[1] else
                       ('max-axis' if axis == order[2] else 'min-axis'), axis,
                       par.separatrix_distance)
    return Polhode('separatrix', None, par.separatrix_distance)


def omega_period(moments, omega):
    """
    Period (s) of omega(t) in the body frame.

    Asymmetric body: 4 K(k) / lambda (k, lambda of the elliptic solution in
    ``free_motion``), the period of sn and cn. Axisymmetric: 2 pi / |Omega|
    (:func:`body_precession_rate`). Infinite for a spin about a principal
    axis, a sphere, or the separatrix.
    """
    shape, par = _sorted_parameters(moments, omega)
    w = np.asarray(omega, dtype=float)
    if par is None:
        if shape.axis is None:
            return math.inf
        ax = shape.axis
        i_perp = 0.5 * (shape.moments[(ax + 1) % 3] + shape.moments[(ax + 2) % 3])
        rate = body_precession_rate(i_perp, shape.moments[ax], w[ax])
        return math.inf if rate == 0.0 else 2.0 * math.pi / abs(rate)
    if par.family not in ('A', 'B'):
        return math.inf
    return par.period


def flip_interval(moments, omega):
    """
    Time (s) between successive flips of a spin near the intermediate axis: 2 K / lambda.

    Half the period of omega(t): the intermediate
    component changes sign once per half period (tennis-racket theorem).
    """
    return 0.5 * omega_period(moments, omega)


def separatrix_growth_rate(moments, omega):
    """
    Growth rate (1/s) of departures from a spin about the intermediate axis.

    omega_2 sqrt((I2 - I1)(I3 - I2) / (I1 I3)) with the intermediate axis'
    component of omega (Shapiro, stability; equals lambda on the separatrix).
    """
    shape = BodyShape(validate_moments(moments))
    if shape.kind != 'asymmetric':
        return 0.0
    mid = shape.permutation.order[1]
    return axis_stability(moments, mid, float(np.asarray(omega, dtype=float)[mid])).rate


def mean_precession_rate(moments, omega, axis=None):
    """
    Mean rate (rad/s) at which a principal body axis precesses about L over one period.

    The attitude returns after one period of omega up to a rotation by
    dpsi about L (right-handed about +L); a body axis that the polhode
    circles picks up one turn more, +2 pi around the largest-moment axis
    and -2 pi around the smallest (the first follows from the exact solution;
    the second was measured here, see test_theory). ``axis`` defaults to the
    circled axis. Axisymmetric bodies: |L| / I_perp for the symmetry axis.
    """
    shape, par = _sorted_parameters(moments, omega)
    w = np.asarray(omega, dtype=float)
    g = float(np.linalg.norm(np.asarray(shape.moments) * w))
    if par is None:
        if shape.axis is None:
            return g / shape.moments[0]
        ax = shape.axis
        return g / (0.5 * (shape.moments[(ax + 1) % 3] + shape.moments[(ax + 2) % 3]))
    if par.family not in ('A', 'B'):
        raise ValueError('no periodic precession on the separatrix or for a principal-axis spin')
    order = shape.permutation.order
    circled = order[2] if par.family == 'A' else order[0]
    if axis is None:
        axis = circled
    extra = 0.0
    if axis == circled:
        extra = 2.0 * math.pi if par.family == 'A' else -2.0 * math.pi
    return (par.psi_per_period + extra) / par.period


def is_near_separatrix(moments, omega):
    """Tell whether the elliptic solution hands over to its numerical fallback here."""
    _, par = _sorted_parameters(moments, omega)
    return par is not None and abs(par.separatrix_distance) < SEPARATRIX_THRESHOLD


def chandler_wobble_period(spin_rate=2.0 * math.pi / SIDEREAL_DAY,
                           dynamical_ellipticity=1.0 / 300.0):
    """
    Body-frame wobble period (s) of an oblate planet: 2 pi / Omega.

    Omega = omega_3 (I3 - I1) / I1 with (I3 - I1) / I1 = ``dynamical_ellipticity``
    (Shapiro: Earth, about 1/300, period about 300 sidereal days, "10 months").
    """
    return 2.0 * math.pi / (spin_rate * dynamical_ellipticity)
