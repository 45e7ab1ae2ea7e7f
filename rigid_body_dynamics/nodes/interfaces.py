"""
The topics and services of each node: the contract the manual's node pages are made from.

One :class:`Interfaces` table per node lists what it publishes, subscribes
and serves, with the message type, the frame or unit, and when it exists (a
parameter, tf2_msgs being importable). ``doc/generate.py`` renders them into
the node reference; ``test/test_docs.py`` starts each node and compares the
table with what the running node has on the ROS graph, so the two cannot
drift. Names are as the node creates them (relative, ``~/`` private, or
absolute); the parameter services, ``/rosout`` and ``/parameter_events`` that
every rclpy node has are listed once, in :data:`STANDARD`.
"""

from dataclasses import dataclass

#: What every rclpy node has; the node pages mention them once, not per node.
STANDARD = {
    'pub': {'/rosout': 'rcl_interfaces/msg/Log',
            '/parameter_events': 'rcl_interfaces/msg/ParameterEvent'},
    'srv': {f'~/{name}': f'rcl_interfaces/srv/{kind}' for name, kind in (
        ('describe_parameters', 'DescribeParameters'),
        ('get_parameter_types', 'GetParameterTypes'),
        ('get_parameters', 'GetParameters'),
        ('list_parameters', 'ListParameters'),
        ('set_parameters', 'SetParameters'),
        ('set_parameters_atomically', 'SetParametersAtomically'))}
    | {'~/get_type_description': 'type_description_interfaces/srv/GetTypeDescription'},
}

HEADINGS = {'sub': 'Subscribed topics', 'pub': 'Published topics', 'srv': 'Services',
            'action': 'Actions'}

#: What an action server puts on the graph under ``<name>/_action/``: kind, name, type
#: (``{}`` is the action's type).
ACTION_ENDPOINTS = (('srv', 'send_goal', '{}_SendGoal'), ('srv', 'get_result', '{}_GetResult'),
                    ('srv', 'cancel_goal', 'action_msgs/srv/CancelGoal'),
                    ('pub', 'feedback', '{}_FeedbackMessage'),
                    ('pub', 'status', 'action_msgs/msg/GoalStatusArray'))

#: The QoS of a topic, as the node pages write it: reliability, durability, history depth.
STATE = 'reliable, volatile, 10'
COMMANDS = 'reliable, volatile, 1000'
INPUT = 'best effort, volatile, 1000'
LATCHED = 'reliable, transient local, 1'


@dataclass(frozen=True)
class Interface:
    """One topic or service of a node."""

    kind: str          # 'pub', 'sub', 'srv' or 'action'
    name: str          # as the node creates it: relative, ~/private or /absolute
    type: str          # e.g. 'nav_msgs/msg/Odometry'  # noqa: A003 (a field name)
    text: str          # what it carries: units, frame, QoS
    when: str = ''     # the condition under which it exists ('' = always)


class Interfaces:
    """The topics and services of the node ``node`` (its default name)."""

    def __init__(self, node, items, qos=None, intake=False):
        self.node = node
        self.items = tuple(items)
        #: whether its subscriptions are on the hidden helper node ``_<node>_intake``
        self.intake = intake
        #: topic name -> QoS (reliability, durability, depth); the rest are STATE
        self.qos = dict(qos or {})

    def qos_of(self, item):
        """Return a topic's QoS text (``reliability, durability, depth``); '' for a service."""
        return '' if item.kind in ('srv', 'action') else self.qos.get(item.name, STATE)

    def resolved(self, namespace='/', present=lambda when: True):
        """
        Return {kind: {full name: type}} in ``namespace``, standard interfaces included.

        ``present(when)`` says whether a conditional item exists in the run at hand. An
        action is its services and topics (:data:`ACTION_ENDPOINTS`).
        """
        out = {kind: {} for kind in HEADINGS if kind != 'action'}
        base = namespace.rstrip('/')
        for kind, names in STANDARD.items():
            for name, msg_type in names.items():
                out[kind][self._full(name, base)] = msg_type
        for item in self.items:
            if item.when and not present(item.when):
                continue
            if item.kind == 'action':
                for kind, part, msg_type in ACTION_ENDPOINTS:
                    out[kind][self._full(f'{item.name}/_action/{part}', base)] = \
                        msg_type.format(item.type)
            else:
                out[item.kind][self._full(item.name, base)] = item.type
        return out

    def _full(self, name, base):
        if name.startswith('/'):
            return name
        if name.startswith('~/'):
            return f'{base}/{self.node}/{name[2:]}'
        return f'{base}/{name}'

    def graph_markdown(self):
        """
        Return what ``ros2 node / topic / service / action list`` show of this node.

        In the default namespace, every conditional item present, the standard
        interfaces of every node left out; names with a part that starts with ``_``
        are hidden, which ``-a`` / ``--include-hidden-...`` shows.
        """
        want = self.resolved('/')
        standard = {kind: {self._full(n, '') for n in names} for kind, names in STANDARD.items()}
        topics = {name: t for kind in ('pub', 'sub') for name, t in want[kind].items()
                  if name not in standard.get(kind, ())}
        services = {n: t for n, t in want['srv'].items() if n not in standard['srv']}
        actions = {self._full(i.name, ''): i.type for i in self.items if i.kind == 'action'}
        hidden = [f'/_{self.node}_intake'] if self.intake else []
        lines = ['## On the ROS graph', '',
                 'What the ROS 2 command line lists for this node alone, in the default '
                 'namespace, with every optional topic on (the parameter services, '
                 '`/rosout` and `/parameter_events` left out). A name with a part that '
                 'starts with `_` is hidden: `-a` (nodes) and `--include-hidden-topics` / '
                 '`--include-hidden-services` show it.', '', '```text',
                 '$ ros2 node list -a']
        lines += [f'{name}    # hidden: the subscriptions it takes in batches'
                  for name in hidden] + [f'/{self.node}']
        lines += ['$ ros2 topic list -t --include-hidden-topics']
        lines += [f'{name} [{t}]' for name, t in sorted(topics.items())]
        if services:
            lines += ['$ ros2 service list -t --include-hidden-services']
            lines += [f'{name} [{t}]' for name, t in sorted(services.items())]
        if actions:
            lines += ['$ ros2 action list -t']
            lines += [f'{name} [{t}]' for name, t in sorted(actions.items())]
        return '\n'.join(lines + ['```', ''])

    def markdown(self):
        """Return the node page's topic and service sections (Markdown; headings at level 2)."""
        lines = []
        for kind, heading in HEADINGS.items():
            items = [i for i in self.items if i.kind == kind]
            lines += [f'## {heading}', '']
            if not items:
                lines += ['None.', '']
                continue
            if kind in ('srv', 'action'):
                lines += ['| name | type | meaning | exists |', '| --- | --- | --- | --- |']
            else:
                lines += ['| name | type | meaning | QoS | exists |',
                          '| --- | --- | --- | --- | --- |']
            for i in items:
                qos = '' if kind in ('srv', 'action') else f' {self.qos_of(i)} |'
                lines.append(f'| `{i.name}` | `{i.type}` | {i.text} |{qos} '
                             f'{i.when or "always"} |')
            lines.append('')
        lines += ['QoS is reliability, durability and history depth (keep last), as the node '
                  'creates the endpoint; the test suite compares reliability and durability '
                  'with the running node. A topic whose node page says so takes '
                  '`qos_overrides` ({doc}`../../howto/troubleshooting`).', '']
        lines += ['Like every rclpy node it also has `/rosout`, `/parameter_events` and the '
                  'parameter services (`~/list_parameters`, `~/get_parameters`, '
                  '`~/set_parameters`, ...) and `~/get_type_description`.', '']
        return '\n'.join(lines)


#: When the standard simulator interface exists.
SIM_IF = ('if `simulation_interfaces` (the parameter; attitude_fleet: off by default) and the '
          'package is importable (always on a ROS install)')

SIMULATOR = Interfaces('attitude_simulator', [
    Interface('sub', 'torque_cmd', 'geometry_msgs/msg/WrenchStamped',
              'Torque command (N m) in `body_frame` (or empty frame id) or `world_frame`; held '
              'until replaced or `torque_timeout`; non-finite values and unknown frames are '
              'refused and counted. Reliable, depth 1000, taken in batches by the integration '
              'thread (held by the hidden helper node `_attitude_simulator_intake`).'),
    Interface('sub', 'wheel_cmd', 'std_msgs/msg/Float64MultiArray',
              'Reaction-wheel motor torques (N m), one per wheel in `wheel_axes` order; held '
              'and timed out like `torque_cmd`; a wrong length or a non-finite value is '
              'refused and counted. In lockstep a wheel_cmd answers the tick it comes in.',
              'if `wheel_axes` is set'),
    Interface('sub', 'magnetorquer_cmd', 'geometry_msgs/msg/Vector3Stamped',
              'Magnetorquer dipole (A m^2) along the body axes, frame id `body_frame` or empty; '
              'each axis clipped to `magnetorquer_max_dipole`; held and timed out like '
              '`torque_cmd`; torque m x B at every integrator stage. In lockstep a stamped one '
              'answers a tick as `torque_cmd` does (`lockstep_answer`).',
              'with a field (`magnetic_field_model` dipole or igrf)'),
    Interface('pub', 'odom', 'nav_msgs/msg/Odometry',
              '`world_frame` -> `body_frame`: orientation body -> world, twist.angular = omega '
              '(rad/s, body frame); with an orbit pose.position = r (m, world) and '
              'twist.linear = v in the body frame (m/s), else 0.'),
    Interface('pub', 'orientation', 'geometry_msgs/msg/QuaternionStamped',
              'Body -> world, `world_frame`.', 'if in `state_topics`'),
    Interface('pub', 'angular_velocity', 'geometry_msgs/msg/Vector3Stamped',
              'omega (rad/s), `body_frame`.', 'if in `state_topics`'),
    Interface('pub', 'angular_momentum', 'geometry_msgs/msg/Vector3Stamped',
              'L (kg m^2/s), `world_frame`; constant when torque-free. With wheels the total '
              'H = I omega + sum J Omega g.', 'if in `state_topics`'),
    Interface('pub', 'angular_momentum_body', 'geometry_msgs/msg/Vector3Stamped',
              'L (kg m^2/s), `body_frame`; with wheels the total H.', 'if in `state_topics`'),
    Interface('pub', 'applied_torque', 'geometry_msgs/msg/WrenchStamped',
              'The body-frame torque (N m) held over the step that ended at the stamp: the '
              'command (zero after a timeout) plus disturbances: the external torque (motor '
              'torques are internal).', 'if in `state_topics`'),
    Interface('pub', 'wheel_state', 'sensor_msgs/msg/JointState',
              'The wheels at the odom stamp: name `wheel_0`.., position the wheel angle (rad), '
              'velocity Omega (rad/s relative to the body), effort the motor torque applied '
              'after the limits (N m).', 'if `wheel_axes` is set'),
    Interface('pub', 'applied_dipole', 'geometry_msgs/msg/Vector3Stamped',
              'The magnetorquer dipole (A m^2, `body_frame`) held over the step that ended at '
              'the odom stamp, after the limits (zero after a timeout).',
              'with a field (`magnetic_field_model` dipole or igrf)'),
    Interface('pub', 'magnetic_field', 'sensor_msgs/msg/MagneticField',
              'The magnetometer at `magnetometer_rate`: the field (T, `body_frame`) plus '
              '`magnetometer_bias` and white noise; covariance noise^2 on the diagonal.',
              'if `magnetometer_rate` > 0'),
    Interface('pub', 'star_tracker', 'geometry_msgs/msg/PoseWithCovarianceStamped',
              'The star tracker at `star_tracker_rate`: the measured body attitude in '
              '`world_frame` and its orientation covariance (rad^2, about the world axes); the '
              'position is not measured (0, variance 1e12 m^2). None while the Sun or the Earth '
              'blocks the view (counted on /diagnostics).', 'if `star_tracker_rate` > 0'),
    Interface('pub', 'sun_sensor', 'geometry_msgs/msg/Vector3Stamped',
              'The sun sensor at `sun_sensor_rate`: the unit Sun direction (`body_frame`) with '
              '`sun_sensor_noise`; none outside `sun_sensor_fov` or in eclipse (counted).',
              'if `sun_sensor_rate` > 0'),
    Interface('pub', 'imu', 'sensor_msgs/msg/Imu',
              'REP 145 gyro at `imu_rate`: measured angular velocity and orientation with the '
              'gyro error model and their covariances; no acceleration (covariance[0] = -1).',
              'if `publish_imu`'),
    Interface('pub', '~/imu_bias', 'geometry_msgs/msg/Vector3Stamped',
              "The gyro's true bias (rad/s, `body_frame`) at each imu stamp.", 'if `publish_imu`'),
    Interface('pub', 'inertia', 'geometry_msgs/msg/InertiaStamped',
              'The inertia tensor (kg m^2, `body_frame`); transient local (latched); mass 0.'),
    Interface('pub', '/clock', 'rosgraph_msgs/msg/Clock',
              'Simulated time; best effort, depth 1.', 'if `publish_clock`'),
    Interface('pub', '/tf', 'tf2_msgs/msg/TFMessage',
              '`world_frame` -> `body_frame` at every odom stamp (rotation only; with an orbit '
              "the position too, and `world_frame` -> `lvlh_frame`); tf2_ros' "
              'broadcaster QoS.', 'if `publish_tf` and tf2_msgs is importable'),
    Interface('pub', '/diagnostics', 'diagnostic_msgs/msg/DiagnosticArray',
              '1 Hz: `<node>: integrator` and `<node>: torque command` statuses (and '
              '`<node>: reaction wheels` with wheels, `<node>: magnetorquers` with a field).'),
    Interface('pub', '~/real_time_factor', 'std_msgs/msg/Float64',
              'Achieved real-time factor, 1 Hz (simulated over wall time between wakes; 0 '
              'while paused).'),
    Interface('srv', '~/reset', 'std_srvs/srv/Trigger',
              'Back to the initial state; simulated time restarts at 0, the command is cleared.'),
    Interface('srv', '~/pause', 'std_srvs/srv/SetBool',
              '`true` freezes the state (nothing published), `false` resumes.'),
    # ROS 2's standard simulator interface ({doc}`../../howto/simulation_interfaces`)
    Interface('srv', 'get_simulator_features', 'simulation_interfaces/srv/GetSimulatorFeatures',
              'What of the standard interface this simulator does (states, resets by time and '
              'state, stepping, entity state).', SIM_IF),
    Interface('srv', 'get_simulation_state', 'simulation_interfaces/srv/GetSimulationState',
              'STOPPED (paused at time 0 and the initial state), PLAYING or PAUSED.', SIM_IF),
    Interface('srv', 'set_simulation_state', 'simulation_interfaces/srv/SetSimulationState',
              'Stop, play or pause; the target state again is ALREADY_IN_TARGET_STATE.',
              SIM_IF),
    Interface('srv', 'reset_simulation', 'simulation_interfaces/srv/ResetSimulation',
              'SCOPE_TIME (the state now at time 0), SCOPE_STATE (the initial state now), both, '
              'or SCOPE_ALL (as `~/reset`); playing or paused stays.', SIM_IF),
    Interface('srv', 'step_simulation', 'simulation_interfaces/srv/StepSimulation',
              'While paused or stopped: exactly `steps` integration steps (1 / '
              '`integration_rate` s each), published as they go; while playing '
              'RESULT_OPERATION_FAILED.', SIM_IF),
    Interface('srv', 'get_entities', 'simulation_interfaces/srv/GetEntities',
              'The one entity, the body, named by its body frame (with `frame_prefix`); the '
              'name filter is a regular expression.', SIM_IF),
    Interface('srv', 'get_entity_state', 'simulation_interfaces/srv/GetEntityState',
              'Attitude (and with an orbit the position), angular (and orbital) velocity and '
              'acceleration in `world_frame`, stamped with the simulated time.', SIM_IF),
    Interface('srv', 'set_entity_state', 'simulation_interfaces/srv/SetEntityState',
              'Sets the attitude and the angular velocity (world frame); an invalid quaternion '
              'is INVALID_POSE.', SIM_IF),
    Interface('action', 'simulate_steps', 'simulation_interfaces/action/SimulateSteps',
              'As `step_simulation`, with feedback after every step; a cancel stops between '
              'steps.', SIM_IF),
], qos={'torque_cmd': COMMANDS, 'wheel_cmd': COMMANDS, 'magnetorquer_cmd': COMMANDS,
        'inertia': LATCHED, '/clock': 'best effort, volatile, 1',
        '/tf': 'reliable, volatile, 100'}, intake=True)

ANALYZER = Interfaces('attitude_analyzer', [
    Interface('sub', 'odom', 'nav_msgs/msg/Odometry',
              'Attitude and angular velocity (with `gravity_gradient`, the position and '
              'linear velocity too); best effort, depth 1000, taken every 100 ms '
              '(hidden helper node `_attitude_analyzer_intake`).'),
    Interface('sub', 'applied_torque', 'geometry_msgs/msg/WrenchStamped',
              'Body torque (N m); with torque in the window the balance laws are checked '
              '(hidden helper node `_attitude_analyzer_intake`).'),
    Interface('sub', 'inertia', 'geometry_msgs/msg/InertiaStamped',
              'Latched; used unless the `inertia` parameter is set.'),
    Interface('sub', 'wheel_state', 'sensor_msgs/msg/JointState',
              "Reaction wheels' speeds and motor torques at the odom stamps; used with the "
              '`wheel_*` parameters (hidden helper node `_attitude_analyzer_intake`).'),
    Interface('sub', 'attitude_estimate', 'geometry_msgs/msg/PoseWithCovarianceStamped',
              "Any estimator's attitude and its covariance (about the world's axes), judged "
              'against odom at the same stamps: the `estimation` status (hidden helper node '
              '`_attitude_analyzer_intake`).'),
    Interface('sub', 'attitude_simulator/imu_bias', 'geometry_msgs/msg/Vector3Stamped',
              "The simulator's true gyro bias (its ~/imu_bias in this namespace): with "
              'attitude_estimator/gyro_bias_estimate, the bias error in `estimation`.'),
    Interface('sub', 'attitude_estimator/gyro_bias_estimate',
              'geometry_msgs/msg/Vector3Stamped',
              "The example estimator's ~/gyro_bias_estimate (remap it for another "
              'estimator).'),
    Interface('pub', 'precession/body_rate', 'std_msgs/msg/Float64',
              "rad/s: omega about the symmetry axis, body frame (Shapiro's Omega)."),
    Interface('pub', 'precession/lab_rate', 'std_msgs/msg/Float64',
              'rad/s: the symmetry axis about L, inertial frame.'),
    Interface('pub', 'kinetic_energy', 'std_msgs/msg/Float64', 'T (J).'),
    Interface('pub', 'angular_momentum_norm', 'std_msgs/msg/Float64', '|L| (kg m^2/s).'),
    Interface('pub', '/diagnostics', 'diagnostic_msgs/msg/DiagnosticArray',
              'Every `diagnostic_period`: `conservation`, `precession`, `stability`, `input` '
              '(and `orbit` with `gravity_gradient`: libration and the Jacobi integral; '
              '`estimation` once an attitude_estimate came).'),
    Interface('srv', '~/reset_baseline', 'std_srvs/srv/Trigger',
              'Measure drift from the next sample on.'),
], qos={name: INPUT for name in (
    'odom', 'applied_torque', 'wheel_state', 'attitude_estimate', 'attitude_simulator/imu_bias',
    'attitude_estimator/gyro_bias_estimate')} | {'inertia': LATCHED}, intake=True)

POINSOT = Interfaces('poinsot_visualizer', [
    Interface('sub', 'odom', 'nav_msgs/msg/Odometry', 'The motion to draw; best effort.'),
    Interface('sub', 'inertia', 'geometry_msgs/msg/InertiaStamped', 'Latched.'),
    Interface('pub', 'poinsot_markers', 'visualization_msgs/msg/MarkerArray',
              "In odom's `header.frame_id`: namespace `poinsot` (ellipsoid, omega, normal, "
              'plane, polhode, herpolhode) and `momentum_sphere` (sphere, L, its curve).'),
], qos={'odom': 'best effort, volatile, 100', 'inertia': LATCHED})

CONTROLLER = Interfaces('attitude_controller', [
    Interface('sub', 'odom', 'nav_msgs/msg/Odometry',
              'The states to answer; reliable, depth 10, `qos_overrides` for a best-effort '
              'source (taken by its own thread; hidden helper node '
              '`_attitude_controller_intake`).'),
    Interface('sub', 'inertia', 'geometry_msgs/msg/InertiaStamped',
              'Latched; no command before it (its diagonal gives the gains).'),
    Interface('sub', 'target_orientation', 'geometry_msgs/msg/QuaternionStamped',
              'Target attitude, body -> world; overrides the parameter.'),
    Interface('sub', 'wheel_state', 'sensor_msgs/msg/JointState',
              'The wheel speeds at the stamp of each state answered (hidden helper node '
              '`_attitude_controller_intake`).', 'if `actuator` is wheels'),
    Interface('sub', 'magnetic_field', 'sensor_msgs/msg/MagneticField',
              'The magnetometer readings B-dot answers (hidden helper node '
              '`_attitude_controller_intake`).', 'if `mode` is bdot'),
    Interface('pub', 'magnetorquer_cmd', 'geometry_msgs/msg/Vector3Stamped',
              "The B-dot dipole (A m^2, the reading's frame) stamped with the reading's stamp.",
              'if `mode` is bdot'),
    Interface('pub', 'torque_cmd', 'geometry_msgs/msg/WrenchStamped',
              'Torque (N m, body frame) stamped with the stamp of the state it answers; with '
              'wheels, the momentum dump (zero unless dumping), published before wheel_cmd.'),
    Interface('pub', 'wheel_cmd', 'std_msgs/msg/Float64MultiArray',
              "Motor torques (N m, one per wheel) flying the law's torque.",
              'if `actuator` is wheels'),
], qos={'inertia': LATCHED}, intake=True)

ESTIMATOR = Interfaces('attitude_estimator', [
    Interface('sub', 'imu', 'sensor_msgs/msg/Imu',
              'The gyro: its angular_velocity propagates the estimate (the orientation is '
              'not used).'),
    Interface('sub', 'star_tracker', 'geometry_msgs/msg/PoseWithCovarianceStamped',
              'Attitude readings; the first starts the filter. Weighted by '
              '`star_tracker_noise` and `star_tracker_orientation`, not by the covariance '
              'the message carries.'),
    Interface('sub', 'sun_sensor', 'geometry_msgs/msg/Vector3Stamped',
              'Sun directions (body frame) against the Sun of `epoch` / `sun_direction`; '
              'used when `sun_sensor_noise` > 0.'),
    Interface('sub', 'magnetic_field', 'sensor_msgs/msg/MagneticField',
              'The field (body frame) against the field model on the orbit; used with '
              '`magnetic_field_model` dipole or igrf and `magnetometer_noise` > 0.'),
    Interface('pub', 'attitude_estimate', 'geometry_msgs/msg/PoseWithCovarianceStamped',
              'The estimate at every gyro stamp (one gyro sample late): orientation in '
              '`world_frame`, its covariance about the world axes (rad^2); position not '
              'estimated (0, variance 1e12 m^2).'),
    Interface('pub', '~/gyro_bias_estimate', 'geometry_msgs/msg/Vector3Stamped',
              "The gyro bias estimate (rad/s, `body_frame`) at the estimate's stamp."),
    Interface('pub', '/diagnostics', 'diagnostic_msgs/msg/DiagnosticArray',
              '1 Hz: `<node>: filter` (its sigmas, the bias, readings used, late readings '
              'dropped, gyro gaps (readings missing), restarts).'),
])

#: Every node's table, by executable name.
NODES = {t.node: t for t in (SIMULATOR, ANALYZER, POINSOT, CONTROLLER, ESTIMATOR)}
