"""The momentum-sphere curves (analysis/momentum_sphere.py) against both surfaces and a run."""

import numpy as np
import pytest
from rigid_body_dynamics.physics import simulate
from rigid_body_dynamics.physics.analysis import momentum_sphere

MOMENTS = np.array([1.0, 2.0, 3.0])


def _on_both(curve, l0, two_t=None):
    """Largest departure (rel.) from the sphere and, if given, from the ellipsoid 2T."""
    sphere = np.max(np.abs(np.linalg.norm(curve, axis=1) / l0 - 1.0))
    if two_t is None:
        return sphere, None
    energy = np.sum(curve * curve / MOMENTS, axis=1)
    return sphere, np.max(np.abs(energy / two_t - 1.0))


def test_every_curve_lies_on_the_sphere_and_on_one_energy_ellipsoid():
    l0 = 2.5
    family = momentum_sphere.curve_family(MOMENTS, l0, per_family=7)
    assert len(family['major']) == 14 and len(family['minor']) == 14
    assert len(family['separatrix']) == 2
    for name in ('major', 'minor', 'separatrix'):
        for curve in family[name]:
            two_t = np.sum(curve[0] ** 2 / MOMENTS)
            sphere, ellipsoid = _on_both(curve, l0, two_t)
            assert sphere < 1e-12 and ellipsoid < 1e-12, name
            assert np.allclose(curve[0], curve[-1])               # closed
    # the major family circles axis 3 (largest I), the minor family axis 1 (smallest)
    assert all(abs(c[:, 2]).min() > 0 for c in family['major'])
    assert all(abs(c[:, 0]).min() > 0 for c in family['minor'])


def test_the_separatrix_has_l2_equal_2t_i2_and_passes_the_intermediate_axis():
    l0 = 1.7
    for circle in momentum_sphere.separatrix(MOMENTS, l0):
        two_t = np.sum(circle ** 2 / MOMENTS, axis=1)
        np.testing.assert_allclose(l0 ** 2, two_t * MOMENTS[1], rtol=1e-12)
        assert np.max(np.abs(circle[:, 1])) == pytest.approx(l0, rel=1e-12)
    with pytest.raises(ValueError, match='three different moments'):
        momentum_sphere.separatrix((1.0, 1.0, 2.0), l0)


def test_a_run_stays_on_its_curve_and_the_tennis_racket_crosses_from_end_to_end():
    """L_body of a simulated tennis racket keeps |L| and 2T; it visits both ends of axis 2."""
    run = simulate(MOMENTS, (0.01, 2.0, 0.01), duration=30.0, dt=1e-2)
    l_body = run.omega * MOMENTS
    l0 = np.linalg.norm(l_body[0])
    two_t = np.sum(l_body[0] ** 2 / MOMENTS)
    sphere, ellipsoid = _on_both(l_body, l0, two_t)
    assert sphere < 1e-12 and ellipsoid < 1e-12
    assert l_body[:, 1].max() > 0.99 * l0 and l_body[:, 1].min() < -0.99 * l0
    # its energy is next to the separatrix's, on the major side (2T < L^2 / I2: 8.0004
    # against 8.0005), so its curve is a loop around axis 3 that passes near both ends of 2
    assert 0.0 < l0 ** 2 / MOMENTS[1] - two_t < 1e-4 * two_t


def test_axisymmetric_bodies_have_one_family_and_no_separatrix():
    family = momentum_sphere.curve_family((1.0, 1.0, 1.5), 1.0, per_family=4)
    assert len(family['major']) == 8 and family['minor'] == [] and family['separatrix'] == []
    with pytest.raises(ValueError, match='no loop'):
        momentum_sphere.loop(MOMENTS, 1.0, 0.1, around=0)


def test_the_current_curve_is_the_one_l_is_on(rng):
    """current_curve: for random L, a curve through L (within the sampling) on both surfaces."""
    for _ in range(30):
        L = rng.normal(size=3)
        curve = momentum_sphere.current_curve(MOMENTS, L, points=2001)
        l0, two_t = np.linalg.norm(L), np.sum(L * L / MOMENTS)
        sphere, ellipsoid = _on_both(curve, l0, two_t)
        assert sphere < 1e-12 and ellipsoid < 1e-12
        assert np.min(np.linalg.norm(curve - L, axis=1)) < 0.01 * l0
    on_separatrix = momentum_sphere.separatrix(MOMENTS, 1.0)[1][37]
    curve = momentum_sphere.current_curve(MOMENTS, on_separatrix, points=361)
    assert np.min(np.linalg.norm(curve - on_separatrix, axis=1)) < 1e-12
    assert momentum_sphere.current_curve((2.0, 2.0, 2.0), (1.0, 0.0, 0.0)) is None
