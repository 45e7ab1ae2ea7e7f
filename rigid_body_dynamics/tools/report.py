"""
rigid_body_report: figures and one HTML page about a run, offline or from a bag.

    rigid_body_report --preset tennis_racket --duration 60 --out report/
    rigid_body_report --record run_bag --duration 20      # from the topics (nodes running)
    rigid_body_report --bag run_bag --out report/         # any rosbag2 folder or .mcap file

Figures (PNG, matplotlib Agg, no screen needed): omega components against time;
the polhode on the inertia ellipsoid (3D, body frame); the herpolhode in the
invariant plane; drift of T, |L| and the L direction on a log scale; the
measured precession against theory (axisymmetric bodies) or the flips of an
unstable spin against theory (tennis racket). index.html shows them with the
table of measured against predicted numbers from the one analysis
(:func:`~rigid_body_dynamics.physics.analysis.analyse`).

``--record`` writes a rosbag2 bag (MCAP storage, metadata version 9) of
``odom``, ``applied_torque`` and the latched ``inertia`` (its transient-local
QoS recorded, so ``ros2 bag play`` latches it again), which ``ros2 bag
info/play``, Foxglove, PlotJuggler, ``rigid_body_analyze`` and ``--bag`` open.
"""

import argparse
import html
import math
import os
import sys

import numpy as np

from . import recorder, report_page
from .. import optional
from ..messages.bags import read_trajectory
from ..physics import INTEGRATORS, presets, quaternions, simulate
from ..physics.analysis import analyse, estimators, momentum_sphere, poinsot, Trajectory
from ..physics.analysis.findings_render import table_rows
from ..physics.sensors import allan_deviation, GyroErrors, GyroModel


def wheels_run(duration=None):
    """
    Run the demo's wheels scene offline: a Trajectory with its wheels (at the control ticks).

    The external torque of each tick (the scene's disturbance plus the dump) is its torque.
    """
    from .demo import WHEEL_SCENE, wheel_scene_ticks
    ticks, wheels = wheel_scene_ticks(duration)
    disturbance = np.array(WHEEL_SCENE['disturbance'])
    t, q, w, speeds, motors, dump = (np.array(c) for c in zip(*ticks))
    return Trajectory.from_samples(np.round(t * 1e9).astype(np.int64), q, w,
                                   presets.get(presets.DEFAULT).moments, dump + disturbance,
                                   origin_ns=0, title='wheels scene (offline)', wheels=wheels,
                                   wheel_speeds=speeds, motor_torques=motors)


def wheels_figures(run, out_dir):
    """
    Figures of a run with wheels: their speeds, and the momentum exchange (world frame).

    |H| of the body (I omega), of the wheels (sum J Omega g) and of the whole
    (their sum, which only external torque changes). Returns {name: (png, curves)}.
    """
    inertia, wheels = run.inertia, run.wheels
    t = run.t
    fig, ax = _figure('Reaction wheel speeds (relative to the body)', 'time (s)',
                      'Omega (rad/s)')
    curves = {}
    for i in range(wheels.count):
        ax.plot(t, run.wheel_speeds[:, i], label=f'wheel_{i}')
        curves[f'wheel_{i}'] = run.wheel_speeds[:, i]
    ax.legend(loc='best')
    out = {'wheel_speeds': (_save(fig, out_dir, 'wheel_speeds.png'), curves)}
    body_h = run.omega @ inertia.tensor.T
    wheel_h = (run.wheel_speeds * np.array(wheels.inertia)) @ np.array(wheels.axes)
    world = {'body I omega': quaternions.rotate(run.q, body_h),
             'wheels sum J Omega g': quaternions.rotate(run.q, wheel_h)}
    world['total H'] = world['body I omega'] + world['wheels sum J Omega g']
    fig, ax = _figure('Momentum exchange: body, wheels and total (world frame)', 'time (s)',
                      '|H| (kg m^2/s)')
    sizes = {label: np.linalg.norm(h, axis=1) for label, h in world.items()}
    for label, size in sizes.items():
        ax.plot(t, size, label=label)
    ax.legend(loc='best')
    out['momentum_exchange'] = (_save(fig, out_dir, 'momentum_exchange.png'), sizes)
    return out


def offline_run(preset, integrator, duration, dt, progress=None, gyro=None):
    """
    Simulate a preset into a Trajectory; ``progress(fraction)`` is called as it goes.

    With ``gyro`` (a GyroModel) returns (trajectory, gyro error): the gyro's
    readings minus the true rate at its samples, (M, 3) rad/s body frame, and
    its rate (Hz), for :func:`make_report`'s Allan-deviation figure.
    """
    body = presets.get(preset)
    result = simulate(body.moments, body.omega0, body.q0, duration, dt, integrator=integrator,
                      progress=progress, gyro=gyro)
    run = Trajectory.from_simulation(result, title=f'{preset} ({integrator}, dt = {dt:g} s)')
    if gyro is None:
        return run
    imu = result.imu
    every = round(1.0 / (imu.rate * dt))
    return run, (imu.omega - result.omega[::every], imu.rate)


def _figure(title, xlabel, ylabel, projection=None):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig = plt.figure(figsize=(8.0, 5.0), dpi=100)
    ax = fig.add_subplot(111, projection=projection)
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    return fig, ax


def _save(fig, out_dir, name):
    import matplotlib.pyplot as plt
    path = os.path.join(out_dir, name)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def allan_figure(error, rate, errors, out_dir):
    """
    Allan deviation of a gyro's error with the lines of its ``errors`` (GyroErrors).

    ``error`` (M, 3) rad/s: readings minus the true rate, as a calibration on
    a still table sees the gyro; ``rate`` Hz. Cluster times from one sample to
    a tenth of the record. Returns (png path, curves) like every figure.
    """
    span = error.shape[0] / rate
    taus = np.logspace(math.log10(1.0 / rate), math.log10(max(span / 10.0, 2.0 / rate)), 40)
    fig, ax = _figure('Allan deviation of the simulated gyro (its error; all axes)',
                      'cluster time tau (s)', 'Allan deviation (rad/s)')
    curves = {}
    for axis in range(3):
        used, adev = allan_deviation(error[:, axis], rate, taus)
        ax.loglog(used, adev, label=f'axis {axis + 1}')
        curves[f'axis {axis + 1}'] = np.stack([used, adev], axis=1)
    n, k = errors.noise_density, errors.bias_random_walk
    if n:
        ax.loglog(used, n / np.sqrt(used), 'k--', label=f'N / sqrt(tau), N = {n:g}')
        curves['N / sqrt(tau)'] = n / np.sqrt(used)
    if k:
        label = f'K sqrt(tau / 3), K = {k:g}'
        if errors.correlation_time:
            label += f' (Gauss-Markov, tau_c = {errors.correlation_time:g} s)'
        ax.loglog(used, k * np.sqrt(used / 3.0), 'k:', label=label)
        curves['K sqrt(tau / 3)'] = k * np.sqrt(used / 3.0)
    ax.legend(loc='best')
    return _save(fig, out_dir, 'allan.png'), curves


def momentum_sphere_figure(moments, l_body, out_dir):
    """
    Draw the momentum sphere |L| = |L0|, its intersection curves and the run's L_body(t).

    ``moments`` principal (kg m^2), ``l_body`` (N, 3) kg m^2/s in the principal frame.
    Loops around the major axis blue, around the minor axis green, the separatrix
    red (physics/analysis/momentum_sphere.py). Returns (png path, curves drawn).
    """
    l0 = float(np.linalg.norm(l_body[0]))
    family = momentum_sphere.curve_family(moments, l0)
    fig, ax = _figure('Momentum sphere |L| = |L0| in the body frame: L runs along its '
                      'intersection with 2T = L.I^-1.L', 'L_1 (kg m^2/s)', 'L_2 (kg m^2/s)',
                      projection='3d')
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
    ax.plot_wireframe(l0 * np.cos(u) * np.sin(v), l0 * np.sin(u) * np.sin(v), l0 * np.cos(v),
                      color='0.85', linewidth=0.4)
    curves = {}
    for name, color, width in (('major', 'tab:blue', 0.8), ('minor', 'tab:green', 0.8),
                               ('separatrix', 'tab:red', 2.0)):
        for k, c in enumerate(family[name]):
            label = {'major': 'loops around the major axis (stable)',
                     'minor': 'loops around the minor axis (stable)',
                     'separatrix': 'separatrix L^2 = 2 T I_2'}[name] if k == 0 else None
            ax.plot(c[:, 0], c[:, 1], c[:, 2], color=color, linewidth=width, label=label)
            curves[f'{name} {k}'] = c
    ax.plot(l_body[:, 0], l_body[:, 1], l_body[:, 2], color='k', linewidth=1.5,
            label='this run')
    curves['this run'] = l_body
    for i in range(3):
        tip = np.zeros(3)
        tip[i] = 1.15 * l0
        ax.text(*tip, f'axis {i + 1}\nI{i + 1} = {moments[i]:.4g}', fontsize=8)
    ax.set_zlabel('L_3 (kg m^2/s)')
    ax.set_box_aspect((1, 1, 1))
    ax.legend(loc='upper left', fontsize=7)
    return _save(fig, out_dir, 'momentum_sphere.png'), curves


def _rigid_body_figures(moments, t, q, w, out_dir):
    """Draw the rigid body's figures: polhode, herpolhode, momentum sphere, drift."""
    figures = {}
    geometry = poinsot.construction(moments, q[0], w[0])
    fig, ax = _figure('Polhode: omega on the inertia ellipsoid omega.I.omega = 2T (body frame)',
                      'omega_1 (rad/s)', 'omega_2 (rad/s)', projection='3d')
    ax.plot_wireframe(*poinsot.ellipsoid_surface(geometry.semi_axes, 40), color='0.8',
                      linewidth=0.5)
    ax.plot(w[:, 0], w[:, 1], w[:, 2], color='tab:red', label='polhode')
    ax.set_zlabel('omega_3 (rad/s)')
    ax.legend(loc='upper left')
    figures['polhode'] = (_save(fig, out_dir, 'polhode.png'), {'polhode': w})

    w_world = quaternions.rotate(q, w)
    e1, e2, _ = estimators.basis_perpendicular(geometry.normal)
    plane = np.stack([w_world @ e1, w_world @ e2], axis=1)
    fig, ax = _figure('Herpolhode: omega in the invariant plane (world frame, normal L)',
                      'along e_u (rad/s)', 'along e_v (rad/s)')
    ax.plot(plane[:, 0], plane[:, 1], color='tab:purple', label='herpolhode')
    ax.plot([0.0], [0.0], 'k+', label='foot of L on the plane')
    ax.set_aspect('equal', adjustable='datalim')
    ax.legend(loc='best')
    figures['herpolhode'] = (_save(fig, out_dir, 'herpolhode.png'), {'herpolhode': plane})

    figures['momentum_sphere'] = momentum_sphere_figure(moments, moments * w, out_dir)

    floor = np.finfo(float).eps
    drift = dict(zip(('|T/T0 - 1|', '||L|/|L0| - 1|', 'angle(L, L0) (rad)'),
                     estimators.drift_series(moments, q, w, q[0], w[0])))
    fig, ax = _figure('Conservation: drift from the first sample (log scale; floor = eps)',
                      'time (s)', 'relative drift')
    for label, values in drift.items():
        ax.semilogy(t, np.maximum(values, floor), label=label)
    ax.legend(loc='best')
    figures['conservation'] = (_save(fig, out_dir, 'conservation.png'), drift)
    return figures


def make_report(run, out_dir, gyro=None):
    """
    Write the figures and index.html for ``run`` into ``out_dir``.

    ``gyro``: optional (error (M, 3) rad/s, rate Hz, GyroErrors) from
    :func:`offline_run` for the Allan-deviation figure. Returns {figure name:
    (png path, {curve label: plotted array})} so that callers (and tests)
    can check what each figure shows, and the table rows.
    """
    os.makedirs(out_dir, exist_ok=True)
    inertia = run.inertia
    moments = inertia.moments
    t, w = run.t, inertia.to_principal(run.omega)
    q = inertia.attitude_to_principal(run.q)
    figures, rows = {}, []

    fig, ax = _figure(f'Angular velocity, body frame: {run.title}', 'time (s)', 'omega (rad/s)')
    curves = {}
    for i in range(3):
        ax.plot(t, w[:, i], label=f'omega_{i + 1} (I{i + 1} = {moments[i]:.4g} kg m^2)')
        curves[f'omega_{i + 1}'] = w[:, i]
    ax.legend(loc='best')
    figures['omega'] = (_save(fig, out_dir, 'omega.png'), curves)

    found = analyse(run)
    if run.wheels is None:
        figures.update(_rigid_body_figures(moments, t, q, w, out_dir))
    else:                        # the Poinsot picture is the rigid body's: the wheels' instead
        figures.update(wheels_figures(run, out_dir))

    pre, stab = found.precession, found.stability
    if pre.kind == 'axisymmetric':
        ax_i = pre.symmetry_axis
        others = [j for j in range(3) if j != ax_i]
        rate, measured = pre.body_rate.theory, pre.body_rate.measured
        angle = np.unwrap(np.arctan2(w[:, others[1]], w[:, others[0]]))
        fig, ax = _figure('Body-frame precession of omega about the symmetry axis',
                          'time (s)', 'angle of omega_perp (rad)')
        ax.plot(t, angle - angle[0], label=f'measured: {measured:.10g} rad/s')
        ax.plot(t, rate * (t - t[0]), '--', label=f'theory Omega = {rate:.10g} rad/s')
        ax.legend(loc='best')
        figures['precession'] = (_save(fig, out_dir, 'precession.png'),
                                 {'measured': angle - angle[0], 'theory': rate * (t - t[0])})
    elif stab.kind == 'unstable':
        mid = int(np.argsort(moments)[1])
        flip = stab.flip_interval.theory
        fig, ax = _figure('Flips of the spin about the intermediate axis (tennis racket)',
                          'time (s)', f'omega_{mid + 1} (rad/s)')
        ax.plot(t, w[:, mid], label=f'omega_{mid + 1}')
        crossings = estimators.crossing_times(t, w[:, mid], direction=0)
        ax.plot(crossings, np.zeros_like(crossings), 'kx', label='flips (measured)')
        if crossings.size and flip is not None and math.isfinite(flip):
            predicted = crossings[0] + flip * np.arange(crossings.size)
            ax.plot(predicted, np.zeros_like(predicted), 'o', mfc='none',
                    label=f'theory: every {flip:.6g} s')
        ax.legend(loc='best')
        figures['flips'] = (_save(fig, out_dir, 'flips.png'),
                            {'omega': w[:, mid], 'flips': crossings})
    if gyro is not None:
        figures['allan'] = allan_figure(*gyro, out_dir)
    rows = table_rows(found)
    interactive = report_page.write(out_dir, report_page.views(moments, t, q, w)) \
        if run.wheels is None else ''    # (the interactive page shows the Poinsot picture)
    _write_html(run, out_dir, figures, rows, interactive)
    return figures, rows


def _write_html(run, out_dir, figures, rows, interactive=''):
    table = '\n'.join(f'<tr><td>{html.escape(a)}</td><td>{html.escape(b)}</td>'
                      f'<td>{html.escape(c)}</td></tr>' for a, b, c in rows)
    images = '\n'.join(f'<figure><img src="{os.path.basename(path)}" alt="{name}">'
                       f'<figcaption>{name}</figcaption></figure>'
                       for name, (path, _) in figures.items())
    moments = ', '.join(f'{m:.6g}' for m in run.inertia.moments)
    span = run.span
    page = f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>rigid_body_dynamics: {html.escape(run.title)}</title>
<script src="plotly.min.js"></script>
<style>body {{ font-family: sans-serif; max-width: 1100px; margin: auto; }}
td, th {{ padding: 2px 12px; text-align: left; }} img {{ max-width: 100%; }}</style></head>
<body><h1>{html.escape(run.title)}</h1>
<p>Principal moments {moments} kg m^2; {len(run)} samples over {span:.6g} s.
Measured against theory by the one analysis (physics/analysis/motion.py):</p>
<table><tr><th>quantity</th><th>measured</th><th>theory</th></tr>
{table}
</table>
<p>Drag to turn a 3D view, scroll to zoom; play the body's animation or move its slider.</p>
{interactive}
<h2>Figures (PNG, for print and for reading without JavaScript)</h2>
{images}
</body></html>
"""
    with open(os.path.join(out_dir, 'index.html'), 'w') as f:
        f.write(page)


def main(argv=None):
    """Console entry point."""
    parser = argparse.ArgumentParser(prog='rigid_body_report',
                                     description='Figures and an HTML page about a run.')
    source = parser.add_mutually_exclusive_group()
    source.add_argument('--preset', help='simulate this preset offline (default symmetric_top), '
                        "or wheels: the demo's scene on four reaction wheels")
    source.add_argument('--bag', help='a rosbag2 folder or a .mcap / .db3 file to report on')
    source.add_argument('--record', metavar='DIR', help='record the running nodes into a new '
                        'rosbag2 bag (MCAP) in this folder, then report on it')
    parser.add_argument('--integrator', default='exact', choices=sorted(INTEGRATORS))
    parser.add_argument('--duration', type=float, help='simulated / recorded seconds (of stamps)')
    parser.add_argument('--dt', type=float, default=1e-3, help='step (s), offline')
    parser.add_argument('--out', default='report', help='output folder (default ./report)')
    noise = parser.add_argument_group(
        'simulated gyro (offline; adds an Allan-deviation figure; the manual, "A noisy IMU")')
    noise.add_argument('--gyro-noise-density', type=float, default=0.0, metavar='N',
                       help='white rate noise N (rad/s/sqrt(Hz))')
    noise.add_argument('--gyro-bias-random-walk', type=float, default=0.0, metavar='K',
                       help='bias random walk K (rad/s^2/sqrt(Hz))')
    noise.add_argument('--gyro-bias-correlation-time', type=float, default=0.0, metavar='S',
                       help='Gauss-Markov bias correlation time (s; 0 = random walk)')
    noise.add_argument('--imu-rate', type=float, default=100.0, help='gyro rate (Hz)')
    noise.add_argument('--noise-seed', type=int, default=0)
    args = parser.parse_args(argv)
    gyro = None
    try:
        optional.require('matplotlib', 'plotly',
                         *(('rosbags',) if args.bag or args.record else ()))
        if args.bag:
            run = read_trajectory(args.bag)[0]
        elif args.record:
            run = recorder.record(args.record, args.duration or 20.0)
        elif args.preset == 'wheels':
            run = wheels_run(args.duration)
        else:
            name = args.preset or presets.DEFAULT
            body = presets.get(name)
            duration = args.duration or body.duration
            last = [-1]

            def progress(fraction):
                step = int(fraction * 10)
                if step != last[0]:
                    last[0] = step
                    print(f'simulating {name}: {100 * fraction:3.0f} % of {duration:g} s',
                          file=sys.stderr, flush=True)
            errors = GyroErrors(args.gyro_noise_density, args.gyro_bias_random_walk,
                                correlation_time=args.gyro_bias_correlation_time)
            if errors.noise_density or errors.bias_random_walk:
                run, (error, rate) = offline_run(
                    name, args.integrator, duration, args.dt, progress,
                    GyroModel(errors, args.imu_rate, seed=args.noise_seed))
                gyro = (error, rate, errors)
            else:
                run = offline_run(name, args.integrator, duration, args.dt, progress)
        figures, rows = make_report(run, args.out, gyro)
    except (ValueError, optional.MissingDependency) as err:
        print(f'rigid_body_report: {err}', file=sys.stderr)
        return 2
    print(f'wrote {os.path.join(args.out, "index.html")} and {len(figures)} figures: '
          + ', '.join(os.path.basename(p) for p, _ in figures.values()))
    for a, b, c in rows:
        print(f'  {a}: {b} (theory {c})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
