"""
rigid_body_report: figures and one HTML page about a run, offline or from a recording.

    rigid_body_report --preset tennis_racket --duration 60 --out report/
    rigid_body_report --record run.npz --duration 20       # from the topics (nodes running)
    rigid_body_report --recording run.npz --out report/

Figures (PNG, matplotlib Agg, no screen needed): omega components against time;
the polhode on the inertia ellipsoid (3D, body frame); the herpolhode in the
invariant plane; drift of T, |L| and the L direction on a log scale; the
measured precession against theory (axisymmetric bodies) or the flips of an
unstable spin against theory (tennis racket). index.html shows them with a
table of measured against predicted numbers.

A recording is a .npz file with arrays ``t`` (N,) s, ``q`` (N, 4) x-y-z-w,
``omega`` (N, 3) rad/s body frame, ``tensor`` (3, 3) kg m^2 body frame and
optionally ``torque`` (N, 3) N m body frame.
"""

import argparse
import html
import math
import os
import sys
import time

import numpy as np

from .physics import (estimators, Inertia, INTEGRATORS, presets, quaternions, simulate,
                      theory)


class Run:
    """The samples a report is made from (body frame = the inertia's frame)."""

    def __init__(self, t, q, omega, inertia, torque=None, title=''):
        self.t = np.asarray(t, dtype=float)
        self.q = quaternions.normalize(np.asarray(q, dtype=float))
        self.omega = np.asarray(omega, dtype=float)
        self.torque = np.zeros_like(self.omega) if torque is None else np.asarray(torque, float)
        self.inertia = inertia
        self.title = title


def load_recording(path):
    """Read a recording (.npz, see the module docstring); ValueError saying what is wrong."""
    try:
        data = np.load(path)
        t, q, w, tensor = data['t'], data['q'], data['omega'], data['tensor']
        torque = data['torque'] if 'torque' in data.files else None
    except (OSError, KeyError, ValueError, EOFError) as err:
        raise ValueError(f'cannot read recording {path!r}: {err}') from None
    n = t.shape[0] if t.ndim == 1 else -1
    if n < 3 or q.shape != (n, 4) or w.shape != (n, 3) or tensor.shape != (3, 3):
        raise ValueError(f'recording {path!r} does not hold t (N,), q (N, 4), omega (N, 3) and '
                         f'tensor (3, 3) with N >= 3')
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(q)) and np.all(np.isfinite(w))):
        raise ValueError(f'recording {path!r} holds non-finite samples')
    if torque is None or torque.shape != w.shape:
        torque = np.zeros_like(w)
    t, q, w, torque = estimators.sort_samples(t, q, w, torque)
    return Run(t, q, w, Inertia.from_tensor(tensor), torque, title=os.path.basename(path))


def save_recording(path, run):
    """Write ``run`` as a recording (.npz)."""
    np.savez(path, t=run.t, q=run.q, omega=run.omega, tensor=run.inertia.tensor,
             torque=run.torque)


def offline_run(preset, integrator, duration, dt, progress=None):
    """Simulate a preset; ``progress(fraction)`` is called as the run goes."""
    body = presets.get(preset)
    result = simulate(body.moments, body.omega0, body.q0, duration, dt, integrator=integrator,
                      progress=progress)
    return Run(result.t, result.q, result.omega, result.inertia, result.torque,
               title=f'{preset} ({integrator}, dt = {dt:g} s)')


def record(path, duration, timeout=60.0):
    """Record odom, applied_torque and the latched inertia from the running nodes."""
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from geometry_msgs.msg import InertiaStamped, WrenchStamped
    from nav_msgs.msg import Odometry
    from .nodes import conversions as conv
    ctx = Context()
    rclpy.init(context=ctx)
    node = rclpy.create_node('rigid_body_report', context=ctx)
    executor = SingleThreadedExecutor(context=ctx)
    executor.add_node(node)
    odom, torque, inertia = [], [], []
    deep = QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE)
    node.create_subscription(Odometry, 'odom', odom.append, deep)
    node.create_subscription(WrenchStamped, 'applied_torque', torque.append, deep)
    node.create_subscription(InertiaStamped, 'inertia', inertia.append, QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL))
    deadline = time.monotonic() + timeout + duration

    def span():
        return (conv.time_ns(odom[-1].header.stamp) - conv.time_ns(odom[0].header.stamp)) * 1e-9
    try:
        while time.monotonic() < deadline and not (inertia and odom and span() >= duration):
            executor.spin_once(timeout_sec=0.05)
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.shutdown(context=ctx)
    if not inertia or len(odom) < 3:
        raise ValueError('nothing recorded: is attitude_simulator running in this domain?')
    i = inertia[-1].inertia
    t = np.array([conv.time_ns(m.header.stamp) * 1e-9 for m in odom])
    tq = {conv.time_ns(m.header.stamp): conv.vector_array(m.wrench.torque) for m in torque}
    run = Run(t, [conv.quaternion_array(m.pose.pose.orientation) for m in odom],
              [conv.vector_array(m.twist.twist.angular) for m in odom],
              Inertia.from_tensor([i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz]),
              [tq.get(conv.time_ns(m.header.stamp), np.zeros(3)) for m in odom],
              title=os.path.basename(path))
    save_recording(path, run)
    return run


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


def make_report(run, out_dir):
    """
    Write the figures and index.html for ``run`` into ``out_dir``.

    Returns {figure name: (png path, {curve label: plotted array})} so that
    callers (and tests) can check what each figure shows, and the table rows.
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

    energy = 0.5 * np.sum(moments * w * w, axis=1)
    two_t = 2.0 * energy[0]
    fig, ax = _figure('Polhode: omega on the inertia ellipsoid omega.I.omega = 2T (body frame)',
                      'omega_1 (rad/s)', 'omega_2 (rad/s)', projection='3d')
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
    a = np.sqrt(two_t / moments)
    ax.plot_wireframe(a[0] * np.cos(u) * np.sin(v), a[1] * np.sin(u) * np.sin(v),
                      a[2] * np.cos(v), color='0.8', linewidth=0.5)
    ax.plot(w[:, 0], w[:, 1], w[:, 2], color='tab:red', label='polhode')
    ax.set_zlabel('omega_3 (rad/s)')
    ax.legend(loc='upper left')
    figures['polhode'] = (_save(fig, out_dir, 'polhode.png'), {'polhode': w})

    w_world = quaternions.rotate(q, w)
    l_world = quaternions.rotate(q, moments * w)
    normal = l_world[0] / np.linalg.norm(l_world[0])
    e1, e2, _ = estimators._basis_perpendicular(normal)
    plane = np.stack([w_world @ e1, w_world @ e2], axis=1)
    fig, ax = _figure('Herpolhode: omega in the invariant plane (world frame, normal L)',
                      'along e_u (rad/s)', 'along e_v (rad/s)')
    ax.plot(plane[:, 0], plane[:, 1], color='tab:purple', label='herpolhode')
    ax.plot([0.0], [0.0], 'k+', label='foot of L on the plane')
    ax.set_aspect('equal', adjustable='datalim')
    ax.legend(loc='best')
    figures['herpolhode'] = (_save(fig, out_dir, 'herpolhode.png'), {'herpolhode': plane})

    floor = np.finfo(float).eps
    g = np.linalg.norm(l_world, axis=1)
    drift = {'|T/T0 - 1|': np.abs(energy / energy[0] - 1.0),
             '||L|/|L0| - 1|': np.abs(g / g[0] - 1.0),
             'angle(L, L0) (rad)': estimators.vector_angle(l_world, l_world[0])}
    fig, ax = _figure('Conservation: drift from the first sample (log scale; floor = eps)',
                      'time (s)', 'relative drift')
    for label, values in drift.items():
        ax.semilogy(t, np.maximum(values, floor), label=label)
    ax.legend(loc='best')
    figures['conservation'] = (_save(fig, out_dir, 'conservation.png'), drift)
    rows += [('largest energy drift (rel.)', f'{drift["|T/T0 - 1|"].max():.2e}', '0'),
             ('largest |L| drift (rel.)', f'{drift["||L|/|L0| - 1|"].max():.2e}', '0'),
             ('largest L direction drift (rad)', f'{drift["angle(L, L0) (rad)"].max():.2e}',
              '0')]

    shape_axis = inertia.symmetry_axis
    if shape_axis is not None:
        ax_i = shape_axis
        others = [j for j in range(3) if j != ax_i]
        i_perp = float(np.mean(moments[others]))
        rate = theory.body_precession_rate(i_perp, moments[ax_i], w[0, ax_i])
        angle = np.unwrap(np.arctan2(w[:, others[1]], w[:, others[0]]))
        measured = estimators.body_precession_rate(t, w, ax_i)
        lab = estimators.lab_precession_rate(t, q, w, moments, ax_i)
        lab_theory = theory.lab_precession_rate(i_perp, float(g[0]))
        fig, ax = _figure('Body-frame precession of omega about the symmetry axis',
                          'time (s)', 'angle of omega_perp (rad)')
        ax.plot(t, angle - angle[0], label=f'measured: {measured.rate:.10g} rad/s')
        ax.plot(t, rate * (t - t[0]), '--', label=f'theory Omega = {rate:.10g} rad/s')
        ax.legend(loc='best')
        figures['precession'] = (_save(fig, out_dir, 'precession.png'),
                                 {'measured': angle - angle[0], 'theory': rate * (t - t[0])})
        rows += [('body precession rate (rad/s)', f'{measured.rate:.10g}', f'{rate:.10g}'),
                 ('lab precession rate (rad/s)', f'{lab.rate:.10g}', f'{lab_theory:.10g}')]
    elif not inertia.is_spherical:
        stab = theory.stability(moments, w[0])
        mid = int(np.argsort(moments)[1])
        flip = theory.flip_interval(moments, w[0])
        fig, ax = _figure('Flips of the spin about the intermediate axis (tennis racket)',
                          'time (s)', f'omega_{mid + 1} (rad/s)')
        ax.plot(t, w[:, mid], label=f'omega_{mid + 1}')
        crossings = estimators.crossing_times(t, w[:, mid], direction=0)
        ax.plot(crossings, np.zeros_like(crossings), 'kx', label='flips (measured)')
        if crossings.size and math.isfinite(flip):
            predicted = crossings[0] + flip * np.arange(crossings.size)
            ax.plot(predicted, np.zeros_like(predicted), 'o', mfc='none',
                    label=f'theory: every {flip:.6g} s')
        ax.legend(loc='best')
        figures['flips'] = (_save(fig, out_dir, 'flips.png'),
                            {'omega': w[:, mid], 'flips': crossings})
        rows.append(('stability of the initial spin', stab.kind, f'axis {stab.axis + 1}'))
        if crossings.size >= 2:
            rows.append(('flip interval (s)', f'{np.diff(crossings).mean():.10g}',
                         f'{flip:.10g}'))
    _write_html(run, out_dir, figures, rows)
    return figures, rows


def _write_html(run, out_dir, figures, rows):
    table = '\n'.join(f'<tr><td>{html.escape(a)}</td><td>{html.escape(b)}</td>'
                      f'<td>{html.escape(c)}</td></tr>' for a, b, c in rows)
    images = '\n'.join(f'<figure><img src="{os.path.basename(path)}" alt="{name}">'
                       f'<figcaption>{name}</figcaption></figure>'
                       for name, (path, _) in figures.items())
    moments = ', '.join(f'{m:.6g}' for m in run.inertia.moments)
    page = f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>rigid_body_dynamics: {html.escape(run.title)}</title>
<style>body {{ font-family: sans-serif; max-width: 900px; margin: auto; }}
td, th {{ padding: 2px 12px; text-align: left; }} img {{ max-width: 100%; }}</style></head>
<body><h1>{html.escape(run.title)}</h1>
<p>Principal moments {moments} kg m^2; {run.t.size} samples over {run.t[-1] - run.t[0]:.6g} s.</p>
<table><tr><th>quantity</th><th>measured</th><th>theory</th></tr>
{table}
</table>
{images}
</body></html>
"""
    with open(os.path.join(out_dir, 'index.html'), 'w') as f:
        f.write(page)


def main(argv=None):
    """Console entry point."""
    parser = argparse.ArgumentParser(description='Figures and an HTML page about a run.')
    source = parser.add_mutually_exclusive_group()
    source.add_argument('--preset', help='simulate this preset offline (default symmetric_top)')
    source.add_argument('--recording', help='a .npz recording to report on')
    source.add_argument('--record', help='record the running nodes into this .npz, then report')
    parser.add_argument('--integrator', default='exact', choices=sorted(INTEGRATORS))
    parser.add_argument('--duration', type=float, help='simulated / recorded seconds')
    parser.add_argument('--dt', type=float, default=1e-3, help='step (s), offline')
    parser.add_argument('--out', default='report', help='output folder (default ./report)')
    args = parser.parse_args(argv)
    try:
        if args.recording:
            run = load_recording(args.recording)
        elif args.record:
            run = record(args.record, args.duration or 20.0)
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
            run = offline_run(name, args.integrator, duration, args.dt, progress)
        figures, rows = make_report(run, args.out)
    except ValueError as err:
        print(f'rigid_body_report: {err}', file=sys.stderr)
        return 2
    print(f'wrote {os.path.join(args.out, "index.html")} and {len(figures)} figures: '
          + ', '.join(os.path.basename(p) for p, _ in figures.values()))
    for a, b, c in rows:
        print(f'  {a}: {b} (theory {c})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
