"""
The parameter table of attitude_simulator: names, defaults, units, ranges, checks.

Declaration, validation and the manual's parameter table are all made from
``PARAMETERS`` (test_docs checks the manual against it); the converters and
cross-checks below give every refusal its reason.
"""

import math

from .environment_parameters import environment_from, environment_params
from .sensor_parameters import sensor_params, sensors_from
from .wheel_parameters import WHEEL_PARAMS, wheel_params, wheels_from
from ..engine import BodySimulation
from ..physics import Inertia, INTEGRATORS, presets
from ..physics.dynamics.gyrostat import GyrostatIntegrator
from ..physics.dynamics.integrators import REMOVED as REMOVED_INTEGRATORS
from ..ros.parameters import as_vector, ConfigurationError, Param, ParameterTable
from ..ros.state_publisher import OPTIONAL_TOPICS


def _preset(node):
    """Return the preset the other parameters default to (ConfigurationError if unknown)."""
    try:
        return presets.get(node.get_parameter('preset').value)
    except ValueError as err:
        raise ConfigurationError(str(err)) from None


def _integrator(name):
    if name not in INTEGRATORS:
        raise ConfigurationError(REMOVED_INTEGRATORS.get(name) or (
            f'unknown integrator {name!r}; choose one of {", ".join(sorted(INTEGRATORS))}'))
    return name


def _orientation(value):
    q = as_vector('initial_orientation', value, 4)
    norm = math.sqrt(sum(c * c for c in q))
    if norm < 1e-9:
        raise ConfigurationError('initial_orientation must not be the zero quaternion')
    return tuple(c / norm for c in q)


def _frame_prefix(value):
    """Check frame_prefix: a string that does not start with '/' (TF frame ids do not)."""
    text = str(value)
    if text.startswith('/') or any(c.isspace() for c in text):
        raise ConfigurationError(f'frame_prefix must not start with / or contain spaces (TF '
                                 f'frame ids do not), got {text!r}')
    return text


def state_topics(value):
    """Parse state_topics: 'all', 'none' or comma-separated names from OPTIONAL_TOPICS."""
    text = str(value).strip()
    if text == 'all':
        return OPTIONAL_TOPICS
    names = () if text in ('', 'none') else tuple(n.strip() for n in text.split(','))
    unknown = [n for n in names if n not in OPTIONAL_TOPICS]
    if unknown:
        raise ConfigurationError(f'state_topics: unknown topic(s) {", ".join(unknown)}; use '
                                 f'all, none or some of {", ".join(OPTIONAL_TOPICS)}')
    return names


def _body(values, out):
    """Cross-check: the Inertia from inertia_tensor (if set) or inertia, as out['body']."""
    try:
        if out.get('inertia_tensor') is not None:
            out['body'] = Inertia.from_tensor(out['inertia_tensor'])
        else:
            out['body'] = Inertia(out['inertia'])
    except ValueError as err:
        raise ConfigurationError(str(err)) from None


def _sensors(values, out):
    """Cross-check: the sensors (gyro, magnetometer, star tracker, sun sensor), out['sensors']."""
    out['sensors'] = sensors_from(out, out['disturbances'])


def _control_steps(values, out):
    """Cross-check, in lockstep: control_period is a whole number of steps (control_every)."""
    if not out['lockstep']:
        out['control_every'] = None
        return
    steps = out['control_period'] * out['integration_rate']
    every = round(steps)
    if every < 1 or abs(steps - every) > 1e-9 * every:
        raise ConfigurationError(
            f'control_period must be a whole number of integration steps (dt = '
            f'{1.0 / out["integration_rate"]:g} s), got {out["control_period"]:g} s')
    out['control_every'] = every


def _disturbances(values, out):
    """Cross-check: the environment (orbit, field, torque models) as out['disturbances']."""
    out['disturbances'] = environment_from(out)


def _wheels(values, out):
    """Cross-check: the wheels (out['wheels'], None without) and their initial speeds."""
    wheels = wheels_from(out)
    out['wheels'] = out['wheel_speeds'] = None
    if wheels is None:
        return
    try:
        # the body less its wheels' spin inertia must stay positive definite
        GyrostatIntegrator(out['body'].moments, wheels.turned(
            lambda g: out['body'].to_principal(g)), 1.0)
    except ValueError as err:
        raise ConfigurationError(str(err)) from None
    speeds = out.get('initial_wheel_speed') or (0.0,) * wheels.count
    if len(speeds) != wheels.count:
        raise ConfigurationError(f'initial_wheel_speed needs {wheels.count} values (one per '
                                 f'wheel), got {len(speeds)}')
    out['wheels'], out['wheel_speeds'] = wheels, tuple(speeds)


def _lockstep_answer(values, out):
    """Cross-check: the kinds of command that answer a lockstep tick (out['answer'])."""
    answer = {'auto': None, 'torque_cmd': ('torque',), 'wheel_cmd': ('wheels',),
              'both': ('torque', 'wheels'),
              'magnetorquer_cmd': ('dipole',)}[out['lockstep_answer']]
    if answer and 'wheels' in answer and out['wheels'] is None:
        raise ConfigurationError(f'lockstep_answer {out["lockstep_answer"]} needs wheels '
                                 '(wheel_axes)')
    if answer == ('dipole',) and out['magnetic_field_model'] == 'none':
        raise ConfigurationError('lockstep_answer magnetorquer_cmd needs magnetorquers '
                                 '(magnetic_field_model dipole or igrf)')
    out['answer'] = answer


def _publish_rate(values, out):
    """Cross-check: publish_rate <= integration_rate."""
    if out['publish_rate'] > out['integration_rate']:
        raise ConfigurationError(f'publish_rate must be within [1e-06, '
                                 f'{out["integration_rate"]:g}] (at most integration_rate), '
                                 f'got {out["publish_rate"]:g}')


#: The parameters of attitude_simulator (the manual's table is made from this; test_docs checks).
PARAMETERS = ParameterTable([
    Param('preset', 'string', presets.DEFAULT, f'`{presets.DEFAULT}`',
          'Named body from physics/presets.py; its values are the defaults of the parameters '
          'below, which override them.', read_only=True, choices=tuple(sorted(presets.PRESETS)),
          convert=lambda name: _preset_name(name)),
    Param('inertia', 'double[3]', lambda node: [float(v) for v in _preset(node).moments],
          'preset', 'Principal moments [I1, I2, I3] (kg m^2), body = principal frame; positive '
          'and satisfying I1 + I2 >= I3 and permutations. A change keeps attitude and angular '
          'velocity.'),
    Param('inertia_tensor', 'double[6]', None, 'unset',
          'Full tensor [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (kg m^2, tensor elements as in URDF) in '
          'the body frame; overrides inertia.'),
    Param('initial_orientation', 'double[4]', lambda node: [float(v) for v in _preset(node).q0],
          'preset', 'Initial attitude (x, y, z, w), body -> world; normalised. Used at start '
          'and on ~/reset.', convert=_orientation),
    Param('initial_angular_velocity', 'double[3]',
          lambda node: [float(v) for v in _preset(node).omega0], 'preset',
          'Initial angular velocity (rad/s) in the body frame. Used at start and on ~/reset.'),
    Param('integrator', 'string', 'exact', '`exact`',
          'Integration method, exact or rk4 (exact4 and dop853 were removed: exact is more '
          'accurate under torque and cheaper); a change continues from the current state.',
          choices=tuple(sorted(INTEGRATORS)), convert=_integrator),
    Param('integration_rate', 'double', lambda node: float(_preset(node).integration_rate),
          '1000.0 Hz', 'Integration steps per simulated second (Hz); dt = 1 / rate.',
          low=1e-6, high=1e5, read_only=True),
    Param('publish_rate', 'double', lambda node: float(_preset(node).publish_rate), '100.0 Hz',
          'State messages per simulated second (Hz); at most integration_rate, rounded to a '
          'whole number of steps.', low=1e-6, high=1e5),
    Param('real_time_factor', 'double', lambda node: float(_preset(node).real_time_factor),
          '1.0', 'Simulated seconds per wall second on the steady clock; 0 = as fast as '
          'possible.', low=0.0, high=1e12),
    Param('publish_clock', 'bool', False, 'false',
          'Publish the simulated time on /clock (stamps then start at 0) so that other nodes '
          'can run with use_sim_time.', read_only=True),
    Param('torque_timeout', 'double', 0.5, '0.5 s',
          'A torque command is held until replaced or until this long (s, steady clock) after '
          'it arrived; 0 = hold forever.', low=0.0, high=1e9),
    Param('max_torque', 'double', 0.0, '0.0 N m',
          'Per-axis limit on the commanded torque (N m); larger values are clipped and '
          'counted. 0 = no limit.', low=0.0, high=1e30),
    Param('world_frame', 'string', 'odom', '`odom`',
          'Inertial frame id (REP 105) of orientation, angular_momentum and odom.',
          read_only=True),
    Param('body_frame', 'string', 'base_link', '`base_link`',
          'Body frame id of angular_velocity, angular_momentum_body, applied_torque, imu.',
          read_only=True),
    Param('frame_prefix', 'string', lambda node: getattr(node, 'frame_prefix_default', ''),
          '"" (attitude_fleet: `<name>/`)',
          'Prefix of every frame id the node publishes and accepts (world_frame, body_frame, '
          "lvlh_frame), as robot_state_publisher's frame_prefix: bodies in several namespaces "
          'then give distinct TF trees, e.g. `sat1/` gives sat1/odom -> sat1/base_link. '
          'attitude_fleet sets it to `<name>/` for each body unless told otherwise.',
          read_only=True, convert=_frame_prefix),
    Param('simulation_interfaces', 'bool',
          lambda node: getattr(node, 'simulation_interfaces_default', True),
          '`true` (attitude_fleet: `false`)',
          "Offer ROS 2's standard simulator services and action (simulation_interfaces: "
          'get_simulator_features, step_simulation, simulate_steps, get_entity_state, ...) in '
          "the node's namespace, where the package is importable. attitude_fleet leaves them "
          'off unless set: 24 more DDS endpoints per body (8 services and an action: a reader '
          'and a writer per service, 3 services and 2 topics per action) made 128 bodies '
          'start in 20-26 s '
          'instead of 7-8 and exit in 7.5-10 s instead of 3-3.5.',
          read_only=True),
    Param('thread_priority', 'int', 0, '0',
          'SCHED_FIFO priority (1-99) of the integration thread on Linux, for fewer missed '
          'deadlines on a loaded machine; 0 = normal scheduling. Needs CAP_SYS_NICE or an '
          'rtprio limit (limits.conf); if refused, the node says so and runs normally.',
          low=0, high=99, read_only=True),
    Param('state_topics', 'string', 'all', '`all`',
          'State topics published besides odom: all, none, or a comma-separated choice of '
          'orientation, angular_velocity, angular_momentum, angular_momentum_body, '
          'applied_torque (odom carries attitude and rate; fewer topics let one fleet '
          'carry more bodies, see benchmarks).', read_only=True, convert=state_topics),
    Param('publish_tf', 'bool', True, 'true',
          'Broadcast world_frame -> body_frame on /tf (tf2_msgs/TFMessage, the odom stamp; '
          'rotation only) when tf2_msgs is importable (on a ROS install; pip-only installs '
          'have no tf2_msgs and the node says so).', read_only=True),
    Param('publish_imu', 'bool', True, 'true',
          'Also publish sensor_msgs/Imu on imu (REP 145; no acceleration) and the true gyro '
          'bias on ~/imu_bias.', read_only=True),
    Param('imu_rate', 'double', lambda node: float(node.get_parameter('publish_rate').value),
          'publish_rate', 'Gyro samples per simulated second (Hz); at most integration_rate, '
          'rounded to a whole number of steps.', low=1e-6, high=1e5, read_only=True),
    Param('gyro_noise_density', 'double', 0.0, '0.0 rad/s/sqrt(Hz)',
          'White rate noise N (angle random walk); its stddev per sample is N sqrt(imu_rate), '
          'which is what Gazebo calls stddev.', low=0.0, high=1e3, read_only=True),
    Param('gyro_bias_random_walk', 'double', 0.0, '0.0 rad/s^2/sqrt(Hz)',
          'Bias random walk K (rate random walk): the bias moves by K sqrt(dt) per sample.',
          low=0.0, high=1e3, read_only=True),
    Param('gyro_turn_on_bias', 'double', 0.0, '0.0 rad/s',
          'Standard deviation of the bias drawn at start and on ~/reset, per axis.',
          low=0.0, high=1e3, read_only=True),
    Param('gyro_bias_correlation_time', 'double', 0.0, '0.0 s',
          'With tau > 0 the bias is Gauss-Markov (stationary deviation K sqrt(tau / 2), as '
          'the dynamic bias of Gazebo); 0 = a random walk.', low=0.0, high=1e9, read_only=True),
    Param('orientation_noise', 'double', 0.0, '0.0 rad',
          'Standard deviation per axis of a random rotation applied to the imu orientation.',
          low=0.0, high=3.0, read_only=True),
    Param('gyro_resolution', 'double', 0.0, '0.0 rad/s',
          'Quantisation step of the gyro reading (one count; Gazebo precision); adds '
          'resolution^2 / 12 of variance that the covariance does not include. 0 = none.',
          low=0.0, high=1e3, read_only=True),
    Param('lockstep', 'bool', False, 'false',
          'Deterministic closed loop: at every control tick publish the state, wait for a '
          'torque_cmd stamped at or after the tick, hold it from the tick on and integrate '
          'to the next as fast as possible (real_time_factor and torque_timeout are unused).',
          read_only=True),
    Param('control_period', 'double', 0.01, '0.01 s',
          'Lockstep control period (s): a whole number of integration steps.',
          low=1e-6, high=1e6, read_only=True),
    Param('lockstep_answer', 'string', 'auto', '`auto`',
          'Lockstep: what answers a tick: torque_cmd (stamped at or after the tick), '
          'magnetorquer_cmd (likewise), '
          "wheel_cmd (a valid one during the tick's wait; it has no stamp), or both (a "
          'controller that flies the wheels and dumps momentum with torque_cmd); auto = '
          'wheel_cmd with wheels, else torque_cmd.',
          read_only=True, choices=('auto', 'both', 'magnetorquer_cmd', 'torque_cmd',
                                   'wheel_cmd')),
    Param('lockstep_timeout', 'double', 1.0, '1.0 s',
          'Lockstep: after the first command, a tick whose command does not come within this '
          'wall time is a counted, logged miss and the last command is held; 0 = wait for '
          'ever. Before the first command the wait has no limit.',
          low=0.0, high=1e9, read_only=True),
    Param('disturbance_torque_body', 'double[3]', [0.0, 0.0, 0.0], '[0, 0, 0] N m',
          'Constant disturbance torque in the body frame, added to the command (and to '
          'applied_torque).'),
    Param('disturbance_torque_world', 'double[3]', [0.0, 0.0, 0.0], '[0, 0, 0] N m',
          'Constant disturbance torque fixed in the world frame, added to the command.'),
    *environment_params(),
    *sensor_params(),
    Param('noise_seed', 'int', 0, '0',
          "Seed of the sensors' noise: the same seed and parameters give the same streams, bit "
          'for bit (also after ~/reset); each sensor draws from a stream of its own, so turning '
          'one on leaves the others unchanged.', low=0, high=2 ** 31 - 1, read_only=True),
    *wheel_params(*WHEEL_PARAMS),
], cross_checks=(_body, _publish_rate, _control_steps, _disturbances, _sensors, _wheels,
                 _lockstep_answer))


def _preset_name(name):
    if name not in presets.PRESETS:
        try:
            presets.get(name)
        except ValueError as err:
            raise ConfigurationError(str(err)) from None
    return name


def body_from(values, publish_every, start_ns=0):
    """
    Return the engine's BodySimulation of a simulator's validated ``values``.

    ``publish_every``: integration steps per published state; ``start_ns``: the
    stamp of simulated time 0 (int ns). In lockstep the torque watchdog is off
    (a tick waits for its command instead).
    """
    return BodySimulation(
        values['body'], values['integrator'], values['integration_rate'],
        (values['initial_orientation'], values['initial_angular_velocity']),
        0.0 if values['lockstep'] else values['torque_timeout'], values['max_torque'],
        publish_every, start_ns, sensors=values['sensors'], seed=values['noise_seed'],
        disturbances=values['disturbances'],
        wheels=values['wheels'], wheel_speeds=values['wheel_speeds'],
        magnetorquers=values['magnetorquer_max_dipole']
        if values['disturbances'].field is not None else None)
