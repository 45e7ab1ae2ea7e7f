"""poinsot_visualizer over real topics, fed by the simulator."""

import numpy as np
import pytest
from rigid_body_dynamics.physics import quaternions
from rigid_body_dynamics.ros.conversions import quaternion_array
from visualization_msgs.msg import Marker, MarkerArray


def _vec(p):
    return np.array([p.x, p.y, p.z])


@pytest.mark.parametrize('preset, moments', [('tennis_racket', (1.0, 2.0, 3.0)),
                                             ('symmetric_top', (1.0, 1.0, 1.5))])
def test_markers_show_the_construction(launch, probe, preset, moments):
    scale = 0.5
    sim = launch('rigid_body_dynamics.nodes.simulator', '-p', f'preset:={preset}',
                 '-p', 'real_time_factor:=4.0', name='sim')
    viz = launch('rigid_body_dynamics.nodes.poinsot', '-p', f'scale:={scale}',
                 '-p', 'trace_length:=300', name='viz')
    arrays = probe.subscribe(MarkerArray, 'poinsot_markers')
    probe.spin_until(lambda: len(arrays) >= 30, 40.0, '30 marker arrays')
    for array in arrays[-5:]:
        by_ns = {m.id: m for m in array.markers if m.ns == 'poinsot'}
        assert len(by_ns) == 6
        sphere_ns = {m.id: m for m in array.markers if m.ns == 'momentum_sphere'}
        assert len(sphere_ns) == 3
        for m in array.markers:
            assert m.header.frame_id == 'odom'
            points = [_vec(p) for p in m.points]
            assert all(np.all(np.isfinite(p)) for p in points)
            assert np.all(np.isfinite([m.scale.x, m.scale.y, m.scale.z]))
            assert m.scale.x > 0.0 and m.scale.y >= 0.0
        ellipsoid, omega, normal, plane, polhode, herpolhode = (by_ns[i] for i in range(6))
        assert ellipsoid.type == Marker.SPHERE and plane.type == Marker.CUBE
        assert 1 < len(polhode.points) <= 300 and 1 < len(herpolhode.points) <= 300
        semi = 0.5 * np.array([ellipsoid.scale.x, ellipsoid.scale.y, ellipsoid.scale.z]) / scale
        # semi-axes proportional to 1 / sqrt(I_i) (seed, Poinsot construction)
        np.testing.assert_allclose(semi * np.sqrt(moments), semi[0] * np.sqrt(moments[0]),
                                   rtol=1e-12)
        q = quaternion_array(ellipsoid.pose.orientation)
        tip = _vec(omega.points[1]) / scale
        body_tip = quaternions.rotate_inverse(q, tip)
        # omega's tip is on the ellipsoid ...
        assert np.sum((body_tip / semi) ** 2) == pytest.approx(1.0, rel=1e-9)
        # ... and on the invariant plane at the same stamp: tangency
        foot = _vec(normal.points[1]) / scale
        n_hat = foot / np.linalg.norm(foot)
        assert float(tip @ n_hat) == pytest.approx(np.linalg.norm(foot), rel=1e-9)
        np.testing.assert_allclose(_vec(plane.pose.position) / scale, foot, rtol=1e-12)
        # the herpolhode lies in the plane too
        her = np.array([_vec(p) for p in herpolhode.points]) / scale
        np.testing.assert_allclose(her @ n_hat, np.linalg.norm(foot), rtol=1e-9)
        # the momentum sphere: L's current curve, back in the body frame, lies on the sphere
        # and on the energy ellipsoid of this instant's L, and L (the arrow) is on it
        sphere, arrow, curve = (sphere_ns[i] for i in (6, 7, 8))
        radius = 0.5 * sphere.scale.x
        assert radius == pytest.approx(scale * np.max(semi), rel=1e-12)
        body = quaternions.rotate_inverse(q, np.array([_vec(p) for p in curve.points]))
        np.testing.assert_allclose(np.linalg.norm(body, axis=1), radius, rtol=1e-9)
        l_now = quaternions.rotate_inverse(q, _vec(arrow.points[1]))
        np.testing.assert_allclose(np.linalg.norm(l_now), radius, rtol=1e-9)
        m = np.array(moments)
        energy = np.sum(body * body / m, axis=1)
        np.testing.assert_allclose(energy, np.sum(l_now * l_now / m), rtol=1e-7)
        assert np.min(np.linalg.norm(body - l_now, axis=1)) < 0.05 * radius   # L is on it
    for proc in (viz, sim):
        code, _ = proc.stop()
        assert code == 0, proc.output()
