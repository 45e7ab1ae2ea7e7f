"""
Monte Carlo campaigns: draws, the check that each took, records, resuming, Dask, the ensemble.

The scenario is the example MEKF on the simulator's gyro (10 Hz) and star
tracker (1 Hz) on a tumbling body, the run's noise seed, initial attitude and
rate dispersed. The consistency test flies 200 runs of 560 s on a LocalCluster
and judges the ANEES at 501 times against its 99 % chi-square bounds; the test
derives its own false-failure rate from the times' correlation.
"""

import copy
import math
import os
import signal
import subprocess
import sys

import numpy as np
import pytest
from rigid_body_dynamics.campaign import build, gather, judge, run_campaign, run_one
from rigid_body_dynamics.campaign.dispersions import Dispersion
from rigid_body_dynamics.campaign.runner import draws, job_of, load_record, run_path
from rigid_body_dynamics.physics import quaternions
from rigid_body_dynamics.physics.analysis import autocorrelation_time
from rigid_body_dynamics.physics.analysis.ensemble import anees_bounds, false_failure_rate
from rigid_body_dynamics.ros.parameters import ConfigurationError
from scipy import stats
import stat_checks

SHARED = {'preset': 'tennis_racket', 'integration_rate': 10.0, 'publish_rate': 10.0,
          'imu_rate': 10.0, 'star_tracker_rate': 1.0, 'star_tracker_noise': [1e-4] * 3,
          'gyro_noise_density': 1e-4, 'gyro_bias_random_walk': 1e-6,
          'gyro_turn_on_bias': 1e-3, 'control_period': 1.0,
          'initial_angular_velocity': [0.02, -0.01, 0.015]}
DISPERSIONS = {'noise_seed': {'distribution': 'seed'},
               'initial_orientation': {'distribution': 'rotation'},
               'initial_angular_velocity': {'distribution': 'normal', 'sigma': 0.005}}


def _values(tmp_path, runs=4, duration=20.0, scenario=None, **keys):
    values = {'scenario': scenario or {'/**': {'ros__parameters': dict(SHARED)}},
              'runs': runs, 'duration': duration, 'control_on': 'none',
              'dispersions': copy.deepcopy(DISPERSIONS), 'output': str(tmp_path / 'out')}
    values.update(keys)
    return values


def _arrays(output, index):
    record = load_record(run_path(output, index))
    return {k: record[k] for k in ('t', 'q_true', 'q_estimate', 'covariance', 'nees')}


def _same_records(a, b, runs):
    for i in range(runs):
        x, y = _arrays(a, i), _arrays(b, i)
        for key in x:
            assert np.array_equal(x[key], y[key]), (i, key)


# ---------------------------------------------------------------------------- draws
def test_a_runs_draw_depends_on_its_seed_index_and_name_only():
    """A draw is the same whichever other dispersions there are, and differs between runs."""
    nominal = [0.02, -0.01, 0.015]
    d = Dispersion('initial_angular_velocity', {'distribution': 'normal', 'sigma': 0.005},
                   nominal)
    again = Dispersion('initial_angular_velocity', {'distribution': 'normal', 'sigma': 0.005},
                       nominal)
    assert d.draw(7, 3) == again.draw(7, 3)
    assert d.draw(7, 3) != d.draw(7, 4) and d.draw(7, 3) != d.draw(8, 3)
    seed = Dispersion('noise_seed', {'distribution': 'seed'}, 0)
    assert seed.draw(7, 3) != seed.draw(7, 4) and isinstance(seed.draw(7, 3), int)
    # a campaign with one more dispersion draws the same values for the others
    values = {'scenario': {'/**': {'ros__parameters': dict(SHARED)}}, 'runs': 4,
              'duration': 20.0, 'dispersions': copy.deepcopy(DISPERSIONS)}
    fewer = draws(build(values), 3)
    values['dispersions']['gyro_noise_density'] = {'distribution': 'uniform', 'low': 1e-5,
                                                   'high': 1e-4}
    more = draws(build(values), 3)
    assert set(more) - set(fewer) == {(None, 'gyro_noise_density')}
    assert all(more[k] == v for k, v in fewer.items())


def test_the_draws_have_their_distributions():
    """
    Check 4000 draws of each kind against its distribution.

    normal: mean and variance per axis inside their intervals; uniform: inside
    [low, high] with the uniform's variance; rotation with sigma: the angle's
    square over sigma^2 is chi-square(3); uniform rotation: the angle's cosine
    law (a Kolmogorov-Smirnov test against (angle - sin angle) / pi); direction:
    unit length, each component uniform on [-1, 1]. Twelve checks share the test's
    false-failure budget of 1e-4.
    """
    n, each = 4000, stat_checks.share(12)
    normal = np.array([Dispersion('w', {'distribution': 'normal', 'sigma': [1.0, 2.0, 3.0]},
                                  [1.0, 0.0, -1.0]).draw(1, i) for i in range(n)])
    for axis, (mean, sigma) in enumerate(((1.0, 1.0), (0.0, 2.0), (-1.0, 3.0))):
        x = normal[:, axis]
        assert abs(x.mean() - mean) < stat_checks.mean_bound(sigma, n, each)
        low, high = stat_checks.variance_interval(n, each, ddof=1)
        assert low < x.var(ddof=1) / sigma ** 2 < high
    u = np.array([Dispersion('x', {'distribution': 'uniform', 'low': 2.0, 'high': 5.0},
                             1.0).draw(1, i) for i in range(n)])
    assert u.min() >= 2.0 and u.max() <= 5.0
    assert stats.kstest((u - 2.0) / 3.0, 'uniform').pvalue > each
    nominal = quaternions.from_axis_angle([0.0, 0.0, 1.0], 0.3)
    small = Dispersion('q', {'distribution': 'rotation', 'sigma': 0.01}, list(nominal))
    angles = np.array([quaternions.angle_between(small.draw(1, i), nominal) for i in range(n)])
    assert stats.kstest((angles / 0.01) ** 2, stats.chi2(3).cdf).pvalue > each
    wide = Dispersion('q', {'distribution': 'rotation'}, [0.0, 0.0, 0.0, 1.0])
    angles = np.array([quaternions.angle_between(wide.draw(1, i), [0, 0, 0, 1])
                       for i in range(n)])
    assert stats.kstest(angles, lambda a: (a - np.sin(a)) / math.pi).pvalue > each
    v = np.array([Dispersion('w', {'distribution': 'direction', 'norm': 2.0},
                             [1.0, 0.0, 0.0]).draw(1, i) for i in range(n)])
    assert np.allclose(np.linalg.norm(v, axis=1), 2.0, rtol=1e-15)
    for axis in range(3):
        assert stats.kstest(v[:, axis] / 4.0 + 0.5, 'uniform').pvalue > each


# ---------------------------------------------------------------------------- refusals
@pytest.mark.parametrize('change, says', [
    ({'runs': 1}, 'runs must be an integer >= 2'),
    ({'dispersion': {}}, 'unknown key(s) dispersion'),
    ({'scenario': {'/**': {'ros__parameters': dict(SHARED, gyro_nois_density=1.0)}}},
     'no node declares gyro_nois_density'),
    ({'scenario': {'attitude_estimator': {'ros__parameters': {'imu_rate': 5.0}}}},
     "attitude_estimator has no parameter 'imu_rate'"),
    ({'scenario': {'attitude_simulatr': {'ros__parameters': {}}}},
     "section 'attitude_simulatr' configures no node"),
    ({'dispersions': {'publish_rate': {'distribution': 'normal', 'sigma': 1.0}}},
     'publish_rate cannot be dispersed on attitude_simulator'),
    ({'dispersions': {'inertia': {'distribution': 'normal'}}}, 'needs sigma'),
    ({'dispersions': {'inertia': {'distribution': 'gamma'}}}, 'needs distribution: one of'),
    ({'dispersions': {'noise_seed': {'distribution': 'seed', 'sigma': 1}}},
     'does not take sigma'),
])
def test_a_campaign_file_that_would_leave_a_default_in_place_is_refused(tmp_path, change, says):
    values = _values(tmp_path)
    values.update(change)
    with pytest.raises(ConfigurationError) as err:
        build(values)
    assert says in str(err.value)


def test_a_drawn_value_that_does_not_take_fails_the_run_with_both_values(tmp_path):
    """
    Disperse inertia where the scenario sets inertia_tensor, which overrides it.

    The nodes take that file without a word; the campaign reads the moments
    back from the engine, sees the tensor's, and fails each run saying so.
    """
    shared = dict(SHARED, inertia_tensor=[2.0, 3.0, 1.5, 0.0, 0.0, 0.0])
    values = _values(tmp_path, scenario={'/**': {'ros__parameters': shared}}, dispersions={
        'inertia': {'distribution': 'normal', 'sigma': 0.01, 'mean': [2.0, 3.0, 1.5]}})
    record = run_one(job_of(build(values)), 0)
    assert record['status'] == 'failed'
    assert record['error'].startswith('DispersionNotApplied: inertia on attitude_simulator: '
                                      'drew [')
    assert record['applied']['attitude_simulator.inertia'] == [2.0, 3.0, 1.5]
    drawn = record['drawn']['inertia']
    assert drawn != [2.0, 3.0, 1.5] and len(drawn) == 3


def test_every_drawn_value_is_read_back_from_the_run_equal(tmp_path):
    values = _values(tmp_path, dispersions=dict(DISPERSIONS, gyro_noise_density={
        'distribution': 'uniform', 'low': 5e-5, 'high': 2e-4}, star_tracker_misalignment={
        'distribution': 'normal', 'sigma': 1e-4, 'node': 'attitude_simulator'}))
    record = run_one(job_of(build(values)), 2)
    assert record['status'] == 'ok', record['error']
    applied = record['applied']
    assert set(applied) == {'attitude_simulator.noise_seed',
                            'attitude_simulator.initial_orientation',
                            'attitude_simulator.initial_angular_velocity',
                            'attitude_simulator.gyro_noise_density',
                            'attitude_estimator.gyro_noise_density',
                            'attitude_simulator.star_tracker_misalignment'}
    assert applied['attitude_estimator.gyro_noise_density'] == [
        record['drawn']['gyro_noise_density']]
    assert applied['attitude_simulator.noise_seed'] == record['drawn']['noise_seed']


# ---------------------------------------------------------------------------- records
def test_a_failing_run_is_recorded_and_the_others_fly(tmp_path):
    """Uniform moments that break the triangle inequality in some runs: those fail, named."""
    values = _values(tmp_path, runs=6, dispersions={'inertia': {
        'distribution': 'uniform', 'low': [1.0, 1.0, 1.0], 'high': [1.0, 1.0, 3.0]}})
    campaign = build(values)
    assert run_campaign(campaign, workers=0, say=lambda line: None) == 6
    ens = gather(campaign.output)
    failed = {r['index']: r for r in ens.failed}
    for r in ens.records:
        i1, i2, i3 = r['drawn']['inertia']
        assert (r['index'] in failed) == (i3 > i1 + i2), r
    assert failed and ens.flown
    assert all('ConfigurationError' in r['error'] for r in failed.values())


def test_a_killed_campaign_runs_only_what_is_missing_and_gives_the_same_records(tmp_path):
    values = _values(tmp_path, runs=4)
    first = build(values)
    said = []
    assert run_campaign(first, workers=0, say=said.append) == 4
    whole = tmp_path / 'whole'
    os.rename(first.output, whole)
    os.makedirs(os.path.join(first.output, 'runs'))
    for name in ('campaign.json', 'runs/run_000000.npz', 'runs/run_000002.npz'):
        os.link(whole / name, os.path.join(first.output, name))
    said.clear()
    assert run_campaign(build(values), workers=0, say=said.append) == 2
    assert 'running the 2 missing' in said[0]
    _same_records(whole, first.output, 4)
    other = dict(values, seed=1)
    with pytest.raises(ConfigurationError, match='holds the runs of another campaign'):
        run_campaign(build(other), workers=0)


def _wait_for_file(path, proc, deadline):
    """Wait until ``path`` exists (the scheduler wrote its address), polling the process."""
    import time
    while not os.path.exists(path):
        assert proc.poll() is None, 'the scheduler stopped'
        assert time.monotonic() < deadline, f'no {path}'
        try:
            proc.wait(timeout=0.1)
        except subprocess.TimeoutExpired:
            pass


def test_a_local_cluster_and_two_hosts_give_the_records_of_one_process(tmp_path):
    """
    Fly 6 runs in this process, on a LocalCluster, and on a scheduler with two workers.

    The scheduler and its workers start apart, each its own process, as on
    hosts of a cluster (on loopback here): the records are equal bit for bit.
    """
    import time
    from distributed import Client
    base = _values(tmp_path, runs=6)
    alone = build(dict(base, output=str(tmp_path / 'alone')))
    run_campaign(alone, workers=0, say=lambda line: None)
    local = build(dict(base, output=str(tmp_path / 'local')))
    before = dict(os.environ)
    run_campaign(local, workers=2, say=lambda line: None)
    assert dict(os.environ) == before        # the cluster's workers' settings stay theirs
    _same_records(alone.output, local.output, 6)
    address_file = str(tmp_path / 'scheduler.json')
    procs = [subprocess.Popen([sys.executable, '-m', 'distributed.cli.dask_scheduler',
                               '--host', '127.0.0.1', '--port', '0', '--no-dashboard',
                               '--dashboard-address', '127.0.0.1:0',
                               '--scheduler-file', address_file],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        _wait_for_file(address_file, procs[0], time.monotonic() + 60.0)
        for _ in range(2):
            procs.append(subprocess.Popen(
                [sys.executable, '-m', 'distributed.cli.dask_worker', '--scheduler-file',
                 address_file, '--nthreads', '1', '--nworkers', '1', '--host', '127.0.0.1',
                 '--no-dashboard', '--dashboard-address', '127.0.0.1:0'],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        with Client(scheduler_file=address_file, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)
            address = client.scheduler.address
        hosts = build(dict(base, output=str(tmp_path / 'hosts')))
        said = []
        run_campaign(hosts, scheduler=address, say=said.append)
        assert '(2 workers)' in said[0]
        _same_records(alone.output, hosts.output, 6)
    finally:
        for proc in reversed(procs):
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
        for proc in reversed(procs):
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


# ---------------------------------------------------------------------------- ensemble
def test_anees_bounds_hold_a_consistent_ensemble_at_their_level():
    """
    Judge 3000 synthetic ensembles of 50 runs of chi-square(3) NEES at one time.

    The share outside the 90 % bounds inside the binomial interval of 10 % at a
    false-failure rate of 1e-4 (the bounds are chi-square(150) over 50, exact).
    """
    rng = np.random.default_rng(5)
    nees = rng.chisquare(3, size=(3000, 50))
    low, high = anees_bounds(50, 0.9)
    outside = np.mean((nees.mean(axis=1) < low) | (nees.mean(axis=1) > high))
    lo, hi = stats.binom.interval(1.0 - stat_checks.FALSE_FAILURE, 3000, 0.1)
    assert lo / 3000 <= outside <= hi / 3000, outside
    assert false_failure_rate(200) == pytest.approx(stats.binom.sf(10, 200, 0.01))


def test_the_example_mekf_is_consistent_over_200_runs_and_a_detuned_one_is_not(tmp_path):
    """
    Fly 200 runs of 560 s on a LocalCluster; judge the ANEES from 60 s on (501 times).

    Inside its 99 % bounds at >= 95 % of the times. The times are correlated
    through each run's errors; counted as T / tau independent ones (tau the
    ANEES series' autocorrelation time, measured 2.3), the chance that a
    consistent filter fails this (more than 5 % of the times outside) is the
    binomial tail, derived here and held <= 1e-4 (measured about 1e-5 with
    T / tau = 220). A filter told a star tracker 10 times better than it is
    (20 runs) is called overconfident.
    """
    campaign = build(_values(tmp_path, runs=200, duration=560.0, judge_from=60.0))
    run_campaign(campaign, workers=2, say=lambda line: None)
    ens = gather(campaign.output)
    assert len(ens.flown) == 200, [r['error'] for r in ens.failed][:3]
    found = judge(campaign, ens).anees
    independent = found.anees.size / autocorrelation_time(found.anees)
    rate = false_failure_rate(independent, 0.99, 0.95)
    assert rate <= stat_checks.FALSE_FAILURE, (independent, rate)
    assert found.verdict == 'consistent' and found.share_inside >= 0.95, found.message
    scenario = {'/**': {'ros__parameters': dict(SHARED)},
                'attitude_estimator': {'ros__parameters': {'star_tracker_noise': [1e-5] * 3}}}
    detuned = build(_values(tmp_path, runs=20, duration=560.0, judge_from=60.0,
                            scenario=scenario, output=str(tmp_path / 'detuned'),
                            dispersions=dict(DISPERSIONS, noise_seed={
                                'distribution': 'seed', 'node': 'attitude_simulator'})))
    run_campaign(detuned, workers=2, say=lambda line: None)
    found = judge(detuned, gather(detuned.output)).anees
    assert found.verdict == 'overconfident' and found.share_inside < 0.05, found.message


def test_the_ensemble_sees_the_mekf_errors_match_its_sigma(tmp_path):
    """RMS error over 40 runs against the mean reported sigma, after the start-up."""
    campaign = build(_values(tmp_path, runs=40, duration=200.0, judge_from=60.0))
    run_campaign(campaign, workers=0, say=lambda line: None)
    judgement = judge(campaign, gather(campaign.output))
    keep = gather(campaign.output).t >= 60.0
    ratio = judgement.rms[keep] / judgement.sigma[keep]
    # the mean square over 40 runs x 3 axes at one time: chi-square(120) / 120 (the axes'
    # sigmas are equal here), at each of the times' share of the false-failure budget
    alpha = stat_checks.share(int(keep.sum()))
    low, high = stats.chi2.ppf([alpha / 2.0, 1.0 - alpha / 2.0], 120) / 120
    assert np.all(ratio ** 2 > low) and np.all(ratio ** 2 < high), (ratio.min(), ratio.max())


def test_the_controller_flies_on_the_truth_or_on_the_estimate(tmp_path):
    """
    Slew 10 runs to the identity from 0.05 rad (1 sigma per axis) away, wn 0.5, zeta 0.7.

    On the truth each run's final error is under the envelope of the small-angle
    PD's response, theta_0 exp(-zeta wn t) / sqrt(1 - zeta^2) (measured 0.3 to 0.6
    of it: 2e-11 to 9e-11 rad after 60 s; the 0.1 s hold is in it), and every run
    settles inside 1e-3 rad. On the estimate the body points at the estimate: its error is
    the estimator's, of the order of the reported 1 sigma (about 1e-4 rad here), so
    the final pointing errors lie between 1e-6 and 1e-3 rad.
    """
    shared = dict(SHARED, initial_angular_velocity=[0.0, 0.0, 0.0], control_period=0.1,
                  target_orientation=[0.0, 0.0, 0.0, 1.0], natural_frequency=0.5,
                  damping_ratio=0.7)
    dispersions = {'noise_seed': {'distribution': 'seed'}, 'initial_orientation': {
        'distribution': 'rotation', 'sigma': 0.05}}
    finals = {}
    for source in ('truth', 'estimate'):
        campaign = build(_values(tmp_path, runs=10, duration=60.0, control_on=source,
                                 scenario={'/**': {'ros__parameters': shared}},
                                 dispersions=dispersions, settling_band=1e-3,
                                 output=str(tmp_path / source)))
        run_campaign(campaign, workers=0, say=lambda line: None)
        ens = gather(campaign.output)
        assert len(ens.flown) == 10, [r['error'] for r in ens.failed]
        pointing = ens.arrays['pointing']
        assert np.all(pointing[:, 0] < 0.25)
        finals[source] = pointing[:, -1]
        envelope = pointing[:, 0] * math.exp(-0.35 * 60.0) / math.sqrt(1.0 - 0.7 ** 2)
        judgement = judge(campaign, ens)
        if source == 'truth':
            assert np.all(np.isfinite(judgement.settling)) and np.all(judgement.settling > 0)
        if source == 'truth':
            assert np.all(finals['truth'] < envelope), finals['truth'] / envelope
    assert np.all(finals['estimate'] > 1e-6) and np.all(finals['estimate'] < 1e-3), \
        finals['estimate']


def test_rigid_body_campaign_runs_a_file_and_refuses_a_bad_one_in_one_line(tmp_path):
    import yaml
    path = tmp_path / 'campaign.yaml'
    values = _values(tmp_path, runs=3)
    values['output'] = str(tmp_path / 'cli')
    path.write_text(yaml.safe_dump(values))
    done = subprocess.run([sys.executable, '-m', 'rigid_body_dynamics.tools.campaign', str(path),
                           '--workers', '0'], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert 'campaign: 3 of 3 runs flew, 0 failed' in done.stdout
    assert os.path.exists(tmp_path / 'cli' / 'runs.csv')
    assert os.path.exists(tmp_path / 'cli' / 'report.html')
    values['runs'] = 1
    path.write_text(yaml.safe_dump(values))
    bad = subprocess.run([sys.executable, '-m', 'rigid_body_dynamics.tools.campaign', str(path)],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stderr.count('\n') == 1, bad.stderr
    assert 'runs must be an integer >= 2' in bad.stderr
