"""rigid_body_report: files, the data the figures show, recordings, clear errors."""

import os

import numpy as np
import pytest
from rigid_body_dynamics import report
from rigid_body_dynamics.physics import theory


def test_offline_report_files_and_plotted_data(tmp_path):
    run = report.offline_run('tennis_racket', 'exact', 30.0, 0.01)
    figures, rows = report.make_report(run, str(tmp_path))
    assert set(figures) == {'omega', 'polhode', 'herpolhode', 'conservation', 'flips'}
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


def test_symmetric_report_has_precession_against_theory(tmp_path):
    run = report.offline_run('symmetric_top', 'exact', 10.0, 0.01)
    figures, rows = report.make_report(run, str(tmp_path))
    data = figures['precession'][1]
    np.testing.assert_allclose(data['measured'], data['theory'], atol=1e-12)
    measured = {a: float(b) for a, b, _ in rows if 'precession' in a}
    assert measured['body precession rate (rad/s)'] == pytest.approx(1.0, rel=1e-12)


def test_recording_round_trip_and_bad_recordings(tmp_path, capsys):
    run = report.offline_run('stable_major', 'rk4', 5.0, 0.01)
    path = str(tmp_path / 'run.npz')
    report.save_recording(path, run)
    assert report.main(['--recording', path, '--out', str(tmp_path / 'out')]) == 0
    assert 'wrote' in capsys.readouterr().out
    loaded = report.load_recording(path)
    np.testing.assert_array_equal(loaded.omega, run.omega)
    garbage = tmp_path / 'garbage.npz'
    garbage.write_bytes(b'not a recording')
    assert report.main(['--recording', str(garbage)]) == 2
    assert 'cannot read recording' in capsys.readouterr().err
    np.savez(tmp_path / 'short.npz', t=np.zeros(2), q=np.zeros((2, 4)), omega=np.zeros((2, 3)),
             tensor=np.eye(3))
    assert report.main(['--recording', str(tmp_path / 'short.npz')]) == 2
    assert 'N >= 3' in capsys.readouterr().err
    assert report.main(['--preset', 'boomerang']) == 2
    assert "unknown preset 'boomerang'" in capsys.readouterr().err


def test_record_from_the_running_simulator(launch, tmp_path):
    sim = launch('rigid_body_dynamics.nodes.simulator', '-p', 'publish_clock:=true',
                 '-p', 'real_time_factor:=4.0', name='sim')
    path = str(tmp_path / 'live.npz')
    assert report.main(['--record', path, '--duration', '3', '--out', str(tmp_path / 'r')]) == 0
    run = report.load_recording(path)
    assert run.t[-1] - run.t[0] >= 3.0
    np.testing.assert_allclose(run.inertia.moments, [1.0, 1.0, 1.5])
    assert os.path.exists(tmp_path / 'r' / 'precession.png')
    code, _ = sim.stop()
    assert code == 0
