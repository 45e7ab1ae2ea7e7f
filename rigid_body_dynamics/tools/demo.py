"""
The main job: run both nodes on a built-in body and print what the analysis finds.

``rigid_body_demo`` starts ``attitude_simulator`` and ``attitude_analyzer`` as
their own processes (DDS kept on this machine, a free domain id if none is
set), waits until the analyzer's diagnostics hold a full window of
measurements, prints them beside theory in a few lines, and stops both nodes
with Ctrl-C's signal: first the default symmetric top (precession rates,
conservation), then the tennis racket (instability, growth rate, flips),
then the closed loop: ``attitude_controller`` slewing the default body at
rest to a target in lockstep, its settling time against the PD theory and
the pointing error at the end; then the same body flown by four reaction
wheels against a disturbance, the wheels spinning up and unloading their
momentum; then a 3U CubeSat in a polar orbit detumbled by B-dot with
magnetorquers (``--preset satellite``, the manual's ``satellite.yaml``); and
a satellite librating about the local vertical under the gravity gradient, its
frequencies against the small-angle theory (``--preset libration``, the manual's
``libration.yaml``; not part of the tour).
``--offline`` measures the same straight from the physics layer and the engine,
without ROS.
"""

import argparse
import math
import os
import sys
import time

import numpy as np

from .libration_scene import LIBRATION, libration_offline, run_libration
from ..physics import FreeRigidBody, INTEGRATORS, presets, quaternions, simulate
from ..physics.analysis import analyse, Trajectory
from ..physics.analysis.findings_render import text_lines
from ..physics.control import QuaternionPD, settling_time

#: The closed-loop scene: 30 degrees about x from rest, wn 2 rad/s, zeta 0.7, 100 Hz, 10 s.
SLEW = {'target': (math.sin(math.radians(15.0)), 0.0, 0.0, math.cos(math.radians(15.0))),
        'natural_frequency': 2.0, 'damping_ratio': 0.7, 'control_period': 0.01,
        'duration': 10.0}
CLOSED_LOOP = 'closed_loop'
#: The wheels scene: 15 degrees about x from rest on four pyramid wheels, wn 1 rad/s, zeta 0.7,
#: against a constant 0.02 N m about body z that fills the wheels until they dump, 40 s.
WHEELS = 'wheels'
_PYRAMID = [c / math.sqrt(3.0) for g in ((1, 1, 1), (-1, 1, 1), (-1, -1, 1), (1, -1, 1))
            for c in g]
WHEEL_SCENE = {'target': (math.sin(math.radians(7.5)), 0.0, 0.0, math.cos(math.radians(7.5))),
               'natural_frequency': 1.0, 'damping_ratio': 0.7, 'duration': 40.0,
               'disturbance': (0.0, 0.0, 0.02),
               'wheels': {'wheel_axes': _PYRAMID, 'wheel_inertia': [0.01] * 4,
                          'wheel_max_torque': [0.2] * 4, 'wheel_max_speed': [30.0] * 4,
                          'wheel_friction_coulomb': [1e-4] * 4,
                          'wheel_friction_viscous': [1e-6] * 4}}


#: The satellite scene (doc/examples/satellite.yaml has the same values; the suite checks):
#: a 3U CubeSat tumbling at 10 deg/s in a 500 km circular polar orbit, B-dot at 1 Hz.
SATELLITE = 'satellite'
SATELLITE_SCENE = {
    'inertia': [0.033, 0.033, 0.007],
    'orbit_elements': [6878137.0, 0.0, math.pi / 2, 0.0, 0.0, 0.0],
    'initial_angular_velocity': [0.10077, 0.10077, 0.10077],
    'magnetorquer_max_dipole': [0.2, 0.2, 0.2], 'bdot_gain': 1e5,
    'integration_rate': 10.0, 'control_period': 1.0, 'target_rate': math.radians(0.5),
}


def _satellite_parameters(params_file=None):
    """
    Return the scene as node parameters: (all nodes, the simulator, the controller).

    ``params_file`` (a ROS parameters file, or None): its sections ``/**``,
    ``/**/attitude_simulator`` and ``/**/attitude_controller`` replace the scene's
    values name by name; an ``orbit_tle`` in it replaces the scene's orbit_elements.
    """
    s = SATELLITE_SCENE
    shared = {'inertia': s['inertia'], 'orbit_elements': s['orbit_elements'],
              'gravity_gradient': True, 'magnetic_field_model': 'dipole',
              'magnetorquer_max_dipole': s['magnetorquer_max_dipole']}
    sim = {'initial_angular_velocity': s['initial_angular_velocity'],
           'integration_rate': s['integration_rate'], 'publish_rate': 1.0 / s['control_period'],
           'publish_clock': True, 'magnetometer_rate': 1.0 / s['control_period'],
           'lockstep': True, 'control_period': s['control_period'],
           'lockstep_answer': 'magnetorquer_cmd'}
    ctl = {'mode': 'bdot', 'actuator': 'magnetorquers', 'bdot_gain': s['bdot_gain']}
    if params_file is not None:
        sections = _read_parameters_file(params_file)
        for key, values in (('/**', shared), ('/**/attitude_simulator', sim),
                            ('/**/attitude_controller', ctl)):
            values.update(sections.get(key, {}))
        if any('orbit_tle' in values for values in (shared, sim)) and \
                'orbit_elements' not in sections.get('/**', {}):
            del shared['orbit_elements']
    return shared, sim, ctl


def _read_parameters_file(path):
    """Return {section: parameters} of a ROS parameters file; ValueError says what is wrong."""
    import yaml
    try:
        with open(path) as f:
            data = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as err:
        raise ValueError(f'--params-file {path}: cannot be read ({err})') from None
    if not isinstance(data, dict) or not all(
            isinstance(v, dict) and isinstance(v.get('ros__parameters'), dict)
            for v in data.values()):
        raise ValueError(f'--params-file {path}: not a ROS parameters file (sections with '
                         'ros__parameters)')
    return {key: value['ros__parameters'] for key, value in data.items()}


def _scene_text(shared, sim, ctl):
    """Return (the orbit's words, its period s) of the scene's parameters, for its lines."""
    from ..physics.environment import KeplerOrbit, TleOrbit
    values = {**shared, **sim}
    if 'orbit_tle' in values:
        orbit = TleOrbit(*values['orbit_tle'], epoch=values.get('epoch') or None)
        field = values.get('magnetic_field_model', 'dipole')
        field = (f'IGRF-14 to degree {values.get("magnetic_field_degree", 13)}'
                 if field == 'igrf' else field)
        return (f'the orbit of the TLE of NORAD {orbit.satellite.satnum} '
                f'({orbit.period / 60:.1f} min, from {orbit.start_text[:19]}Z, field {field})',
                orbit.period)
    orbit = KeplerOrbit(values['orbit_elements'])
    height = (orbit.a - 6378137.0) / 1e3
    return (f'a {height:.0f} km circular polar orbit ({orbit.period / 60:.1f} min)',
            orbit.period)


def satellite_lines(t, rates, dipoles, how, parameters=None):
    """
    Lines about the satellite scene: when |omega| passed 5, 1 and 0.5 deg/s; rod saturation.

    ``parameters``: the scene's (all nodes, simulator, controller) values (default: the
    built-in scene's).
    """
    shared, sim, ctl = parameters or _satellite_parameters()
    orbit_text, period = _scene_text(shared, sim, ctl)
    target = SATELLITE_SCENE['target_rate']
    deg = np.degrees(np.asarray(rates))
    below = {}
    for level in (5.0, 1.0, math.degrees(target)):
        hit = np.flatnonzero(deg <= level + 1e-12)
        below[level] = t[hit[0]] if hit.size else None
    limit = shared['magnetorquer_max_dipole'][0]
    full = np.flatnonzero([max(abs(c) for c in m) >= limit * (1 - 1e-12) for m in dipoles])
    saturated = t[full[-1]] if full.size else 0.0
    reached = below[math.degrees(target)]
    return [f'{SATELLITE}: B-dot detumbles a 3U CubeSat (I = {tuple(shared["inertia"])} kg m^2) '
            f'from {deg[0]:.2f} deg/s in {orbit_text}, k = {ctl["bdot_gain"]:g} A m^2 s/T every '
            f'{sim["control_period"]:g} s, {limit:g} A m^2 rods, {how}:',
            '  |omega| below ' + ', '.join(
                f'{level:g} deg/s after {"never" if at is None else f"{at:.0f} s"}'
                for level, at in below.items()),
            f'  target {math.degrees(target):g} deg/s reached '
            + ('not within the run' if reached is None else
               f'after {reached / period:.2f} orbit') +
            f'; the rods were at their limit until {saturated:.0f} s']


def _satellite_body():
    """Build the satellite scene's body on the engine, with magnetometer and magnetorquers."""
    from ..engine import BodySimulation, Disturbances
    from ..physics import Inertia
    from ..physics.environment import DipoleField, KeplerOrbit
    from ..physics.sensors import Magnetometer
    s = SATELLITE_SCENE
    every = round(s['integration_rate'] * s['control_period'])
    return BodySimulation(
        Inertia(s['inertia']), 'exact', s['integration_rate'],
        ((0.0, 0.0, 0.0, 1.0), tuple(s['initial_angular_velocity'])), torque_timeout=0.0,
        publish_every=every, disturbances=Disturbances(
            orbit=KeplerOrbit(s['orbit_elements']), field=DipoleField(), gravity_gradient=True),
        magnetorquers=tuple(s['magnetorquer_max_dipole']),
        sensors=[Magnetometer(1.0 / s['control_period'])])


def satellite_offline():
    """Run the satellite scene on the engine without ROS (engine.offline.detumble)."""
    from ..engine.offline import detumble
    from ..physics.control import BDot
    s = SATELLITE_SCENE
    run = detumble(_satellite_body(), BDot(s['bdot_gain'], s['magnetorquer_max_dipole']),
                   5700.0, s['target_rate'])
    return satellite_lines(np.array(run['times']), run['rates'], run['dipoles'], 'offline')


def run_satellite(params_file=None):
    """
    Run the satellite scene on the nodes: the simulator in lockstep and B-dot.

    ``params_file``: values that replace the scene's (:func:`_satellite_parameters`).
    """
    from geometry_msgs.msg import Vector3Stamped
    from nav_msgs.msg import Odometry
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    from ..ros.client import interrupt, RosClient, start_node
    from ..ros.conversions import time_ns
    from ..ros.parameters import write_parameters_file
    scene = shared, sim_params, ctl_params = _satellite_parameters(params_file)
    _orbit_text, period = _scene_text(*scene)
    limit = max(5700.0, 1.01 * period)
    params = write_parameters_file({'/**': shared, '/**/attitude_simulator': sim_params,
                                    '/**/attitude_controller': ctl_params})
    quiet = ['--log-level', 'warn', '--params-file', params]
    sim, ctl = start_node('simulator', list(quiet) + [
        '-p', 'qos_overrides./odom.publisher.depth:=10000',
        '-p', 'qos_overrides./applied_dipole.publisher.depth:=10000']), None
    rates, dipoles = {}, {}
    deep = QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE)
    client = RosClient('rigid_body_demo')
    target = SATELLITE_SCENE['target_rate']
    try:
        node = client.node
        node.create_subscription(Odometry, 'odom', lambda m: rates.setdefault(
            time_ns(m.header.stamp), math.sqrt(m.twist.twist.angular.x ** 2
                                               + m.twist.twist.angular.y ** 2
                                               + m.twist.twist.angular.z ** 2)), deep)
        # the dipole held over each tick, as the simulator applied it (the controller's own
        # topic is matched only after it starts, while lockstep may already be running)
        period = round(SATELLITE_SCENE['control_period'] * 1e9)
        node.create_subscription(Vector3Stamped, 'applied_dipole', lambda m: dipoles.setdefault(
            time_ns(m.header.stamp) - period, (m.vector.x, m.vector.y, m.vector.z)), deep)
        client.spin_until(lambda: rates and node.count_publishers('applied_dipole'), 30.0,
                          'the first state of attitude_simulator')
        ctl = start_node('controller', list(quiet))
        print(f'{SATELLITE}: started attitude_simulator in orbit, in lockstep (pid {sim.pid}), '
              f'and attitude_controller flying B-dot (pid {ctl.pid}) ...', flush=True)

        def done():
            stamps = sorted(rates)
            return stamps[-1] >= limit * 1e9 or (rates[stamps[-1]] <= target and
                                                 stamps[-1] in dipoles)
        client.spin_until(done, 300.0, 'the CubeSat to detumble')
    finally:
        client.close()
        codes = [interrupt(proc) for proc in (ctl, sim) if proc is not None]
        os.unlink(params)
    stamps = [k for k in sorted(rates) if k in dipoles]
    return satellite_lines(np.array(stamps) * 1e-9, [rates[k] for k in stamps],
                           [dipoles[k] for k in stamps], 'in lockstep', scene) + [
        f'  stopped attitude_controller and attitude_simulator (exit codes '
        f'{", ".join(str(c) for c in codes)})']


def report(preset, integrator, duration, dt):
    """Simulate ``preset`` offline and analyse it (the one analysis); returns the lines."""
    body = presets.get(preset)
    run = simulate(body.moments, body.omega0, body.q0, duration, dt, integrator=integrator)
    found = analyse(Trajectory.from_simulation(run))
    exact_q, _ = FreeRigidBody(body.moments, body.omega0, body.q0).state_at(run.t[-1])
    return [f'{body.name}: {body.description}',
            f'  I = {body.moments} kg m^2, omega0 = {body.omega0} rad/s body, '
            f'{integrator}, dt = {dt} s; the analysis finds:'] + found.lines()[1:] + [
        f'  attitude at the end vs the exact solution: '
        f'{float(quaternions.angle_between(run.q[-1], exact_q)):.1e} rad']


#: What the demo waits for in the analyzer's diagnostics, per kind of body.
_READY = {
    'axisymmetric': ('precession', 'lab rate error (rel.)'),
    'asymmetric': ('stability', 'flip interval, measured (s)'),
}


def findings(statuses):
    """
    Lines from the analyzer's newest statuses (name -> (level, message, values)).

    The values are read back into the analysis' Findings (by the module that wrote
    them) and printed with the same renderer as the offline analysis.
    """
    from ..nodes import analyzer_diagnostics as diagnostics
    return text_lines(diagnostics.findings_from(statuses))[1:]


def run_nodes(preset, integrator, rate):
    """
    Start attitude_simulator and attitude_analyzer, wait for the analyzer's findings, stop both.

    The simulator runs at 4x (axisymmetric) or 8x real time with stamps =
    simulated time; the analyzer's window is sized to a few periods of what
    the body does. Returns the printable lines.
    """
    from diagnostic_msgs.msg import DiagnosticArray

    from ..ros.client import interrupt, RosClient, start_node, WaitTimeout
    from ..ros.conversions import status_values
    body = presets.get(preset)
    kind = FreeRigidBody(body.moments, body.omega0).shape.kind
    check, key = _READY.get(kind, ('conservation', 'mode'))
    window = 50.0 if kind == 'asymmetric' else 10.0
    rtf = 8.0 if kind == 'asymmetric' else 4.0

    def start(node, *params):
        args = ['--log-level', 'warn']
        for p in params:
            args += ['-p', p]
        return start_node(node, args)
    sim = start('simulator', f'preset:={preset}', f'integrator:={integrator}',
                f'integration_rate:={rate}', f'real_time_factor:={rtf}', 'publish_clock:=true')
    analyzer = start('analyzer', f'window:={window}')
    print(f'{preset}: started attitude_simulator (pid {sim.pid}, {integrator}, {rtf:g}x real '
          f'time) and attitude_analyzer (pid {analyzer.pid}, window {window:g} s) ...',
          flush=True)
    statuses = {}
    first = {}

    def on_diagnostics(msg):
        for st in msg.status:
            if st.name.startswith('attitude_analyzer: '):
                values = status_values(st)
                name = st.name.split(': ', 1)[1]
                statuses[name] = (st.level, st.message, values)
                if key in values and _is_number(values[key]):
                    first.setdefault(name, time.monotonic())

    def ready():
        # findings are ready once the window is full: a window's worth of wall time after
        # the first estimate
        for proc, name in ((sim, 'attitude_simulator'), (analyzer, 'attitude_analyzer')):
            if proc.poll() is not None:
                raise RuntimeError(f'{name} exited with code {proc.returncode}')
        return check in first and time.monotonic() > first[check] + window / rtf + 1.0
    client = RosClient('rigid_body_demo')
    try:
        client.node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, 10)
        client.spin_until(ready, 60.0 + window / rtf, "the analyzer's findings")
    except WaitTimeout:
        if check not in first:
            raise RuntimeError('the analyzer reported no findings in time') from None
    finally:
        client.close()
        codes = [interrupt(proc) for proc in (analyzer, sim)]
    lines = [f'{body.name}: {body.description}',
             f'  I = {body.moments} kg m^2, omega0 = {body.omega0} rad/s body; '
             'attitude_analyzer finds:'] + findings(statuses)
    lines.append(f'  stopped attitude_analyzer and attitude_simulator (exit codes {codes[0]}, '
                 f'{codes[1]})')
    return lines


def slew_lines(t, q, how):
    """Lines about a slew: settling time (2 %) against the PD theory, final pointing error."""
    target = np.array(SLEW['target'])
    error = np.array([quaternions.angle_between(a, target) for a in q])
    outside = np.flatnonzero(error > 0.02 * error[0])
    measured = t[outside[-1] + 1] - t[0] if outside.size and outside[-1] + 1 < t.size \
        else math.nan
    theory = settling_time(SLEW['natural_frequency'], SLEW['damping_ratio'])
    body = presets.get(presets.DEFAULT)
    return [f'{CLOSED_LOOP}: attitude_controller slews {body.name} from rest by '
            f'{math.degrees(error[0]):.0f} deg about x (wn = {SLEW["natural_frequency"]:g} rad/s, '
            f'zeta = {SLEW["damping_ratio"]:g}, every {SLEW["control_period"] * 1e3:g} ms), '
            f'{how}:',
            f'  settling time (2 %)                {measured:.3f} s      PD theory '
            f'{theory:.3f} s  (rel. {abs(measured / theory - 1.0):.1e})',
            f'  pointing error after {t[-1] - t[0]:g} s         {error[-1]:.1e} rad']


def closed_loop_offline():
    """Run the closed-loop scene in the physics layer: the same law held per control period."""
    body = presets.get(presets.DEFAULT)
    law = QuaternionPD(body.moments, SLEW['target'], SLEW['natural_frequency'],
                       SLEW['damping_ratio'])
    every = round(SLEW['control_period'] / 1e-3)
    run = simulate(body.moments, (0.0, 0.0, 0.0), body.q0, SLEW['duration'], 1e-3,
                   torque=lambda t, q, w: law(q, w), torque_every=every, every=every)
    return slew_lines(run.t, run.q, 'offline')


def run_closed_loop():
    """Start the simulator in lockstep and attitude_controller; measure the slew; stop both."""
    from nav_msgs.msg import Odometry
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    from ..ros.client import interrupt, RosClient, start_node
    from ..ros.conversions import time_ns
    body = presets.get(presets.DEFAULT)
    quiet = ['--log-level', 'warn']
    sim = start_node('simulator', quiet + [
        '-p', f'preset:={body.name}', '-p', 'initial_angular_velocity:=[0.0, 0.0, 0.0]',
        '-p', 'lockstep:=true', '-p', 'publish_clock:=true',
        '-p', f'control_period:={SLEW["control_period"]}',
        '-p', 'qos_overrides./odom.publisher.depth:=10000'])
    states, ctl = {}, None
    client = RosClient('rigid_body_demo')
    try:
        def keep(msg):
            o = msg.pose.pose.orientation
            states.setdefault(time_ns(msg.header.stamp),
                              ((o.x, o.y, o.z, o.w), time.monotonic()))
        client.node.create_subscription(Odometry, 'odom', keep, QoSProfile(
            depth=10000, reliability=ReliabilityPolicy.RELIABLE))
        client.spin_until(lambda: states, 30.0, 'the first state of attitude_simulator')
        ctl = start_node('controller', quiet + [
            '-p', f'target_orientation:={list(SLEW["target"])}',
            '-p', f'natural_frequency:={SLEW["natural_frequency"]}',
            '-p', f'damping_ratio:={SLEW["damping_ratio"]}'])
        print(f'{CLOSED_LOOP}: started attitude_simulator in lockstep (pid {sim.pid}) and '
              f'attitude_controller (pid {ctl.pid}) ...', flush=True)
        client.spin_until(lambda: max(states) >= SLEW['duration'] * 1e9, 120.0,
                          f'{SLEW["duration"]:g} simulated seconds of the slew')
    finally:
        client.close()
        codes = [interrupt(proc) for proc in (ctl, sim) if proc is not None]
    stamps = sorted(states)
    t = np.array(stamps) * 1e-9
    q = np.array([states[k][0] for k in stamps])
    wall = states[stamps[-1]][1] - states[stamps[1]][1]
    return slew_lines(t, q, 'in lockstep') + [
        f'  {len(stamps) - 1} control ticks at {(t[-1] - t[1]) / wall:.1f}x real time; '
        f'stopped attitude_controller and attitude_simulator (exit codes '
        f'{", ".join(str(c) for c in codes)})']


def _scene_wheels():
    """Return the wheels of the wheels scene (physics.dynamics.gyrostat.Wheels)."""
    from ..physics.dynamics.gyrostat import Wheels
    w = WHEEL_SCENE['wheels']
    return Wheels(w['wheel_axes'], w['wheel_inertia'], w['wheel_max_torque'],
                  w['wheel_max_speed'], w['wheel_friction_coulomb'], w['wheel_friction_viscous'])


def wheel_lines(t, q, speeds, dumping, how):
    """
    Lines about the wheels scene: pointing against the PD theory, the wheels' speeds and dumps.

    ``t`` (N,) s, ``q`` (N, 4), ``speeds`` (N, 4) rad/s, ``dumping`` (N,) bool: at the
    control ticks.
    """
    body = presets.get(presets.DEFAULT)
    scene, target = WHEEL_SCENE, np.array(WHEEL_SCENE['target'])
    limit = scene['wheels']['wheel_max_speed'][0]
    error = np.degrees([quaternions.angle_between(a, target) for a in q])
    held = error[t >= t[-1] / 2.0]
    # the small-angle PD (gains 2 I wn^2 on the quaternion's vector part) holds a constant
    # disturbance d about z at theta = d / (I3 wn^2)
    steady = math.degrees(scene['disturbance'][2] / (body.moments[2]
                                                     * scene['natural_frequency'] ** 2))
    fastest = np.max(np.abs(speeds), axis=1)
    lines = [f'{WHEELS}: a {2 * math.degrees(math.asin(target[0])):g} degree slew about x '
             f'flown by four pyramid wheels (J {scene["wheels"]["wheel_inertia"][0]:g} kg m^2, '
             f'{scene["wheels"]["wheel_max_torque"][0]:g} N m, {limit:g} rad/s) against '
             f'{scene["disturbance"][2]:g} N m about z, {how}',
             f'  pointing error over the second half: {held.min():.4f} to {held.max():.4f} deg; '
             f'the PD holds the disturbance at {steady:.4f} deg (small-angle theory)']
    if np.any(dumping):
        first = int(np.argmax(dumping))
        last = first + int(np.argmin(dumping[first:])) if not np.all(dumping[first:]) \
            else len(t) - 1
        lines.append(f'  the wheels spun up to {fastest[first]:.1f} rad/s '
                     f'({100 * fastest[first] / limit:.0f} % of the limit) by t = {t[first]:.2f} '
                     f's; momentum dumped on torque_cmd until t = {t[last]:.2f} s, down to '
                     f'{fastest[last]:.1f} rad/s; {fastest[-1]:.1f} rad/s at the end')
    else:
        lines.append(f'  the wheels reached {fastest.max():.1f} rad/s: no dump was needed')
    return lines


def wheel_scene_ticks(duration=None):
    """
    Run the wheels scene in the physics layer (the controller's law and allocator).

    Returns :func:`~rigid_body_dynamics.physics.control.fly_on_wheels`' control ticks
    (t, q, omega, speeds, motor torques, dump torque) and the scene's wheels.
    """
    from ..physics.control import fly_on_wheels, WheelAllocator
    body, scene, wheels = presets.get(presets.DEFAULT), WHEEL_SCENE, _scene_wheels()
    law = QuaternionPD(body.moments, scene['target'], scene['natural_frequency'],
                       scene['damping_ratio'])
    ticks, _ = fly_on_wheels(body.moments, wheels, law, WheelAllocator(wheels),
                             duration or scene['duration'], q0=body.q0,
                             disturbance=scene['disturbance'])
    return ticks, wheels


def wheels_offline():
    """Run the wheels scene in the physics layer; the printable lines."""
    ticks, _ = wheel_scene_ticks()
    return wheel_lines(np.array([k[0] for k in ticks]), np.array([k[1] for k in ticks]),
                       np.array([k[3] for k in ticks]), np.array([any(k[5]) for k in ticks]),
                       'offline')


def run_wheels():
    """Run the wheels scene on the nodes: the simulator in lockstep and attitude_controller."""
    from geometry_msgs.msg import WrenchStamped
    from nav_msgs.msg import Odometry
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState

    from ..ros.client import interrupt, RosClient, start_node
    from ..ros.conversions import time_ns
    body, scene = presets.get(presets.DEFAULT), WHEEL_SCENE
    wheel_args = [a for name, value in scene['wheels'].items()
                  for a in ('-p', f'{name}:={list(value)}')]
    quiet = ['--log-level', 'warn']
    sim = start_node('simulator', quiet + wheel_args + [
        '-p', f'preset:={body.name}', '-p', 'initial_angular_velocity:=[0.0, 0.0, 0.0]',
        '-p', 'lockstep:=true', '-p', 'lockstep_answer:=both', '-p', 'publish_clock:=true',
        '-p', f'disturbance_torque_body:={list(scene["disturbance"])}',
        '-p', 'qos_overrides./odom.publisher.depth:=10000',
        '-p', 'qos_overrides./wheel_state.publisher.depth:=10000',
        '-p', 'qos_overrides./applied_torque.publisher.depth:=10000'])
    states, wheels, torques, ctl = {}, {}, {}, None
    deep = QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE)
    client = RosClient('rigid_body_demo')
    try:
        node = client.node
        node.create_subscription(Odometry, 'odom', lambda m: states.setdefault(
            time_ns(m.header.stamp), (m.pose.pose.orientation.x, m.pose.pose.orientation.y,
                                      m.pose.pose.orientation.z, m.pose.pose.orientation.w)),
            deep)
        node.create_subscription(JointState, 'wheel_state', lambda m: wheels.setdefault(
            time_ns(m.header.stamp), tuple(m.velocity)), deep)
        node.create_subscription(WrenchStamped, 'applied_torque', lambda m: torques.setdefault(
            time_ns(m.header.stamp), m.wrench.torque.z), deep)
        client.spin_until(lambda: states, 30.0, 'the first state of attitude_simulator')
        ctl = start_node('controller', quiet + wheel_args + [
            '-p', 'actuator:=wheels', '-p', f'target_orientation:={list(scene["target"])}',
            '-p', f'natural_frequency:={scene["natural_frequency"]}',
            '-p', f'damping_ratio:={scene["damping_ratio"]}'])
        print(f'{WHEELS}: started attitude_simulator in lockstep with four wheels (pid '
              f'{sim.pid}) and attitude_controller flying them (pid {ctl.pid}) ...', flush=True)
        end = int(scene['duration'] * 1e9)
        client.spin_until(lambda: max(states) >= end and max(torques, default=0) >= end,
                          180.0, f'{scene["duration"]:g} simulated seconds on wheels')
    finally:
        client.close()
        codes = [interrupt(proc) for proc in (ctl, sim) if proc is not None]
    ticks = [s for s in sorted(states) if s % 10_000_000 == 0 and s in wheels and s <= end]
    # applied_torque at the end of a tick (publish ticks are control ticks here): the
    # disturbance plus the dump held over it
    dumping = np.array([abs(torques.get(s + 10_000_000, scene['disturbance'][2])
                            - scene['disturbance'][2]) > 0.0 for s in ticks])
    return wheel_lines(np.array(ticks) * 1e-9, np.array([states[s] for s in ticks]),
                       np.array([wheels[s] for s in ticks]), dumping, 'in lockstep') + [
        f'  stopped attitude_controller and attitude_simulator (exit codes '
        f'{", ".join(str(c) for c in codes)})']


def _is_number(text):
    try:
        float(text)
    except (TypeError, ValueError):
        return False
    return True


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
    parser = argparse.ArgumentParser(prog='rigid_body_demo', description=__doc__.splitlines()[1])
    parser.add_argument('--preset', default=None,
                        help=f'preset name, or {CLOSED_LOOP}, {WHEELS}, {SATELLITE} or '
                        f'{LIBRATION} (default: a tour of the first five scenes)')
    parser.add_argument('--integrator', default='exact', choices=sorted(INTEGRATORS))
    parser.add_argument('--duration', type=float, default=None,
                        help='simulated seconds (--offline)')
    parser.add_argument('--dt', type=float, default=1e-3, help='step (s)')
    parser.add_argument('--offline', action='store_true', help='physics only, no ROS nodes')
    parser.add_argument('--params-file', default=None, metavar='FILE',
                        help=f'--preset {SATELLITE} only: a ROS parameters file whose values '
                        "replace the scene's (e.g. orbit_tle, epoch, magnetic_field_model igrf)")
    args = parser.parse_args(argv)
    if args.params_file is not None and (args.preset != SATELLITE or args.offline):
        parser.error(f'--params-file goes with --preset {SATELLITE}, on the nodes (not '
                     '--offline)')
    names = [args.preset] if args.preset else ['symmetric_top', 'tennis_racket', CLOSED_LOOP,
                                               WHEELS, SATELLITE]
    reservation = None if args.offline else _ros_environment()
    try:
        for name in names:
            if name == CLOSED_LOOP:
                lines = closed_loop_offline() if args.offline else run_closed_loop()
                print('\n'.join(lines), flush=True)
                continue
            if name == WHEELS:
                lines = wheels_offline() if args.offline else run_wheels()
                print('\n'.join(lines), flush=True)
                continue
            if name == SATELLITE:
                lines = satellite_offline() if args.offline else run_satellite(
                    args.params_file)
                print('\n'.join(lines), flush=True)
                continue
            if name == LIBRATION:
                lines = libration_offline() if args.offline else run_libration()
                print('\n'.join(lines), flush=True)
                continue
            body = presets.get(name)
            if args.offline:
                lines = report(name, args.integrator, args.duration or body.duration, args.dt)
            else:
                lines = run_nodes(name, args.integrator, 1.0 / args.dt)
            print('\n'.join(lines), flush=True)
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
