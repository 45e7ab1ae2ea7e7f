"""
attitude_simulator: integrates Euler's equations and publishes the attitude state.

Topics, frames and parameters are listed in the README (the parameter list is
made from ``PARAMETERS`` below).
The node is thin: it keeps the parameters, the torque subscription, the
services and the diagnostics; the body is an engine
:class:`~rigid_body_dynamics.engine.body.BodySimulation` (ROS-free), paced by
an engine :class:`~rigid_body_dynamics.engine.pacer.Pace`, and its state
messages come from a :class:`~.state_publisher.StatePublisher`.

Threads. Integration and state publishing run on one steady-clock thread
that sleeps until each step's deadline, so a torque command is used from the
next integration step on and pacing costs a few percent of a core at 1 kHz.
Subscriptions, services, parameter changes and diagnostics run on the
executor; both sides share the body under its lock.

Time. The simulated time is an integer step count times dt. Every message of
one publish tick carries header.stamp = start + simulated time (start is the
ROS time at start-up, or 0 with ``publish_clock``, which also publishes it on
/clock). A ``~/reset`` returns the state *and* the simulated time to the start.

Lockstep (``lockstep``): instead of the wall clock, an engine
:class:`~rigid_body_dynamics.engine.lockstep.Lockstep` paces the body by its
controller: the state at each control tick goes out, the body waits for a
``torque_cmd`` stamped at or after the tick, holds it from the tick on and
integrates to the next as fast as it can.
"""

import math
import os
import sys
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import WrenchStamped
import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos_overriding_options import QoSOverridingOptions
from rclpy.serialization import deserialize_message
from std_msgs.msg import Float64
from std_srvs.srv import SetBool, Trigger

from . import conversions as conv
from .intake import Intake
from .parameters import as_vector, ConfigurationError, Param, ParameterTable
from .runner import run
from .state_publisher import OPTIONAL_TOPICS, STATE_QOS, StatePublisher, tf_available
from .throttle import ThrottledWarnings
from ..engine import BodySimulation, Disturbances, Lockstep, Pace
from ..engine.pacer import LATE_LIMIT
from ..physics import Inertia, INTEGRATORS, presets
from ..physics.disturbances import GravityGradient
from ..physics.integrators import REMOVED as REMOVED_INTEGRATORS
from ..physics.sensors import GyroErrors

NODE_NAME = 'attitude_simulator'
_NS = 1_000_000_000
#: Period of /diagnostics (s, steady clock).
DIAGNOSTIC_PERIOD = 1.0
#: Python's GIL switch interval for the simulator process (s). The default 5 ms
#: lets a busy executor thread (a torque-command flood) hold the interpreter
#: for 5 ms after the integration thread's deadline; 0.5 ms bounds that wait.
SWITCH_INTERVAL = 0.0005


def use_thread_priority(priority, logger):
    """
    Put the calling thread under SCHED_FIFO at ``priority`` (1-99); 0 leaves it alone.

    Logs the outcome; a refusal (no CAP_SYS_NICE / rtprio limit, not Linux)
    is a warning, and the thread keeps normal scheduling.
    """
    if not priority:
        return
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except (AttributeError, OSError) as err:
        logger.warning(f'thread_priority {priority}: SCHED_FIFO refused ({err}); the '
                       'integration thread keeps normal scheduling (grant CAP_SYS_NICE or an '
                       'rtprio limit to use it)')
        return
    logger.info(f'integration thread runs under SCHED_FIFO at priority {priority}')


def integration_loop(cycle, stop, priority, logger, context):
    """
    Call ``cycle()`` until the event ``stop`` is set: the body of an integration thread.

    Applies the SCHED_FIFO ``priority`` first (0: none). An error after
    shutdown began (a publisher closed under the loop) ends it quietly; any
    other is logged on ``logger`` and raised.
    """
    use_thread_priority(priority, logger)
    try:
        while not stop.is_set():
            cycle()
    except Exception as err:
        if rclpy.ok(context=context) and not stop.is_set():
            logger.error(f'integration thread stopped: {err!r}')
            raise


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


def _state_topics(value):
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


def _imu_rate(values, out):
    """Cross-check: imu_rate <= integration_rate."""
    if out['imu_rate'] > out['integration_rate']:
        raise ConfigurationError(f'imu_rate must be at most integration_rate '
                                 f'({out["integration_rate"]:g} Hz), got {out["imu_rate"]:g}')


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
    """Cross-check: the orbit's frame is valid when the gravity gradient is on."""
    if out['gravity_gradient_orbit_rate'] > 0.0:
        try:
            GravityGradient((1.0, 1.0, 1.0), out['gravity_gradient_orbit_rate'],
                            out['orbit_normal'], out['orbit_nadir'])
        except ValueError as err:
            raise ConfigurationError(str(err).replace('nadir0', 'orbit_nadir')) from None
    out['disturbances'] = Disturbances(
        out['disturbance_torque_body'], out['disturbance_torque_world'],
        out['gravity_gradient_orbit_rate'], out['orbit_normal'], out['orbit_nadir'])


def _publish_rate(values, out):
    """Cross-check: publish_rate <= integration_rate."""
    if out['publish_rate'] > out['integration_rate']:
        raise ConfigurationError(f'publish_rate must be within [1e-06, '
                                 f'{out["integration_rate"]:g}] (at most integration_rate), '
                                 f'got {out["publish_rate"]:g}')


#: The parameters of attitude_simulator (README's list is made from this; test_config checks).
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
    Param('thread_priority', 'int', 0, '0',
          'SCHED_FIFO priority (1-99) of the integration thread on Linux, for fewer missed '
          'deadlines on a loaded machine; 0 = normal scheduling. Needs CAP_SYS_NICE or an '
          'rtprio limit (limits.conf); if refused, the node says so and runs normally.',
          low=0, high=99, read_only=True),
    Param('state_topics', 'string', 'all', '`all`',
          'State topics published besides odom: all, none, or a comma-separated choice of '
          'orientation, angular_velocity, angular_momentum, angular_momentum_body, '
          'applied_torque (odom carries attitude and rate; fewer topics let one fleet '
          'carry more bodies, see benchmarks).', read_only=True, convert=_state_topics),
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
    Param('gravity_gradient_orbit_rate', 'double', 0.0, '0.0 rad/s',
          'Orbit rate n of a circular orbit whose gravity-gradient torque 3 n^2 r x (I r) '
          'acts on the body (r the nadir unit vector in the body frame); 0 = none. '
          'Low Earth orbit: about 1.1e-3.', low=0.0, high=1e3, read_only=True),
    Param('orbit_normal', 'double[3]', [0.0, 0.0, 1.0], '[0, 0, 1]',
          'Orbit normal (world frame): nadir turns about it at n.', read_only=True),
    Param('orbit_nadir', 'double[3]', [1.0, 0.0, 0.0], '[1, 0, 0]',
          'Direction from the body to the planet (world frame) at simulated time 0; made '
          'perpendicular to orbit_normal.', read_only=True),
    Param('noise_seed', 'int', 0, '0',
          'Seed of the gyro noise: the same seed and parameters give the same imu stream, bit '
          'for bit (also after ~/reset).', low=0, high=2 ** 31 - 1, read_only=True),
], cross_checks=(_body, _publish_rate, _imu_rate, _control_steps, _disturbances))


def _preset_name(name):
    if name not in presets.PRESETS:
        try:
            presets.get(name)
        except ValueError as err:
            raise ConfigurationError(str(err)) from None
    return name


class AttitudeSimulator(Node):
    """
    The attitude_simulator node. ``kwargs`` go to rclpy's Node (context, overrides).

    :meth:`start` starts its integration thread and diagnostics timer. A host
    of many bodies (attitude_fleet) instead drives ``pace`` itself, publishes
    the snapshots with ``state`` and calls :meth:`publish_diagnostics`.
    """

    def __init__(self, **kwargs):
        super().__init__(NODE_NAME, **kwargs)
        self._stop = threading.Event()
        self._thread = None
        values = PARAMETERS.validate(PARAMETERS.declare(self))
        self._preset = presets.get(values['preset'])
        self._frames = (values['world_frame'], values['body_frame'])
        self._publish_clock = values['publish_clock']
        self.thread_priority = values['thread_priority']
        self._rate = rate = values['integration_rate']
        self._warnings = ThrottledWarnings(self.get_logger())
        start_ns = 0 if self._publish_clock else self.get_clock().now().nanoseconds
        self.lockstep = values['lockstep']
        self._misses_seen = 0
        self.body = BodySimulation(
            values['body'], values['integrator'], rate,
            (values['initial_orientation'], values['initial_angular_velocity']),
            0.0 if self.lockstep else values['torque_timeout'], values['max_torque'],
            self._publish_every(values['publish_rate']), start_ns,
            imu_every=self._publish_every(values['imu_rate']) if values['publish_imu'] else 0,
            gyro=GyroErrors(values['gyro_noise_density'], values['gyro_bias_random_walk'],
                            values['gyro_turn_on_bias'], values['gyro_bias_correlation_time'],
                            values['orientation_noise'], values['gyro_resolution']),
            seed=values['noise_seed'], disturbances=values['disturbances'])
        self._publish_rate = values['publish_rate']
        if self.lockstep:
            self.pace = Lockstep(self.body, values['control_every'], values['lockstep_timeout'],
                                 wait_for_commands=self._take_torque)
        else:
            self.pace = Pace(self.body, values['real_time_factor'], on_backlog=self._on_backlog)
        self._make_interfaces()
        self.state.publish_inertia(self.body.inertia, start_ns)
        with self.body.lock:
            items = self.body.first_items()
        for item in items:
            self.state.publish(item)
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.add_post_set_parameters_callback(self._post_set_parameters)
        body = self.body.inertia
        rtf = self.pace.rtf
        pacing = (f'lockstep every {values["control_period"]:g} s (waiting for the first '
                  'torque_cmd)' if self.lockstep else
                  f'real-time factor {rtf:g}{" (as fast as possible)" if rtf == 0 else ""}')
        self.get_logger().info(
            f'{self._preset.name}: I = {body.moments.tolist()} kg m^2 ({body.kind}), '
            f'omega0 = {list(self.body.initial[1])} rad/s, {self.body.integrator_name} at '
            f'{rate:g} Hz, publishing at {self._publish_rate:g} Hz, {pacing}')
        if values['disturbances'].active:
            self.get_logger().info(f'disturbances: {values["disturbances"]}')

    # ------------------------------------------------------------------ parameters
    def _on_set_parameters(self, params):
        return PARAMETERS.on_set(self, params)

    def _post_set_parameters(self, params):
        names = {p.name for p in params}
        if not names & set(PARAMETERS.params):
            return
        self._apply(PARAMETERS.validate(PARAMETERS.values(self)), changed=names)

    def _publish_every(self, publish_rate):
        return max(1, round(self._rate / publish_rate))

    def _apply(self, values, changed):
        """Take validated values into effect (a parameter change after start-up)."""
        body = self.body
        self._publish_rate = values['publish_rate']
        with body.lock:
            inertia = values['body'] if {'inertia', 'inertia_tensor'} & set(changed) else None
            lines = body.configure(
                inertia=inertia, integrator=values['integrator'],
                initial=(values['initial_orientation'], values['initial_angular_velocity']),
                torque_timeout=0.0 if self.lockstep else values['torque_timeout'],
                max_torque=values['max_torque'],
                publish_every=self._publish_every(values['publish_rate']),
                disturbances=values['disturbances'])
            if 'real_time_factor' in changed:
                self.pace.set_rtf(values['real_time_factor'])
        if inertia is not None:
            self.state.publish_inertia(body.inertia, body.start_ns)
        for line in lines:
            self.get_logger().info(line)

    # ------------------------------------------------------------------ interfaces
    def _make_interfaces(self):
        publish_tf = self.get_parameter('publish_tf').value
        self.state = StatePublisher(
            self, self._frames, publish_imu=self.get_parameter('publish_imu').value,
            publish_clock=self._publish_clock, publish_tf=publish_tf,
            topics=_state_topics(self.get_parameter('state_topics').value))
        if publish_tf and not tf_available():
            self.get_logger().info('publish_tf: tf2_msgs is not importable here (no tf2_msgs '
                                   'wheel exists; on a ROS install it is), so /tf is not '
                                   'broadcast; odom carries the same pose')
        self._pub_diag = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self._pub_rtf = self.create_publisher(Float64, '~/real_time_factor', 10)
        if self.get_parameter('lockstep').value:
            # the lockstep thread takes its commands itself: no executor hop in the loop
            self._intake = Intake(self)
            self._intake.subscribe(WrenchStamped, 'torque_cmd', STATE_QOS)
        else:
            self.create_subscription(
                WrenchStamped, 'torque_cmd', self._on_torque, STATE_QOS,
                qos_overriding_options=QoSOverridingOptions.with_default_policies())
        self.create_service(Trigger, '~/reset', self._on_reset)
        self.create_service(SetBool, '~/pause', self._on_pause)

    # ------------------------------------------------------------------ torque
    def _on_torque(self, msg):
        warn = self._warnings.warn
        frame = msg.header.frame_id
        if not conv.is_finite_vector(msg.wrench.torque):
            self.body.reject('rejected_non_finite')
            warn('non-finite', 'torque_cmd rejected: non-finite torque; state unchanged')
            return
        world_frame, body_frame = self._frames
        if frame not in ('', body_frame, world_frame):
            self.body.reject('rejected_frame')
            shown = frame if len(frame) <= 64 else frame[:64] + '...'
            warn('frame', f'torque_cmd rejected: unknown frame_id {shown!r}; use '
                 f'{body_frame!r}, {world_frame!r} or "" (= body)')
            return
        f = msg.wrench.force
        vector, world = conv.vector_array(msg.wrench.torque), \
            frame == world_frame and frame != body_frame
        if self.lockstep:
            events = self.pace.command(vector, world, time.monotonic_ns(),
                                       conv.time_ns(msg.header.stamp), force=(f.x, f.y, f.z))
            if 'stale' in events:
                warn('stale', 'lockstep: torque_cmd stamped before the current tick dropped '
                     '(an answer that came after its tick was missed)')
        else:
            events = self.body.command(vector, world, time.monotonic_ns(),
                                       force=(f.x, f.y, f.z))
        if 'clipped' in events:
            warn('clipped', f'torque_cmd clipped to max_torque = {self.body.max_torque:g} N m '
                 'per axis')
        if 'force_ignored' in events:
            warn('force', 'torque_cmd carries a force; only the torque is used (the body '
                 'does not translate)', period=math.inf)

    def _take_torque(self, timeout):
        """Lockstep: wait up to ``timeout`` s for torque_cmd and take every pending one."""
        if self._intake.wait('torque_cmd', timeout):
            for raw in self._intake.take('torque_cmd'):
                self._on_torque(deserialize_message(raw, WrenchStamped))

    def destroy_node(self):
        """Destroy the lockstep intake's helper node too."""
        if getattr(self, '_intake', None) is not None:
            self._intake.destroy()
            self._intake = None
        super().destroy_node()

    # ------------------------------------------------------------------ stepping
    def start(self, diagnostics=True):
        """
        Start the integration thread (and shorten the GIL switch interval, process-wide).

        With ``diagnostics`` also the 1 Hz diagnostics timer (steady clock);
        attitude_fleet with a thread per body serves all bodies from one timer.
        """
        if diagnostics:
            steady = Clock(clock_type=ClockType.STEADY_TIME)
            self.create_timer(DIAGNOSTIC_PERIOD, self.publish_diagnostics, clock=steady)
        sys.setswitchinterval(SWITCH_INTERVAL)
        self._thread = threading.Thread(
            target=integration_loop, name='integration', daemon=True,
            args=(self._cycle, self._stop, self.thread_priority, self.get_logger(),
                  self.context))
        self._thread.start()

    def stop(self):
        """Stop the integration thread and wait for it."""
        self._stop.set()
        if self.lockstep:
            self.pace.arrived.set()       # wake a lockstep wait
        if self._thread is not None:
            self._thread.join(timeout=5.0)

    def _cycle(self):
        """Integrate and publish the steps that are due, then sleep until the next is due."""
        wait = self.step_due()
        if wait > 0.0:
            self._stop.wait(wait)

    def step_due(self):
        """
        Integrate the steps that are due now (a batch, as fast as possible) and publish them.

        Returns the wall time (s) until the next step is due. Publishing happens
        outside the body's lock: a torque command never waits for it.
        """
        outbox = []
        wait = self.pace.due(outbox)
        self.log_notes()
        for snapshot in outbox:
            self.state.publish(snapshot)
        return wait

    def log_notes(self):
        """Log what the body noted while stepping (the watchdog's timeouts)."""
        for note in self.body.take_notes():
            self.get_logger().info(note)

    def _on_backlog(self, behind):
        self._warnings.warn('backlog', f'cannot keep up with real_time_factor {self.pace.rtf:g}: '
                            f'dropped a backlog of {behind} steps', period=5.0)

    # ------------------------------------------------------------------ diagnostics
    def publish_diagnostics(self):
        """Publish /diagnostics and ~/real_time_factor (every DIAGNOSTIC_PERIOD s)."""
        name = self.get_name()
        hw = self.get_fully_qualified_name()
        body, pace = self.body, self.pace
        achieved = pace.achieved()
        max_late = pace.take_max_late()
        h = body.health()
        rtf = pace.rtf
        if h['paused']:
            level, message = DiagnosticStatus.OK, 'paused'
        elif self.lockstep:
            misses = pace.misses
            level = DiagnosticStatus.WARN if misses > self._misses_seen else DiagnosticStatus.OK
            self._misses_seen = misses
            message = ('lockstep: waiting for the first torque_cmd' if not pace.ticks else
                       f'lockstep at {achieved:.3g}x real time, {misses} missed ticks')
        elif rtf and achieved < 0.9 * rtf:
            level, message = DiagnosticStatus.WARN, (
                f'running at {achieved:.3g}x real time, {rtf:g}x requested')
        else:
            level, message = DiagnosticStatus.OK, 'running'
        integrator = conv.status(f'{name}: integrator', level, message, [
            ('integrator', body.integrator_name), ('dt (s)', body.dt), ('steps', h['steps']),
            ('simulated time (s)', h['time']), ('requested real-time factor', rtf),
            ('achieved real-time factor', achieved),
            (f'missed deadlines (> {LATE_LIMIT * 1e3:g} ms late)', pace.missed),
            ('latest step lateness in the last period (ms)', max_late),
            ('quaternion norm error', h['quaternion norm error']),
            ('energy drift since last torque (rel.)', h['energy drift']),
            ('|L| drift since last torque (rel.)', h['momentum drift']),
            ('L direction drift since last torque (rad)', h['direction drift']),
            ('work since reset (J)', h['work']),
        ] + self._lockstep_values(), hw)
        cmd, counts, timed_out = h['command'], h['counts'], h['timed_out']
        age = (time.monotonic_ns() - cmd.received_ns) / _NS if cmd is not None else math.inf
        rejected = counts['rejected_non_finite'] + counts['rejected_frame']
        if cmd is None:
            level, message = DiagnosticStatus.OK, 'no command received'
        elif timed_out:
            level, message = DiagnosticStatus.WARN, f'timed out {age:.2f} s after the last command'
        else:
            level, message = DiagnosticStatus.OK, 'holding the last command'
        if rejected:
            message += f'; {rejected} rejected'
        torque = conv.status(f'{name}: torque command', level, message, [
            ('command age (s)', age), ('timed out', timed_out),
            ('frame', 'none' if cmd is None else ('world' if cmd.world else 'body')),
            ('command (N m)', 'none' if cmd is None else list(cmd.vector)),
            ('timeout (s)', body.timeout_ns / _NS)] + list(counts.items()), hw)
        array = DiagnosticArray(status=[integrator, torque])
        array.header.stamp = self.get_clock().now().to_msg()
        self._pub_diag.publish(array)
        self._pub_rtf.publish(Float64(data=achieved))

    def _lockstep_values(self):
        """Diagnostics of lockstep: answered and missed ticks, the wall wait per tick."""
        if not self.lockstep:
            return []
        mean, worst = self.pace.take_wait()
        return [('lockstep', True), ('control period (s)', self.pace.control_every * self.body.dt),
                ('answered ticks', self.pace.ticks), ('missed ticks', self.pace.misses),
                ('mean wait per answered tick (ms)', mean),
                ('longest wait in the last period (ms)', worst)]

    # ------------------------------------------------------------------ services
    def _on_reset(self, _request, response):
        with self.body.lock:
            self.body.reset()
            self.pace.restart()
            items = self.body.first_items()
        for item in items:
            self.state.publish(item)
        self.get_logger().info('reset to the initial state, simulated time 0')
        response.success = True
        response.message = 'reset to the initial state; simulated time restarts at 0'
        return response

    def _on_pause(self, request, response):
        body = self.body
        with body.lock:
            was = body.set_paused(request.data)
            if was and not body.paused:
                self.pace.anchor()
            state = 'paused' if body.paused else 'running'
            t = body.steps * body.dt
        self.get_logger().info(f'simulation {state} at t = {t:.6g} s')
        response.success = True
        response.message = state
        return response


def main(args=None, early=None):
    """Run until Ctrl-C / SIGTERM; exit 0, or 1 on bad configuration (see runner.run)."""
    return run(AttitudeSimulator, NODE_NAME, args, early=early,
               on_start=lambda node: node.start(), on_stop=lambda node: node.stop())


if __name__ == '__main__':
    sys.exit(main())
