"""Inertia: validation with reasons, the full-tensor path, symmetry detection."""

import numpy as np
import pytest
from rigid_body_dynamics.physics import FreeRigidBody, Inertia, quaternions
from rigid_body_dynamics.physics.inertia import AxisPermutation, ellipsoid_semi_axes
from scipy.spatial.transform import Rotation


@pytest.mark.parametrize('moments, reason', [
    ((1.0, 2.0), 'three numbers'),
    ((1.0, 2.0, float('nan')), 'finite'),
    ((1.0, 2.0, float('inf')), 'finite'),
    ((1.0, 0.0, 1.0), 'positive'),
    ((1.0, -2.0, 2.0), 'positive'),
    ((1.0, 1.0, 3.0), 'triangle inequality'),
    ((5.0, 1.0, 1.0), 'triangle inequality'),
    (('a', 1.0, 1.0), 'three numbers'),
])
def test_bad_moments_are_rejected_with_a_reason(moments, reason):
    with pytest.raises(ValueError, match=reason):
        Inertia(moments)


def test_flat_lamina_is_allowed():
    # A thin plate has I1 + I2 = I3 exactly: the limit of a real body.
    assert Inertia((1.0, 2.0, 3.0)).moments.tolist() == [1.0, 2.0, 3.0]


@pytest.mark.parametrize('tensor, reason', [
    ([[1, 0.1, 0], [0, 2, 0], [0, 0, 2.5]], 'symmetric'),
    ([[1, 0, 0], [0, -2, 0], [0, 0, 2.5]], 'positive definite'),
    ([[1, 0, 0], [0, 1, 0], [0, 0, 5]], 'triangle'),
    ([1, 2, 3, 4, 5], '6 numbers'),
    ([[1, 0, 0], [0, np.nan, 0], [0, 0, 1]], 'finite'),
])
def test_bad_tensors_are_rejected_with_a_reason(tensor, reason):
    with pytest.raises(ValueError, match=reason):
        Inertia.from_tensor(tensor)


def test_from_tensor_recovers_moments_and_a_proper_rotation(rng):
    rot = Rotation.random(random_state=7)
    moments = np.array([1.0, 2.0, 2.5])
    tensor = rot.as_matrix() @ np.diag(moments) @ rot.as_matrix().T
    inertia = Inertia.from_tensor(tensor)
    np.testing.assert_allclose(inertia.moments, moments, rtol=1e-13)
    assert np.linalg.det(inertia.rotation) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(inertia.tensor, tensor, atol=1e-13)
    v = rng.normal(size=3)
    np.testing.assert_allclose(inertia.to_body(inertia.to_principal(v)), v, atol=1e-14)


def test_six_element_form_matches_matrix():
    six = [2.0, 3.0, 4.0, 0.1, -0.2, 0.3]
    a = Inertia.from_tensor(six)
    b = Inertia.from_tensor([[2.0, 0.1, -0.2], [0.1, 3.0, 0.3], [-0.2, 0.3, 4.0]])
    np.testing.assert_allclose(a.moments, b.moments, rtol=1e-14)


def test_rotated_body_gives_the_same_physics():
    """A body described in a rotated frame moves exactly like the principal one."""
    rot = Rotation.from_euler('xyz', [0.3, -0.7, 1.1])
    moments = np.array([1.0, 2.0, 3.0])
    omega_p = np.array([0.4, 0.3, 2.0])
    principal = FreeRigidBody(moments, omega_p)
    rotated = FreeRigidBody(Inertia.from_tensor(rot.as_matrix() @ np.diag(moments)
                                                @ rot.as_matrix().T),
                            rot.apply(omega_p), rot.inv().as_quat())
    t = np.linspace(0.0, 10.0, 21)
    q_p, w_p = principal.state_at(t)
    q_r, w_r = rotated.state_at(t)
    np.testing.assert_allclose(w_r, rot.apply(w_p), atol=1e-12)
    # same motion of every material point: world image of a body vector agrees
    v_p = np.array([0.2, -0.5, 0.9])
    np.testing.assert_allclose(quaternions.rotate(q_r, rot.apply(v_p)),
                               quaternions.rotate(q_p, v_p), atol=1e-12)


@pytest.mark.parametrize('moments, kind, axis', [
    ((1.0, 2.0, 3.0), 'asymmetric', None),
    ((2.0, 2.0, 3.0), 'axisymmetric', 2),
    ((3.0, 2.0, 2.0), 'axisymmetric', 0),
    ((2.0, 2.0 * (1 + 1e-14), 3.0), 'axisymmetric', 2),
    ((1.0, 1.0, 1.0), 'spherical', None),
])
def test_symmetry_detection(moments, kind, axis):
    inertia = Inertia(moments)
    assert inertia.kind == kind
    assert inertia.symmetry_axis == axis


@pytest.mark.parametrize('moments', [(3.0, 1.0, 2.0), (2.0, 3.0, 1.0), (1.0, 3.0, 2.0),
                                     (3.0, 2.0, 1.0), (2.0, 1.0, 3.0)])
def test_axis_permutation_is_a_rotation(moments):
    perm = AxisPermutation.ascending(moments)
    assert list(perm.sorted_moments(moments)) == sorted(moments)
    v = (0.3, -1.2, 0.8)
    assert perm.from_sorted(perm.to_sorted(v)) == pytest.approx(v)
    # the quaternion maps sorted-frame vectors to the original frame
    np.testing.assert_allclose(quaternions.rotate(perm.quaternion, perm.to_sorted(v)), v,
                               atol=1e-15)


def test_ellipsoid_semi_axes_scale_as_inverse_sqrt_moments():
    axes = ellipsoid_semi_axes((1.0, 4.0, 4.0), kinetic_energy=2.0)
    np.testing.assert_allclose(axes, [2.0, 1.0, 1.0])
