"""rigid_body_report: files, the data the figures show, bags recorded and read, clear errors."""

import os

from bag_writers import rosbags_messages, write_rosbags
import numpy as np
import pytest
from rigid_body_dynamics.messages.bags import read_trajectory
from rigid_body_dynamics.physics.analysis import theory
from rigid_body_dynamics.tools import report


def test_offline_report_files_and_plotted_data(tmp_path):
    run = report.offline_run('tennis_racket', 'exact', 30.0, 0.01)
    figures, rows = report.make_report(run, str(tmp_path))
    assert set(figures) == {'omega', 'polhode', 'herpolhode', 'momentum_sphere', 'conservation',
                            'flips'}
    for path, _ in figures.values():
        assert os.path.getsize(path) > 10000                      # a real PNG
    page = open(tmp_path / 'index.html').read()
    assert all(os.path.basename(p) in page for p, _ in figures.values())
    # the figures show this run's data, not something else
    np.testing.assert_array_equal(figures['omega'][1]['omega_2'], run.omega[:, 1])
    np.testing.assert_array_equal(figures['polhode'][1]['polhode'], run.omega)
    assert np.max(figures['conservation'][1]['|T/T0 - 1|']) < 1e-14
    flips = figures['flips'][1]['flips']
    assert flips.size == 3                                        # at 6.1, 17.0 and 28.0 s
    expected = theory.flip_interval((1.0, 2.0, 3.0), (0.01, 2.0, 0.01))
    assert np.diff(flips).mean() == pytest.approx(expected, rel=1e-8)
    assert figures['herpolhode'][1]['herpolhode'].shape == (run.t.size, 2)
    assert {a: b for a, b, _ in rows}['flip interval (s)'].startswith('10.977572')
    # the momentum sphere: every drawn curve on both surfaces, the run's L on its own curve
    sphere = figures['momentum_sphere'][1]
    moments = np.array([1.0, 2.0, 3.0])
    l0 = np.linalg.norm(sphere['this run'][0])
    for name, curve in sphere.items():
        assert np.max(np.abs(np.linalg.norm(curve, axis=1) - l0)) < 1e-9 * l0, name
        energy = np.sum(curve * curve / moments, axis=1)
        assert np.ptp(energy) < 1e-9 * energy[0], name
        if name.startswith('separatrix'):
            np.testing.assert_allclose(energy * moments[1], l0 ** 2, rtol=1e-9)
    assert sum(name.startswith('separatrix') for name in sphere) == 2


def test_symmetric_report_has_precession_against_theory(tmp_path):
    run = report.offline_run('symmetric_top', 'exact', 10.0, 0.01)
    figures, rows = report.make_report(run, str(tmp_path))
    data = figures['precession'][1]
    np.testing.assert_allclose(data['measured'], data['theory'], atol=1e-12)
    measured = {a: float(b) for a, b, _ in rows if 'precession' in a}
    assert measured['body precession Omega (rad/s)'] == pytest.approx(1.0, rel=1e-12)


def test_allan_figure_of_the_simulated_gyro_shows_its_n_and_k(tmp_path, capsys):
    """
    --gyro-noise-density 1e-3 --gyro-bias-random-walk 1e-4 over 600 s at 100 Hz.

    The figure's curves are the Allan deviation of readings minus truth: at 1 s it is N's
    line (the walk adds K sqrt(1/3) = 6e-5 in quadrature, under 0.2 %), at 60 s K's line
    dominates (N / sqrt(60) = 1.3e-4 against K sqrt(20) = 4.5e-4). A 600 s record gives
    about 5 % / 20 % statistical scatter there, so the bounds are 10 % / 35 %.
    """
    assert report.main(['--preset', 'stable_major', '--duration', '600', '--dt', '0.01',
                        '--gyro-noise-density', '1e-3', '--gyro-bias-random-walk', '1e-4',
                        '--out', str(tmp_path)]) == 0
    assert 'allan.png' in capsys.readouterr().out
    assert 'allan.png' in open(tmp_path / 'index.html').read()
    from rigid_body_dynamics.physics.sensors import GyroErrors, GyroModel
    errors = GyroErrors(1e-3, 1e-4)
    run, gyro = report.offline_run('stable_major', 'exact', 600.0, 0.01,
                                   gyro=GyroModel(errors, 100.0))
    figures, _ = report.make_report(run, str(tmp_path / 'again'), (*gyro, errors))
    curves = figures['allan'][1]
    tau = curves['axis 1'][:, 0]
    adev = np.mean([curves[f'axis {a}'][:, 1] for a in (1, 2, 3)], axis=0)
    np.testing.assert_allclose(curves['N / sqrt(tau)'], 1e-3 / np.sqrt(tau), rtol=1e-12)
    np.testing.assert_allclose(curves['K sqrt(tau / 3)'], 1e-4 * np.sqrt(tau / 3), rtol=1e-12)
    at_1 = np.argmin(abs(np.log(tau)))
    at_60 = np.argmin(abs(np.log(tau / 60.0)))
    assert adev[at_1] == pytest.approx(1e-3 / np.sqrt(tau[at_1]), rel=0.10)
    assert adev[at_60] == pytest.approx(np.hypot(1e-3 / np.sqrt(tau[at_60]),
                                                 1e-4 * np.sqrt(tau[at_60] / 3)), rel=0.35)
    assert tau[0] == pytest.approx(0.01) and tau[-1] == pytest.approx(60.0, rel=0.02)


def test_report_from_a_bag_and_bad_input(tmp_path, capsys):
    run = report.offline_run('stable_major', 'rk4', 5.0, 0.01)
    t_ns = 1_764_547_200_000_000_000 + run.t_ns
    bag = write_rosbags(tmp_path / 'bag', rosbags_messages(
        t_ns, run.q, run.omega, [1.0, 2.0, 3.0, 0.0, 0.0, 0.0]))
    assert report.main(['--bag', str(bag), '--out', str(tmp_path / 'out')]) == 0
    assert 'wrote' in capsys.readouterr().out
    figures, _ = report.make_report(report.read_trajectory(str(bag))[0], str(tmp_path / 'again'))
    np.testing.assert_array_equal(figures['omega'][1]['omega_2'], run.omega[:, 1])
    garbage = tmp_path / 'garbage.mcap'
    garbage.write_bytes(b'not a bag')
    assert report.main(['--bag', str(garbage)]) == 2
    err = capsys.readouterr().err
    assert 'not a readable rosbag2 bag or MCAP file' in err and len(err.splitlines()) == 1
    assert report.main(['--preset', 'boomerang']) == 2
    assert "unknown preset 'boomerang'" in capsys.readouterr().err


def test_record_from_the_running_simulator(launch, tmp_path):
    sim = launch('rigid_body_dynamics.nodes.simulator', '-p', 'publish_clock:=true',
                 '-p', 'real_time_factor:=4.0', name='sim')
    path = tmp_path / 'live'
    assert report.main(['--record', str(path), '--duration', '3', '--out',
                        str(tmp_path / 'r')]) == 0
    assert sorted(os.listdir(path)) == ['live.mcap', 'metadata.yaml']
    run, info = read_trajectory(str(path))
    assert run.span >= 3.0 and (info.odom_topic, info.torque_topic) == ('/odom', '/applied_torque')
    np.testing.assert_allclose(run.inertia.moments, [1.0, 1.0, 1.5])
    assert os.path.exists(tmp_path / 'r' / 'precession.png')
    # the latched inertia is recorded latched, so `ros2 bag play` latches it again
    meta = open(path / 'metadata.yaml').read()
    assert 'transient_local' in meta.lower() or 'durability: 1' in meta
    code, _ = sim.stop()
    assert code == 0


def test_interactive_views_draw_this_run_and_the_box_has_its_moments(tmp_path):
    """report_page: the equivalent box reproduces the moments; frames turn it with the run."""
    from rigid_body_dynamics.tools import report_page
    from rigid_body_dynamics.physics import quaternions
    from rigid_body_dynamics.physics.inertia import equivalent_box
    for moments in ((1.0, 2.0, 3.0), (0.0419, 0.0419, 0.00667), (2.0, 2.5, 3.5)):
        a, b, c = equivalent_box(moments)
        np.testing.assert_allclose([(b * b + c * c) / 12, (a * a + c * c) / 12,
                                    (a * a + b * b) / 12], moments, rtol=1e-12)
    run = report.offline_run('tennis_racket', 'exact', 30.0, 0.01)
    moments = np.array([1.0, 2.0, 3.0])
    views = report_page.views(moments, run.t, run.q, run.omega)
    assert set(views) == {'polhode', 'herpolhode', 'momentum sphere', 'tumbling body'}
    polhode = views['polhode'].data[1]
    w = np.stack([polhode.x, polhode.y, polhode.z], axis=1)
    stride = -(-run.t.size // report_page.MAX_POINTS)                 # thinned evenly
    np.testing.assert_allclose(w, run.omega[::stride], rtol=0, atol=0)  # the run itself
    anim = views['tumbling body']
    assert len(anim.frames) == report_page.FRAMES
    corners = report_page.box_vertices(moments)
    k = np.argmin(np.abs(run.t[::stride] - float(anim.frames[60].name)))
    box = anim.frames[60].data[0]
    np.testing.assert_allclose(np.stack([box.x, box.y, box.z], axis=1),
                               quaternions.rotate(np.repeat(run.q[::stride][k][None], 8, 0),
                                                  corners),
                               atol=1e-12)
    flips = np.sign([f.data[-1].y[1] for f in anim.frames])       # omega_2 at each frame
    assert np.count_nonzero(np.diff(flips)) >= 2                  # the flips are in the film
    page = report_page.write(str(tmp_path), views)
    assert os.path.getsize(tmp_path / 'plotly.min.js') > 1_000_000
    assert 'src="http' not in page and 'cdn.plot.ly' not in page        # nothing online


def test_the_wheels_report_shows_the_momentum_exchange(tmp_path):
    """--preset wheels: wheel speeds and |H| of body, wheels and total; only the torque moves H."""
    out = tmp_path / 'wheels'
    run = report.wheels_run(10.0)
    figures, _rows = report.make_report(run, str(out))
    assert {'wheel_speeds', 'momentum_exchange'} <= set(figures)
    assert 'polhode' not in figures                    # the rigid body's picture does not apply
    sizes = figures['momentum_exchange'][1]
    # the total starts at rest and grows by the 0.02 N m disturbance (about body z, tilted
    # by at most the 15 degree slew): between cos(15 deg) and 1 times 0.02 t
    total, t = sizes['total H'], run.t
    assert total[0] == 0.0
    assert np.all(total[1:] <= 0.02 * t[1:] * (1.0 + 1e-9))
    assert np.all(total[1:] >= 0.02 * t[1:] * np.cos(np.radians(15.0)) * (1.0 - 1e-9))
    # the wheels took the body's momentum during the slew
    assert sizes['wheels sum J Omega g'].max() > 0.1 and (out / 'momentum_exchange.png').exists()
