"""The one analysis (physics/analysis/): findings against closed forms, statuses, defects."""

import math

import numpy as np
import pytest
from rigid_body_dynamics.physics import FreeRigidBody, presets, simulate
from rigid_body_dynamics.physics.analysis import (analyse, ERROR, OK, theory, Trajectory,
                                                  UNAVAILABLE, WARN)

#: 2026-12-01 in ns since 1970: stamps as a live system has them
EPOCH_2026 = 1_764_547_200_000_000_000


def top_trajectory(duration=10.0, rate=1000.0, origin_ns=0, omega_scale=None):
    """Exact symmetric-top samples at ``rate`` Hz, stamped in integer ns from ``origin_ns``."""
    body = FreeRigidBody((1.0, 1.0, 1.5), (0.3, 0.0, 2.0))
    k = np.arange(int(duration * rate) + 1)
    t_ns = origin_ns + (k * round(1e9 / rate)).astype(np.int64)
    q, w = body.state_at((t_ns - origin_ns) * 1e-9)
    if omega_scale is not None:
        w = w * omega_scale((t_ns - origin_ns) * 1e-9)[:, None]
    return Trajectory.from_samples(t_ns, q, w, (1.0, 1.0, 1.5))


def test_symmetric_top_rates_and_statuses():
    found = analyse(top_trajectory())
    p = found.precession
    assert p.kind == 'axisymmetric' and p.status == OK
    assert p.body_rate.theory == pytest.approx(1.0, rel=1e-15)
    assert p.body_rate.relative_error < 1e-12 and p.lab_rate.relative_error < 1e-12
    assert found.conservation.status == OK and found.conservation.energy_drift < 1e-14
    assert found.stability.kind == 'stable' and found.stability.axis == 2


def test_stamps_since_1970_lose_nothing():
    """Defect 5: integer ns from a 2026 origin give the same rates as from 0 (float s: ~1e-10)."""
    near = analyse(top_trajectory(origin_ns=0)).precession
    far = analyse(top_trajectory(origin_ns=EPOCH_2026)).precession
    assert far.body_rate.relative_error < 1e-12
    assert far.body_rate.measured == pytest.approx(near.body_rate.measured, rel=1e-13)
    # what float seconds since 1970 would have done to the same stamps
    t_float = (EPOCH_2026 + np.arange(10001) * 1_000_000) * 1e-9
    assert np.max(np.abs(np.diff(t_float) - 1e-3)) > 1e-8


def test_top_wobble_and_precession_are_one_frequency():
    """Defect 3: the stable wobble of a top is its body precession Omega, not |L| / I3."""
    found = analyse(top_trajectory())
    wobble, omega = found.stability.wobble_frequency, found.precession.body_rate
    assert wobble.theory == pytest.approx(abs(omega.theory), rel=1e-14)
    assert wobble.measured == pytest.approx(abs(omega.measured), rel=1e-14)
    spin = math.hypot(1.0 * 0.3, 1.5 * 2.0) / 1.5        # what |L| / I3 gives instead
    assert abs(theory.axis_stability((1.0, 1.0, 1.5), 2, spin).rate / wobble.theory - 1) > 4e-3


@pytest.mark.parametrize('periods', [2.3, 2.5, 3.9])
def test_asymmetric_mean_precession_over_whole_periods(periods):
    """Defect 4: a window that is not a whole number of periods still measures the mean rate."""
    body = presets.get('stable_major')
    period = theory.omega_period(body.moments, body.omega0)
    run = simulate(body.moments, body.omega0, body.q0, duration=periods * period, dt=1e-2)
    p = analyse(Trajectory.from_simulation(run)).precession
    assert p.kind == 'asymmetric' and p.status == OK, p.message
    assert p.mean_precession.relative_error < 1e-9
    assert p.omega_period.relative_error < 5e-8     # zero crossings interpolated linearly


def test_a_wrong_precession_is_flagged_not_labelled_ok():
    """A simulator whose body rate turns 1e-3 too fast: precession ERROR, with the error."""
    traj = top_trajectory()
    # rotate omega about the symmetry axis a little faster than physics: Omega * (1 + 1e-3)
    phase = 1e-3 * 1.0 * traj.t
    c, s = np.cos(phase), np.sin(phase)
    w = traj.omega.copy()
    w[:, 0], w[:, 1] = c * traj.omega[:, 0] - s * traj.omega[:, 1], \
        s * traj.omega[:, 0] + c * traj.omega[:, 1]
    bad = Trajectory.from_samples(traj.t_ns, traj.q, w, traj.inertia)
    p = analyse(bad).precession
    assert p.status == ERROR and p.body_rate.status == ERROR
    assert p.body_rate.relative_error == pytest.approx(1e-3, rel=1e-3)


def test_energy_drift_from_the_first_sample_by_stamp():
    """Defect 1 at the analysis level: drift from the baseline, whatever order samples came in."""
    traj = top_trajectory(omega_scale=lambda t: 1.0 + 1e-4 * t)
    shuffled = np.random.default_rng(3).permutation(len(traj))
    again = Trajectory.from_samples(traj.t_ns[shuffled], traj.q[shuffled],
                                    traj.omega[shuffled], traj.inertia)
    for found in (analyse(traj), analyse(again)):
        c = found.conservation
        assert c.baseline_ns == 0
        assert c.energy_drift == pytest.approx((1.0 + 1e-3) ** 2 - 1.0, rel=1e-9)
        assert c.status == ERROR


def test_an_explicit_baseline_outside_the_window():
    traj = top_trajectory(omega_scale=lambda t: 1.0 + 1e-4 * t)
    window = traj.between(start=5.0)
    base = (int(traj.t_ns[0]), traj.q[0], traj.omega[0])
    c = analyse(window, baseline=base).conservation
    assert c.energy_drift == pytest.approx((1.0 + 1e-3) ** 2 - 1.0, rel=1e-9)
    assert analyse(window).conservation.energy_drift < 1.1e-3     # from its own first sample


def test_not_enough_data_and_torque_say_why():
    found = analyse(top_trajectory(duration=0.01))
    assert found.precession.status == UNAVAILABLE
    assert 'not enough data yet (11 of 20 samples)' in found.precession.message
    body = presets.get('tennis_racket')
    run = simulate(body.moments, body.omega0, body.q0, duration=5.0, dt=1e-2,
                   torque=(0.0, 0.0, 0.05))
    found = analyse(Trajectory.from_simulation(run))
    assert found.under_torque and found.conservation.mode == 'balance laws'
    assert found.precession.status == UNAVAILABLE and 'torque' in found.precession.message
    assert found.stability.flip_interval.measured is None
    assert found.stability.status == WARN                       # still unstable


def test_short_window_asymmetric_precession_is_unavailable_with_theory():
    body = presets.get('tennis_racket')
    run = simulate(body.moments, body.omega0, body.q0, duration=5.0, dt=1e-2)
    p = analyse(Trajectory.from_simulation(run)).precession
    assert p.status == UNAVAILABLE and 'shorter than a period' in p.message
    # the theory of the window's newest state (near the separatrix the period is sensitive)
    assert p.omega_period.theory == theory.omega_period(body.moments, run.omega[-1])


def test_json_form_has_the_documented_keys():
    d = analyse(top_trajectory()).to_dict()
    assert d['samples'] == 10001 and d['span_s'] == pytest.approx(10.0)
    assert set(d['conservation']) >= {'status', 'energy_drift', 'momentum_drift',
                                      'direction_drift'}
    assert set(d['precession']) >= {'status', 'body_rate', 'body_rate_theory', 'lab_rate',
                                    'lab_rate_theory'}
    assert set(d['stability']) >= {'status', 'axis', 'class', 'growth_rate',
                                   'growth_rate_theory', 'flip_interval',
                                   'flip_interval_theory'}
    assert d['stability']['axis'] == 3 and d['stability']['growth_rate'] is None


def test_from_samples_drops_bad_samples_and_duplicates():
    traj = top_trajectory(duration=0.1)
    t = np.concatenate([traj.t_ns, traj.t_ns[:5]])
    q = np.concatenate([traj.q, traj.q[:5]])
    w = np.concatenate([traj.omega, traj.omega[:5]])
    q[3] = np.nan
    q[7] = 0.0
    w[9, 1] = np.inf
    again = Trajectory.from_samples(t, q, w, traj.inertia)
    # rows 7 and 9 go; row 3's stamp comes back from its duplicate
    assert len(again) == len(traj) - 2 and again.dropped == 3
    assert np.all(np.diff(again.t_ns) > 0)


@pytest.mark.parametrize('field', ['energy', 'momentum', 'balance', 'rate', 'growth'])
@pytest.mark.parametrize('value', [0.0, -1e-6, float('nan'), float('inf')])
def test_a_tolerance_that_is_not_positive_is_refused_with_the_reason(field, value):
    """A tolerance of 0 (meant as 'strict') switched the check off: a permanent OK."""
    from rigid_body_dynamics.physics.analysis import Tolerances
    with pytest.raises(ValueError, match=f'the {field} tolerance must be a finite number > 0'):
        Tolerances(**{field: value})


def test_a_missing_or_zero_prediction_is_never_a_silent_ok():
    from rigid_body_dynamics.physics.analysis import compare, ERROR, OK, UNAVAILABLE, WARN
    missing = compare(1.0, None, 1e-6)
    assert missing.status == UNAVAILABLE and missing.why == 'no prediction'
    # a prediction of exactly 0: |measured| against the tolerance, in the unit
    assert compare(5e-7, 0.0, 1e-6, 'rad/s').status == OK
    assert compare(5e-5, 0.0, 1e-6, 'rad/s').status == WARN
    far = compare(1.0, 0.0, 1e-6, 'rad/s')
    assert far.status == ERROR and 'absolute' in far.why and far.relative_error is None
    assert compare(1.0 + 5e-7, 1.0, 1e-6).status == OK
    with pytest.raises(ValueError, match='tolerance must be > 0'):
        compare(1.0, 1.0, 0.0)


@pytest.mark.parametrize('name', ['energy_tolerance', 'momentum_tolerance', 'balance_tolerance',
                                  'rate_tolerance'])
def test_the_analyzers_tolerance_parameters_refuse_zero(name):
    from rigid_body_dynamics.nodes.analyzer import PARAMETERS
    from rigid_body_dynamics.ros.parameters import ConfigurationError
    with pytest.raises(ConfigurationError, match=f'{name} must be greater than 0, got 0'):
        PARAMETERS.params[name].check(0.0)
    assert PARAMETERS.params[name].check(1e-9) == 1e-9


def test_rigid_body_analyze_refuses_a_zero_tolerance(capsys):
    from rigid_body_dynamics.tools import analyze
    with pytest.raises(SystemExit) as stop:
        analyze.main(['any.mcap', '--rate-tolerance', '0'])
    assert stop.value.code == 2
    assert 'the rate tolerance must be a finite number > 0, got 0.0' in capsys.readouterr().err


def _cases():
    """Return findings of every kind: a top, a racket (flips, under torque), wheels, an orbit."""
    out = {}
    for name, duration, torque in (('symmetric_top', 10.0, None), ('tennis_racket', 50.0, None),
                                   ('tennis_racket', 5.0, (0.0, 0.0, 0.05)),
                                   ('tennis_racket', 0.05, None)):
        body = presets.get(name)
        run = simulate(body.moments, body.omega0, body.q0, duration=duration, dt=1e-2,
                       torque=torque)
        out[f'{name} {duration} s torque {torque}'] = analyse(Trajectory.from_simulation(run))
    run = simulate((1.0, 2.0, 3.0), (2.0, 0.1, 0.1), (0.0, 0.0, 0.0, 1.0), duration=30.0,
                   dt=1e-2)
    out['stable about the minor axis'] = analyse(Trajectory.from_simulation(run))
    out['wheels exchanging momentum'] = analyse(wheel_trajectory(duration=2.0))
    out['a free gyrostat'] = analyse(_free_gyrostat((1.0, 1.0, 1.5), ((0.0, 0.0, 1.0),), (0.1,),
                                                    (20.0,), (0.3, 0.0, 2.0), 10.0))
    from scipy.spatial.transform import Rotation
    from test_libration import _fly, MOMENTS
    trajectory, _ = _fly(MOMENTS, Rotation.identity(), [0.001, 0.002, -0.0015])
    out['gravity-gradient libration'] = analyse(trajectory, gravity_gradient=True)
    trajectory, _ = _fly(MOMENTS, Rotation.identity(), [0.001, 0.0, 0.0],
                         elements=[7.5e6, 0.01, 1.0, 0.0, 0.0, 0.0], steps=300)
    out['an eccentric orbit'] = analyse(trajectory, gravity_gradient=True)
    return out


def wheel_trajectory(duration=10.0, inertia_error=1.0):
    """
    Simulate a gyrostat with four pyramid wheels under varying motor torques, at 100 Hz.

    ``inertia_error`` scales the wheel inertia the analysis is told (1: the true one).
    """
    from rigid_body_dynamics.physics.dynamics.gyrostat import GyrostatIntegrator, Wheels
    axes = [c / math.sqrt(3.0) for g in ((1, 1, 1), (-1, 1, 1), (-1, -1, 1), (1, -1, 1))
            for c in g]
    wheels = Wheels(axes, (0.02,) * 4, coulomb=(1e-4,) * 4, viscous=(1e-6,) * 4)
    stepper = GyrostatIntegrator((1.0, 2.0, 3.0), wheels, 1e-3, omega0=(0.3, 1.5, -0.4),
                                 speeds0=(100.0, -50.0, 0.0, 20.0))
    rows = []
    for k in range(int(duration * 1000) + 1):
        if k % 10 == 0:
            rows.append((k * 1_000_000, stepper.q, stepper.omega, stepper.speeds,
                         stepper.applied))
        if k % 100 == 0:      # a new motor command every 0.1 s
            stepper.command_motors([0.02 * math.sin(0.3 * k / 100 + i) for i in range(4)])
        stepper.step()
    told = Wheels(axes, tuple(0.02 * inertia_error for _ in range(4)), coulomb=(1e-4,) * 4,
                  viscous=(1e-6,) * 4)
    t, q, w, speeds, motors = (np.array(c) for c in zip(*rows))
    return Trajectory.from_samples(t, q, w, (1.0, 2.0, 3.0), origin_ns=0, wheels=told,
                                   wheel_speeds=speeds, motor_torques=motors)


def test_a_momentum_exchange_with_wheels_is_conserved_and_a_wrong_wheel_is_not():
    """Total H constant to round-off; T follows the motor work to the quadrature's error."""
    found = analyse(wheel_trajectory())
    c = found.conservation
    assert c.mode == 'momentum exchange' and c.status == OK, c
    assert c.momentum_drift < 1e-13 and c.direction_drift < 1e-13
    assert c.energy_residual < 1e-3                   # trapezoid of a held torque at 100 Hz
    assert found.precession.status == UNAVAILABLE and 'motor' in found.precession.message
    wrong = analyse(wheel_trajectory(inertia_error=1.01)).conservation
    assert wrong.status in (WARN, ERROR) and 'total H' in wrong.message


def test_the_analyzers_diagnostics_read_back_into_the_same_findings():
    """
    The one rendering to key/values and its reader agree (the demo prints what it reads).

    Through the real path: DiagnosticStatus with string values, read back by key into
    Findings, printed by the one text renderer: the same lines as the findings printed
    directly, for every kind of finding. A key renamed on one side only fails here.
    """
    from rigid_body_dynamics.physics.analysis.findings_render import table_rows, text_lines
    from rigid_body_dynamics.nodes import analyzer_diagnostics as diagnostics
    from rigid_body_dynamics.ros.conversions import status_values
    seen = set()
    for case, found in _cases().items():
        statuses = diagnostics.statuses(found, 'attitude_analyzer', 'hw', 7)
        received = {st.name.split(': ', 1)[1]: (st.level, st.message, status_values(st))
                    for st in statuses}
        for _level, _message, values in received.values():
            seen |= set(values)
        back = diagnostics.findings_from(received)
        assert text_lines(back)[1:] == text_lines(found)[1:], case
        assert table_rows(back) == table_rows(found), case
    # every key written is in the manual's table (made from the same module)
    import re
    from rigid_body_dynamics.physics.analysis.findings_render import reference_rows
    listed = [re.escape(key).replace('<axis>', '[1-3]') for _sec, key, _m in reference_rows()]
    assert [k for k in seen if not any(re.fullmatch(p, k) for p in listed)] == []
    # every quantity of the reader's table was written by some case, with its unit
    for key in ('body rate, measured (rad/s)', 'lab rate, measured (rad/s)',
                'omega period, measured (s)',
                'mean precession of axis 3 about L, measured (rad/s)',
                'growth rate, measured (1/s)', 'flip interval, measured (s)',
                'wobble frequency, measured (rad/s)', 'circled axis',
                'pitch libration frequency, measured (rad/s)',
                'roll-yaw libration frequency, slow, measured (rad/s)',
                'roll-yaw libration frequency, fast, measured (rad/s)',
                'Jacobi integral drift (rel.)', 'stability region'):
        assert key in seen, key


def _free_gyrostat(moments, axes, j, speeds0, omega0, duration, dt=1e-2):
    """Sample a torque-free gyrostat at ``dt`` (the motors off): a Trajectory with wheels."""
    from rigid_body_dynamics.physics.dynamics.gyrostat import GyrostatIntegrator, Wheels
    wheels = Wheels(axes, j)
    body = GyrostatIntegrator(moments, wheels, dt, omega0=omega0, speeds0=speeds0)
    rows = [(0, body.q, body.omega, body.speeds)]
    for k in range(1, int(round(duration / dt)) + 1):
        body.step()
        rows.append((int(round(k * dt * 1e9)), body.q, body.omega, body.speeds))
    t, q, w, s = (np.array(c) for c in zip(*rows))
    return Trajectory.from_samples(t, q, w, moments, origin_ns=0, wheels=wheels,
                                   wheel_speeds=s, motor_torques=np.zeros_like(s))


def test_an_axisymmetric_gyrostat_precesses_at_the_gyrostat_rate():
    """Rotor on the symmetry axis: body rate ((I3 - I1) omega3 + h) / I1, to 1e-9."""
    found = analyse(_free_gyrostat((1.0, 1.0, 1.5), ((0.0, 0.0, 1.0),), (0.1,), (20.0,),
                                   (0.3, 0.0, 2.0), 10.0))
    p = found.precession
    assert p.kind == 'gyrostat' and p.status == OK
    assert p.body_rate.theory == pytest.approx(((1.5 - 1.0) * 2.0 + 2.0) / 1.0, rel=1e-12)
    assert p.body_rate.relative_error < 1e-9
    assert found.conservation.mode == 'momentum exchange' and found.conservation.status == OK


@pytest.mark.parametrize('h,kind', [(2.0, 'stable'), (0.5, 'unstable')])
def test_the_gyrostat_theory_judges_a_spin_about_the_intermediate_axis(h, kind):
    """A rotor of momentum h along axis 2 of (1, 2, 3) spinning at 1 rad/s: h^2 > omega^2."""
    found = analyse(_free_gyrostat((1.0, 2.0, 3.0), ((0.0, 1.0, 0.0),), (0.05,), (h / 0.05,),
                                   (1e-6, 1.0, 0.0), 2.0))
    s = found.stability
    assert s.axis == 1 and s.kind == kind and 'gyrostat theory' in s.message
    if kind == 'unstable':
        assert s.status == WARN and s.growth_rate.theory == pytest.approx(0.5, rel=1e-12)
    else:
        assert s.status == OK and s.growth_rate is None
