"""
The demo's libration scene: a satellite held near the local vertical by the gravity gradient.

I = (2, 3, 1.2) kg m^2 (the Lagrange region: I_y > I_x > I_z, roll x, pitch y, yaw z)
on a 500 km circular equatorial orbit, its principal axes along LVLH at t = 0 and
turning with it at the orbit rate n, nudged by a rate offset of a few micro-rad/s,
so that it librates by about a milliradian: the analyzer's ``orbit`` status
measures the pitch and the two roll-yaw frequencies over 60 000 s (10.6 orbits)
against the small-angle theory (Wie, *Space Vehicle Dynamics and Control*,
section 6.3) and the drift of the Jacobi integral. ``doc/examples/libration.yaml``
holds the same values (the suite checks). The equatorial orbit puts LVLH at t = 0
on simple axes: r along world x, v along world y, so LVLH x is world y, LVLH y
world -z and LVLH z (nadir) world -x: q = (-1/2, -1/2, 1/2, 1/2).
"""

import math
import os

import numpy as np

#: The scene: node parameters, and the rate offset the initial angular velocity carries.
LIBRATION = 'libration'
LIBRATION_SCENE = {
    'inertia': [2.0, 3.0, 1.2],
    'orbit_elements': [6878137.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    'initial_orientation': [-0.5, -0.5, 0.5, 0.5],
    'rate_offset': [1.0e-6, 2.0e-6, -1.5e-6],          # rad/s, body
    'integration_rate': 1.0, 'publish_rate': 0.1, 'real_time_factor': 5000.0,
    'window': 60000.0,
}


def initial_angular_velocity(scene=LIBRATION_SCENE):
    """
    Return the body's initial angular velocity (rad/s, body frame): (0, -n, 0) + the offset.

    Turning with LVLH means turning at the orbit rate n = sqrt(mu / a^3) about
    LVLH's -y (the orbit normal), which is the body's -y at t = 0.
    """
    from ..physics.environment import MU_EARTH
    n = math.sqrt(MU_EARTH / scene['orbit_elements'][0] ** 3)
    return [float(c) for c in np.add((0.0, -n, 0.0), scene['rate_offset'])]


def parameters(scene=LIBRATION_SCENE):
    """Return (all nodes', the simulator's, the analyzer's) parameters of the scene."""
    shared = {'inertia': scene['inertia'], 'gravity_gradient': True}
    sim = {'orbit_elements': scene['orbit_elements'],
           'initial_orientation': scene['initial_orientation'],
           'initial_angular_velocity': initial_angular_velocity(scene),
           'integration_rate': scene['integration_rate'],
           'publish_rate': scene['publish_rate'], 'real_time_factor': scene['real_time_factor'],
           'publish_clock': True, 'publish_imu': False}
    # odom comes every 10 s of stamps: gaps and jumps below 100 s are no restart
    analyzer = {'window': scene['window'], 'max_gap': 100.0, 'reset_jump': 100.0}
    return shared, sim, analyzer


def _headline(how):
    s = LIBRATION_SCENE
    height = (s['orbit_elements'][0] - 6378137.0) / 1e3
    return (f'{LIBRATION}: the gravity gradient holds a satellite (I = {tuple(s["inertia"])} '
            f'kg m^2) near the local vertical of a {height:.0f} km circular orbit, released '
            f'turning with it {how}; over {s["window"]:.0f} s:')


def libration_offline():
    """Fly the scene on the exact integrator without ROS and analyse it (the one analysis)."""
    from ..physics import Inertia, make_integrator
    from ..physics.analysis import analyse, Trajectory
    from ..physics.analysis.findings_render import orbit_lines
    from ..physics.environment import GravityGradient, KeplerOrbit, MU_EARTH, SpaceEnvironment
    s = LIBRATION_SCENE
    orbit = KeplerOrbit(s['orbit_elements'])
    env = SpaceEnvironment(orbit, None, [GravityGradient(s['inertia'], MU_EARTH)])
    dt = 1.0 / s['integration_rate']
    every = round(s['integration_rate'] / s['publish_rate'])
    body = make_integrator('exact', s['inertia'], dt, s['initial_orientation'],
                           initial_angular_velocity())
    rows = []
    for k in range(round(s['window'] * s['integration_rate']) + 1):
        if k % every == 0:
            r, v = orbit.state(body.time)
            rows.append((round(body.time * 1e9), body.q, body.omega, r, v))
        body.step((0.0, 0.0, 0.0), None, env)
    t, q, w, r, v = (np.array(c) for c in zip(*rows))
    trajectory = Trajectory.from_samples(t, q, w, Inertia(s['inertia']), origin_ns=0,
                                         position=r, velocity=v)
    return [_headline('(offline)')] + orbit_lines(
        analyse(trajectory, gravity_gradient=True).orbit)


def run_libration():
    """Run the scene on attitude_simulator and attitude_analyzer; the analyzer's orbit lines."""
    from diagnostic_msgs.msg import DiagnosticArray
    from nav_msgs.msg import Odometry

    from ..nodes import analyzer_diagnostics as diagnostics
    from ..physics.analysis.findings_render import orbit_lines
    from ..ros.client import interrupt, RosClient, start_node
    from ..ros.parameters import write_parameters_file
    from ..ros.conversions import status_values, time_ns
    shared, sim_params, analyzer_params = parameters()
    params = write_parameters_file({'/**': shared, '/**/attitude_simulator': sim_params,
                                    '/**/attitude_analyzer': analyzer_params})
    end = round(LIBRATION_SCENE['window'] * 1e9)
    newest = {'odom': -1}
    orbit = {}
    procs = []

    def on_diagnostics(msg):
        for st in msg.status:
            if st.name == 'attitude_analyzer: orbit' and newest['odom'] >= end:
                orbit['status'] = (st.level, st.message, status_values(st))

    def done():
        for proc, name in zip(procs, ('attitude_simulator', 'attitude_analyzer')):
            if proc.poll() is not None:
                raise RuntimeError(f'{name} exited with code {proc.returncode}')
        return 'status' in orbit
    client = RosClient('rigid_body_demo')
    try:
        node = client.node
        node.create_subscription(Odometry, 'odom', lambda m: newest.__setitem__(
            'odom', max(newest['odom'], time_ns(m.header.stamp))), 10)
        node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, 10)
        quiet = ['--log-level', 'warn', '--params-file', params]
        procs.append(start_node('simulator', list(quiet)))
        procs.append(start_node('analyzer', list(quiet)))
        print(f'{LIBRATION}: started attitude_simulator in orbit at '
              f'{LIBRATION_SCENE["real_time_factor"]:g}x real time (pid {procs[0].pid}) and '
              f'attitude_analyzer (pid {procs[1].pid}) ...', flush=True)
        client.spin_until(done, 120.0 + LIBRATION_SCENE['window'] /
                          LIBRATION_SCENE['real_time_factor'], 'the orbit status of the window')
    finally:
        client.close()
        codes = [interrupt(proc) for proc in reversed(procs)]
        os.unlink(params)
    found = diagnostics.findings_from({'orbit': orbit['status']}).orbit
    return [_headline('(attitude_simulator, attitude_analyzer)')] + orbit_lines(found) + [
        f'  stopped attitude_analyzer and attitude_simulator (exit codes '
        f'{", ".join(str(c) for c in codes)})']
