"""
The main job: run the simulator node, watch its topics, print what the motion does.

``rigid_body_demo`` starts ``attitude_simulator`` as its own process on the
default body (DDS kept on this machine, a free domain id if none is set),
records its state topics for a stretch of simulated time, measures the
precession rates and conservation from them, prints that beside theory, and
stops the node with Ctrl-C's signal. ``--offline`` does the same without ROS,
straight from the physics layer.
"""

import argparse
import os
import signal
import subprocess
import sys
import time

import numpy as np

from .physics import estimators, FreeRigidBody, INTEGRATORS, presets, quaternions, simulate, theory


def _line(label, measured, predicted, unit):
    rel = abs(measured - predicted) / abs(predicted) if predicted else float('nan')
    return f'  {label:<34} {measured:>+.10f} {unit:<6} theory {predicted:>+.10f}  (rel. {rel:.1e})'


def report(preset, integrator, duration, dt, run=None):
    """Compare a run of ``preset`` (simulated here unless given) with theory; returns lines."""
    body = presets.get(preset)
    moments = np.array(body.moments)
    if run is None:
        run = simulate(moments, body.omega0, body.q0, duration, dt, integrator=integrator)
    lines = [f'{body.name}: {body.description}',
             f'  I = {body.moments} kg m^2, omega0 = {body.omega0} rad/s body, '
             f'{integrator}, dt = {dt} s, {run.t[-1] - run.t[0]:.4g} s of samples']
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


class Recording:
    """Samples recorded from the topics: the same fields simulate() returns."""

    def __init__(self, t, q, omega):
        self.t, self.q, self.omega = t, q, omega


def record_from_node(preset, integrator, duration, rate):
    """
    Start attitude_simulator, record ``duration`` s of simulated time from odom, stop it.

    Runs at real-time factor 4 with stamps = simulated time (publish_clock),
    recording from the first message that arrives (after DDS discovery).
    """
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from nav_msgs.msg import Odometry

    from .nodes.conversions import quaternion_array, vector_array
    rtf = 4.0
    cmd = [sys.executable, '-m', 'rigid_body_dynamics.nodes.simulator', '--ros-args',
           '-p', f'preset:={preset}', '-p', f'integrator:={integrator}',
           '-p', f'integration_rate:={rate}', '-p', f'real_time_factor:={rtf}',
           '-p', 'publish_clock:=true', '--log-level', 'warn']
    node_proc = subprocess.Popen(cmd)
    ctx = Context()
    rclpy.init(context=ctx)
    node = rclpy.create_node('rigid_body_demo', context=ctx)
    executor = SingleThreadedExecutor(context=ctx)
    executor.add_node(node)
    samples = []
    node.create_subscription(Odometry, 'odom', samples.append,
                             QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE))
    print(f'started attitude_simulator (pid {node_proc.pid}, preset {preset}, {integrator}); '
          f'recording {duration:g} s of simulated time at {rtf:g}x real time ...', flush=True)
    deadline = time.monotonic() + 30.0 + duration / rtf

    def sim_time():
        h = samples[-1].header.stamp
        return h.sec + 1e-9 * h.nanosec

    def recorded():
        first = samples[0].header.stamp
        return sim_time() - (first.sec + 1e-9 * first.nanosec)
    try:
        while (not samples or recorded() < duration) and time.monotonic() < deadline:
            if node_proc.poll() is not None:
                raise RuntimeError(f'attitude_simulator exited with code {node_proc.returncode}')
            executor.spin_once(timeout_sec=0.05)
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.shutdown(context=ctx)
        if node_proc.poll() is None:
            node_proc.send_signal(signal.SIGINT)
            try:
                node_proc.wait(10.0)
            except subprocess.TimeoutExpired:
                node_proc.kill()
    if not samples or recorded() < duration:
        raise RuntimeError('no state arrived from attitude_simulator in time')
    print(f'stopped attitude_simulator (exit code {node_proc.returncode}); '
          f'{len(samples)} odom messages', flush=True)
    t = np.array([m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in samples])
    q = np.array([quaternion_array(m.pose.pose.orientation) for m in samples])
    w = np.array([vector_array(m.twist.twist.angular) for m in samples])
    return Recording(t, q, w)


def _ros_environment():
    """Keep DDS on this machine and pick a free domain unless the user chose one."""
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    os.environ.pop('ROS_LOCALHOST_ONLY', None)
    if 'ROS_DOMAIN_ID' in os.environ:
        return None
    from domain_coordinator import domain_id
    reservation = domain_id()
    os.environ['ROS_DOMAIN_ID'] = str(reservation.__enter__())
    return reservation


def main(argv=None):
    """Console entry point: print theory against simulation (nodes, or --offline)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--preset', default=None, help='preset name (default: a tour of several)')
    parser.add_argument('--integrator', default='exact', choices=sorted(INTEGRATORS))
    parser.add_argument('--duration', type=float, default=None, help='simulated seconds')
    parser.add_argument('--dt', type=float, default=1e-3, help='step (s)')
    parser.add_argument('--offline', action='store_true', help='physics only, no ROS nodes')
    args = parser.parse_args(argv)
    names = [args.preset] if args.preset else ['symmetric_top', 'tennis_racket']
    reservation = None if args.offline else _ros_environment()
    try:
        for name in names:
            body = presets.get(name)
            duration = args.duration or body.duration
            run = None
            if not args.offline:
                run = record_from_node(name, args.integrator, duration, 1.0 / args.dt)
            print('\n'.join(report(name, args.integrator, duration, args.dt, run)), flush=True)
    except (ValueError, RuntimeError) as err:
        print(f'rigid_body_demo: {err}', file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    finally:
        if reservation is not None:
            reservation.__exit__(None, None, None)
    return 0


if __name__ == '__main__':
    sys.exit(main())
