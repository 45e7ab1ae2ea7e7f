"""
Offline physics demo: theory against simulation for a preset body, no ROS.

``rigid_body_demo [--preset NAME] [--integrator NAME] [--duration S]``
simulates the body, measures what the motion does with the estimators, and
prints it beside the closed-form predictions.
"""

import argparse
import sys

import numpy as np

from .physics import estimators, FreeRigidBody, INTEGRATORS, presets, quaternions, simulate, theory


def _line(label, measured, predicted, unit):
    rel = abs(measured - predicted) / abs(predicted) if predicted else float('nan')
    return f'  {label:<34} {measured:>+.10f} {unit:<6} theory {predicted:>+.10f}  (rel. {rel:.1e})'


def report(preset, integrator, duration, dt):
    """Simulate ``preset`` and return the lines of the comparison."""
    body = presets.get(preset)
    moments = np.array(body.moments)
    run = simulate(moments, body.omega0, body.q0, duration, dt, integrator=integrator)
    lines = [f'{body.name}: {body.description}',
             f'  I = {body.moments} kg m^2, omega0 = {body.omega0} rad/s body, '
             f'{integrator}, dt = {dt} s, {duration} s']
    shape_axis = FreeRigidBody(moments, body.omega0).shape.axis
    if shape_axis is not None:
        ax = shape_axis
        i_perp = moments[(ax + 1) % 3]
        g = float(np.linalg.norm(moments * body.omega0))
        lines.append(_line('body precession Omega (rad/s)',
                           estimators.body_precession_rate(run.t, run.omega, ax).rate,
                           theory.body_precession_rate(i_perp, moments[ax], body.omega0[ax]), ''))
        lab = estimators.lab_precession_rate(run.t, run.q, run.omega, moments, ax)
        lines.append(_line('lab precession |L|/I1 (rad/s)', lab.rate,
                           theory.lab_precession_rate(i_perp, g), ''))
    else:
        st = theory.stability(moments, body.omega0)
        lines.append(f'  spin about axis {st.axis + 1}: {st.kind}'
                     + (f', growth rate {st.rate:.6f} 1/s' if st.kind == 'unstable' else
                        f', wobble {st.rate:.6f} rad/s'))
        period = theory.omega_period(moments, body.omega0)
        if np.isfinite(period) and duration > 2.0 * period:
            mid = int(np.argsort(moments)[1])
            lines.append(_line('flip interval (s)',
                               0.5 * estimators.crossing_period(run.t, run.omega[:, mid], 0),
                               theory.flip_interval(moments, body.omega0), ''))
    cons = estimators.conservation(run.t, run.q, run.omega, moments)
    exact_q, _ = FreeRigidBody(moments, body.omega0, body.q0).state_at(run.t[-1])
    lines.append(f'  conservation: energy {cons.energy:.1e}, |L| {cons.momentum:.1e} (relative), '
                 f'L direction {cons.direction:.1e} rad; attitude vs exact '
                 f'{float(quaternions.angle_between(run.q[-1], exact_q)):.1e} rad')
    return lines


def main(argv=None):
    """Console entry point: print theory against simulation."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--preset', default=None, help='preset name (default: a tour of several)')
    parser.add_argument('--integrator', default='exact', choices=sorted(INTEGRATORS))
    parser.add_argument('--duration', type=float, default=None, help='simulated seconds')
    parser.add_argument('--dt', type=float, default=1e-3, help='step (s)')
    args = parser.parse_args(argv)
    names = [args.preset] if args.preset else ['symmetric_top', 'tennis_racket']
    try:
        for name in names:
            body = presets.get(name)
            print('\n'.join(report(name, args.integrator, args.duration or body.duration,
                                   args.dt)))
    except ValueError as err:
        print(f'rigid_body_demo: {err}', file=sys.stderr)
        return 2
    return 0


if __name__ == '__main__':
    sys.exit(main())
