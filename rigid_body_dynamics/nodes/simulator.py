"""
attitude_simulator: integrates Euler's equations and publishes the attitude state.

Topics, frames and parameters follow DESIGN.md (see README for the list).
The node is thin: the physics is :mod:`rigid_body_dynamics.physics`.

Threads. Integration and state publishing run on one steady-clock thread
that sleeps until each step's deadline, so a torque command is used from the
next integration step on and pacing costs a few percent of a core at 1 kHz.
Subscriptions, services, parameter changes and diagnostics run on the
executor; both sides share the simulation state under one lock.

Time. The simulated time is an integer step count times dt. Every message of
one publish tick carries header.stamp = start + simulated time (start is the
ROS time at start-up, or 0 with ``publish_clock``, which also publishes it on
/clock). A ``~/reset`` returns the state *and* the simulated time to the start.
"""

import math
import os
import sys
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import InertiaStamped, QuaternionStamped, Vector3Stamped, WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy)
from rclpy.qos_overriding_options import QoSOverridingOptions
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import Imu
from std_msgs.msg import Float64
from std_srvs.srv import SetBool, Trigger

from . import conversions as conv
from .parameters import as_float, as_vector, check_change, ConfigurationError, descriptor
from .runner import run
from .throttle import ThrottledWarnings
from ..physics import Inertia, INTEGRATORS, make_integrator, presets, quaternions
from ..physics.integrators import REMOVED as REMOVED_INTEGRATORS

NODE_NAME = 'attitude_simulator'
_ZERO = (0.0, 0.0, 0.0)
_NS = 1_000_000_000
#: Wall time the pacing may fall behind before the backlog is dropped (s).
MAX_LAG = 0.25
#: A step computed more than this after its deadline counts as a missed deadline (s).
LATE_LIMIT = 0.005
#: In as-fast-as-possible mode, wall time per batch of steps (s), and the pause
#: after each batch that lets the executor thread take the lock (services,
#: parameters, torque commands, diagnostics); without it the lock is re-taken
#: at once and the executor starves.
AFAP_BATCH = 0.005
AFAP_YIELD = 0.0002
#: Period of /diagnostics (s, steady clock).
DIAGNOSTIC_PERIOD = 1.0
#: Python's GIL switch interval for the simulator process (s). The default 5 ms
#: lets a busy executor thread (a torque-command flood) hold the interpreter
#: for 5 ms after the integration thread's deadline; 0.5 ms bounds that wait.
SWITCH_INTERVAL = 0.0005

STATE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                       reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.VOLATILE)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
CLOCK_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                       reliability=ReliabilityPolicy.BEST_EFFORT)


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


def integration_loop(cycle, stop, node):
    """
    Call ``cycle()`` until the event ``stop`` is set: the body of an integration thread.

    Applies ``node``'s thread_priority first. An error after shutdown began
    (a publisher closed under the loop) ends it quietly; any other is logged
    on ``node`` and raised.
    """
    use_thread_priority(node.thread_priority, node.get_logger())
    try:
        while not stop.is_set():
            cycle()
    except Exception as err:
        if rclpy.ok(context=node.context) and not stop.is_set():
            node.get_logger().error(f'integration thread stopped: {err!r}')
            raise


class TorqueCommand:
    """The held torque command: body- or world-frame vector (N m) and its steady receive time."""

    __slots__ = ('vector', 'world', 'received_ns', 'principal')

    def __init__(self, vector, world, received_ns, principal):
        self.vector = vector
        self.world = world
        self.received_ns = received_ns
        self.principal = principal


class AttitudeSimulator(Node):
    """
    The attitude_simulator node. ``kwargs`` go to rclpy's Node (context, overrides).

    ``diagnostics_timer=False`` leaves the 1 Hz diagnostics to the caller
    (``publish_diagnostics``), as attitude_fleet does with one timer for all.
    """

    def __init__(self, diagnostics_timer=True, **kwargs):
        super().__init__(NODE_NAME, **kwargs)
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._thread = None
        self._declare_parameters()
        values = self._validate({p: self.get_parameter(p).value for p in self._dynamic})
        self._frames = (self.get_parameter('world_frame').value,
                        self.get_parameter('body_frame').value)
        self._publish_clock = self.get_parameter('publish_clock').value
        self.thread_priority = self.get_parameter('thread_priority').value
        rate = as_float('integration_rate', self.get_parameter('integration_rate').value,
                        1e-6, 1e5)
        self._rate = rate
        self._dt = 1.0 / rate
        self._dt_ns = _NS / rate
        self._apply(values, initial=True)
        self._counts = dict.fromkeys(
            ('accepted', 'rejected_non_finite', 'rejected_frame', 'clipped', 'force_ignored'), 0)
        self._warnings = ThrottledWarnings(self.get_logger())
        self._make_interfaces(diagnostics_timer)
        self._start_ns = 0 if self._publish_clock else self.get_clock().now().nanoseconds
        self._reset_state()
        self._publish_inertia()
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.add_post_set_parameters_callback(self._post_set_parameters)
        body = self._inertia
        self.get_logger().info(
            f'{self._preset.name}: I = {body.moments.tolist()} kg m^2 ({body.kind}), '
            f'omega0 = {list(self._initial[1])} rad/s, {self._integrator_name} at '
            f'{rate:g} Hz, publishing at {self._publish_rate:g} Hz, real-time factor '
            f'{self._rtf:g}{" (as fast as possible)" if self._rtf == 0 else ""}')

    # ------------------------------------------------------------------ parameters
    def _declare_parameters(self):
        preset_name = self.declare_parameter(
            'preset', presets.DEFAULT,
            descriptor('Named body from physics/presets.py; its values are the defaults of '
                       'the parameters below, which override them.', read_only=True,
                       constraints='one of: ' + ', '.join(sorted(presets.PRESETS)))).value
        try:
            self._preset = preset = presets.get(preset_name)
        except ValueError as err:
            raise ConfigurationError(str(err)) from None
        num = {'dynamic_typing': True}
        self._dynamic = []

        def declare(name, default, desc):
            self.declare_parameter(name, default, desc)
            self._dynamic.append(name)

        declare('inertia', [float(v) for v in preset.moments], descriptor(
            'Principal moments [I1, I2, I3] (kg m^2), body = principal frame; positive and '
            'satisfying I1 + I2 >= I3 and permutations. A change keeps attitude and angular '
            'velocity.', **num))
        self.declare_parameter('inertia_tensor', None, descriptor(
            'Optional full tensor [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (kg m^2, tensor elements as in '
            'URDF) in the body frame; overrides inertia. Unset by default.', **num))
        self._dynamic.append('inertia_tensor')
        declare('initial_orientation', [float(v) for v in preset.q0], descriptor(
            'Initial attitude (x, y, z, w), body -> world; normalised. Used at start and on '
            '~/reset.', **num))
        declare('initial_angular_velocity', [float(v) for v in preset.omega0], descriptor(
            'Initial angular velocity (rad/s) in the body frame. Used at start and on ~/reset.',
            **num))
        declare('integrator', 'exact', descriptor(
            'Integration method; a change continues from the current state.',
            constraints='one of: ' + ', '.join(sorted(INTEGRATORS))))
        self.declare_parameter('integration_rate', float(preset.integration_rate), descriptor(
            'Integration steps per simulated second (Hz); dt = 1 / rate.', read_only=True,
            low=1e-6, high=1e5, **num))
        declare('publish_rate', float(preset.publish_rate), descriptor(
            'State messages per simulated second (Hz); at most integration_rate, rounded to a '
            'whole number of steps.', low=1e-6, high=1e5, **num))
        declare('real_time_factor', float(preset.real_time_factor), descriptor(
            'Simulated seconds per wall second on the steady clock; 0 = as fast as possible.',
            low=0.0, high=1e12, **num))
        self.declare_parameter('publish_clock', False, descriptor(
            'Publish the simulated time on /clock (stamps then start at 0) so that other nodes '
            'can run with use_sim_time.', read_only=True))
        declare('torque_timeout', 0.5, descriptor(
            'A torque command is held until replaced or until this long (s, steady clock) '
            'after it arrived; 0 = hold forever.', low=0.0, high=1e9, **num))
        declare('max_torque', 0.0, descriptor(
            'Per-axis limit on the commanded torque (N m); larger values are clipped and '
            'counted. 0 = no limit.', low=0.0, high=1e30, **num))
        self.declare_parameter('world_frame', 'odom', descriptor(
            'Inertial frame id (REP 105) of orientation, angular_momentum and odom.',
            read_only=True))
        self.declare_parameter('body_frame', 'base_link', descriptor(
            'Body frame id of angular_velocity, angular_momentum_body, applied_torque, imu.',
            read_only=True))
        self.declare_parameter('thread_priority', 0, descriptor(
            'SCHED_FIFO priority (1-99) of the integration thread on Linux, for fewer missed '
            'deadlines on a loaded machine; 0 = normal scheduling. Needs CAP_SYS_NICE or an '
            'rtprio limit (limits.conf); if refused, the node says so and runs normally.',
            read_only=True, low=0, high=99, integer=True))
        self.declare_parameter('publish_imu', True, descriptor(
            'Also publish sensor_msgs/Imu on imu (REP 145; no acceleration).', read_only=True))

    def _validate(self, values):
        """
        Check parameter values and return them converted; raise ConfigurationError.

        ``values`` maps names to new values merged over the current ones. Free
        of side effects (used by the on-set callback).
        """
        out = dict(values)
        tensor = values.get('inertia_tensor')
        try:
            if tensor is not None and len(tensor) > 0:
                out['inertia_tensor'] = as_vector('inertia_tensor', tensor, 6)
                out['body'] = Inertia.from_tensor(out['inertia_tensor'])
            else:
                out['body'] = Inertia(as_vector('inertia', values['inertia'], 3))
        except ValueError as err:
            raise ConfigurationError(str(err)) from None
        q = as_vector('initial_orientation', values['initial_orientation'], 4)
        norm = math.sqrt(sum(c * c for c in q))
        if norm < 1e-9:
            raise ConfigurationError('initial_orientation must not be the zero quaternion')
        out['initial_orientation'] = tuple(c / norm for c in q)
        out['initial_angular_velocity'] = as_vector(
            'initial_angular_velocity', values['initial_angular_velocity'], 3)
        if values['integrator'] not in INTEGRATORS:
            raise ConfigurationError(REMOVED_INTEGRATORS.get(values['integrator']) or (
                f'unknown integrator {values["integrator"]!r}; choose one of '
                f'{", ".join(sorted(INTEGRATORS))}'))
        rate = getattr(self, '_rate', None) or as_float(
            'integration_rate', self.get_parameter('integration_rate').value, 1e-6, 1e5)
        out['publish_rate'] = as_float('publish_rate', values['publish_rate'], 1e-6, rate)
        out['real_time_factor'] = as_float('real_time_factor', values['real_time_factor'],
                                           0.0, 1e12)
        out['torque_timeout'] = as_float('torque_timeout', values['torque_timeout'], 0.0, 1e9)
        out['max_torque'] = as_float('max_torque', values['max_torque'], 0.0, 1e30)
        return out

    def _on_set_parameters(self, params):
        values = {p: self.get_parameter(p).value for p in self._dynamic}
        for param in params:
            if param.name in values:
                values[param.name] = param.value
        return check_change(self.get_logger(), self._validate, values)

    def _post_set_parameters(self, params):
        names = {p.name for p in params}
        if not names & set(self._dynamic):
            return
        values = self._validate({p: self.get_parameter(p).value for p in self._dynamic})
        with self._lock:
            self._apply(values, changed=names)

    def _apply(self, values, initial=False, changed=()):
        """Take validated values into effect (under the lock after start-up)."""
        body = values['body']
        self._initial = (values['initial_orientation'], values['initial_angular_velocity'])
        self._publish_rate = values['publish_rate']
        self._publish_every = max(1, round(self._rate / self._publish_rate))
        self._timeout_ns = int(values['torque_timeout'] * _NS)
        self._max_torque = values['max_torque']
        if initial:
            self._inertia = body
            self._integrator_name = values['integrator']
            self._rtf = values['real_time_factor']
            return
        log = self.get_logger()
        if 'real_time_factor' in changed:
            self._rtf = values['real_time_factor']
            self._anchor()
        rebuild = False
        if {'inertia', 'inertia_tensor'} & set(changed):
            q_b, w_b = self._body_state()
            self._inertia = body
            self._stepper.reset(body.attitude_to_principal(np.array(q_b)),
                                body.to_principal(np.array(w_b)))
            rebuild = True
            self._publish_inertia()
            log.info(f'inertia now {body.moments.tolist()} kg m^2 ({body.kind}); '
                     'attitude and angular velocity kept')
        if 'integrator' in changed and values['integrator'] != self._integrator_name:
            self._integrator_name = values['integrator']
            rebuild = True
            log.info(f'integrator now {self._integrator_name}, continuing from the current state')
        if rebuild:
            self._stepper = make_integrator(self._integrator_name, self._inertia.moments,
                                            self._dt, self._stepper.q, self._stepper.omega)
            self._baseline()
            if self._command is not None:
                self._command = self._make_command(self._command.vector, self._command.world,
                                                   self._command.received_ns)

    # ------------------------------------------------------------------ interfaces
    def _make_interfaces(self, diagnostics_timer):
        qos_opts = QoSOverridingOptions.with_default_policies()

        def pub(msg_type, name, qos=STATE_QOS):
            return self.create_publisher(msg_type, name, qos, qos_overriding_options=qos_opts)
        self._pub_odom = pub(Odometry, 'odom')
        self._pub_orientation = pub(QuaternionStamped, 'orientation')
        self._pub_omega = pub(Vector3Stamped, 'angular_velocity')
        self._pub_l_world = pub(Vector3Stamped, 'angular_momentum')
        self._pub_l_body = pub(Vector3Stamped, 'angular_momentum_body')
        self._pub_torque = pub(WrenchStamped, 'applied_torque')
        self._pub_imu = pub(Imu, 'imu') if self.get_parameter('publish_imu').value else None
        self._pub_inertia = pub(InertiaStamped, 'inertia', LATCHED_QOS)
        self._pub_clock = self.create_publisher(ClockMsg, '/clock', CLOCK_QOS) \
            if self._publish_clock else None
        self._pub_diag = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self._pub_rtf = self.create_publisher(Float64, '~/real_time_factor', 10)
        self.create_subscription(WrenchStamped, 'torque_cmd', self._on_torque, STATE_QOS,
                                 qos_overriding_options=qos_opts)
        self.create_service(Trigger, '~/reset', self._on_reset)
        self.create_service(SetBool, '~/pause', self._on_pause)
        if diagnostics_timer:   # else someone calls publish_diagnostics (attitude_fleet)
            steady = Clock(clock_type=ClockType.STEADY_TIME)
            self.create_timer(DIAGNOSTIC_PERIOD, self.publish_diagnostics, clock=steady)

    # ------------------------------------------------------------------ state
    def _reset_state(self):
        q0, w0 = self._initial
        body = self._inertia
        self._stepper = make_integrator(self._integrator_name, body.moments, self._dt,
                                        body.attitude_to_principal(np.array(q0)),
                                        body.to_principal(np.array(w0)))
        self._steps = 0
        self._paused = False
        self._command = None
        self._timed_out = False
        self._last_torque = _ZERO
        self._missed = 0
        self._max_late = 0
        self._stats = (time.monotonic_ns(), 0)
        self._baseline()
        self._anchor()
        self.publish_state(self._snapshot())

    def _baseline(self):
        """Remember T and L_w now: drift is reported since the last torque or change."""
        self._base = self._invariants()

    def _invariants(self):
        s = self._stepper
        m = s.angular_momentum_body
        return s.kinetic_energy, quaternions.rotate_components(s.q, m)

    def _anchor(self):
        """Restart the pacing: the next step is due one period from now."""
        self._anchor_ns = time.monotonic_ns()
        self._anchor_steps = self._steps

    def _body_state(self):
        """(q, omega) of the user's body frame as arrays."""
        s = self._stepper
        body = self._inertia
        return body.attitude_to_body(np.array(s.q)), body.to_body(np.array(s.omega))

    # ------------------------------------------------------------------ torque
    def _make_command(self, vector, world, received_ns):
        principal = None if world else tuple(
            float(c) for c in self._inertia.to_principal(np.array(vector)))
        return TorqueCommand(vector, world, received_ns, principal)

    def _on_torque(self, msg):
        warn = self._warnings.warn
        frame = msg.header.frame_id
        if not conv.is_finite_vector(msg.wrench.torque):
            with self._lock:
                self._counts['rejected_non_finite'] += 1
            warn('non-finite', 'torque_cmd rejected: non-finite torque; state unchanged')
            return
        world_frame, body_frame = self._frames
        if frame not in ('', body_frame, world_frame):
            with self._lock:
                self._counts['rejected_frame'] += 1
            shown = frame if len(frame) <= 64 else frame[:64] + '...'
            warn('frame', f'torque_cmd rejected: unknown frame_id {shown!r}; use '
                 f'{body_frame!r}, {world_frame!r} or "" (= body)')
            return
        vector = conv.vector_array(msg.wrench.torque)
        with self._lock:
            if self._max_torque > 0.0 and np.any(np.abs(vector) > self._max_torque):
                vector = np.clip(vector, -self._max_torque, self._max_torque)
                self._counts['clipped'] += 1
                warn('clipped', f'torque_cmd clipped to max_torque = {self._max_torque:g} N m '
                     'per axis')
            if not conv.is_finite_vector(msg.wrench.force) or any(
                    (msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z)):
                self._counts['force_ignored'] += 1
                warn('force', 'torque_cmd carries a force; only the torque is used (the body '
                     'does not translate)', period=math.inf)
            self._counts['accepted'] += 1
            self._command = self._make_command(tuple(float(c) for c in vector),
                                               frame == world_frame and frame != body_frame,
                                               time.monotonic_ns())

    def _torque_now(self, now_ns):
        """
        Torque for the next step: (principal-frame part, world-frame part or None).

        A world-frame command stays fixed in the world over the step (the
        integrator rotates it into the body as the body turns).
        """
        cmd = self._command
        if cmd is None:
            return _ZERO, None
        if self._timeout_ns and now_ns - cmd.received_ns > self._timeout_ns:
            if not self._timed_out:
                self._timed_out = True
                self.get_logger().info('torque command timed out: torque is zero until the '
                                       'next command')
            return _ZERO, None
        self._timed_out = False
        if cmd.world:
            return _ZERO, cmd.vector
        return cmd.principal, None

    # ------------------------------------------------------------------ stepping
    def start(self):
        """Start the integration thread (and shorten the GIL switch interval, process-wide)."""
        sys.setswitchinterval(SWITCH_INTERVAL)
        self._thread = threading.Thread(target=integration_loop, name='integration',
                                        args=(self._cycle, self._stop, self), daemon=True)
        self._thread.start()

    def stop(self):
        """Stop the integration thread and wait for it."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)

    def _cycle(self):
        """Integrate and publish the steps that are due, then sleep until the next is due."""
        wait = self.step_due()
        if wait > 0.0:
            self._stop.wait(wait)

    def step_due(self, outbox=None):
        """
        Integrate the steps that are due now (a batch, as fast as possible) and publish.

        Returns the wall time (s) until the next step is due. Called by this
        node's integration thread, or by one thread that steps many bodies
        (attitude_fleet) instead of ``start()``; given a list ``outbox``, the
        snapshots of the publish ticks go there (for ``publish_state``)
        instead of being published at once.
        """
        publish_now = outbox is None
        outbox = [] if publish_now else outbox
        with self._lock:
            if self._paused:
                wait = 0.05
            elif self._rtf == 0.0:
                end = time.perf_counter() + AFAP_BATCH
                while time.perf_counter() < end:
                    self._advance(time.monotonic_ns(), outbox)
                wait = AFAP_YIELD
            else:
                now = time.monotonic_ns()
                period = self._dt_ns / self._rtf
                due = self._anchor_steps + int((now - self._anchor_ns) / period)
                behind = due - self._steps
                if behind > 0:
                    # lateness of the oldest due step
                    late = now - (self._anchor_ns
                                  + (self._steps + 1 - self._anchor_steps) * period)
                    self._max_late = max(self._max_late, late)
                    if late > LATE_LIMIT * _NS:
                        self._missed += 1
                    if behind * period > MAX_LAG * _NS:
                        self._warnings.warn(
                            'backlog', f'cannot keep up with real_time_factor {self._rtf:g}: '
                            f'dropped a backlog of {behind} steps', period=5.0)
                        self._anchor()
                        behind = 1
                    for _ in range(behind):
                        self._advance(now, outbox)
                next_due = self._anchor_ns + (self._steps + 1 - self._anchor_steps) * period
                wait = max(0.0, (next_due - time.monotonic_ns()) / _NS)
        # publish outside the lock: a torque command never waits for publishing
        if publish_now:
            for snapshot in outbox:
                self.publish_state(snapshot)
        return wait

    def _advance(self, now_ns, outbox):
        """One integration step; on a publish tick its state goes into ``outbox``."""
        torque, torque_world = self._torque_now(now_ns)
        self._stepper.step(torque, torque_world)
        self._steps += 1
        if torque_world is not None:
            q = self._stepper.q
            torque = quaternions.rotate_components((-q[0], -q[1], -q[2], q[3]), torque_world)
        if torque[0] or torque[1] or torque[2]:
            self._baseline()
        self._last_torque = torque
        if self._steps % self._publish_every == 0:
            outbox.append(self._snapshot())

    # ------------------------------------------------------------------ publishing
    def _snapshot(self):
        """Take what one publish tick needs (under the lock)."""
        s = self._stepper
        return (self._steps, s.q, s.omega, self._last_torque, self._inertia)

    def publish_state(self, snapshot):
        """Publish the state topics of one publish tick (a snapshot taken under the lock)."""
        steps, q_p, w_p, torque, inertia = snapshot
        stamp = conv.time_msg(self._start_ns + int(steps * self._dt_ns))
        world, body_frame = self._frames
        q_b = inertia.attitude_to_body(np.array(q_p))
        w_b = inertia.to_body(np.array(w_p))
        m_p = tuple(i * w for i, w in zip(inertia.moments, w_p))
        l_world = quaternions.rotate_components(q_p, m_p)
        l_body = inertia.to_body(np.array(m_p))
        tau_b = inertia.to_body(np.array(torque))
        q_msg = conv.quaternion_msg(q_b)
        w_msg = conv.vector_msg(w_b)

        odom = Odometry()
        odom.header.stamp, odom.header.frame_id, odom.child_frame_id = stamp, world, body_frame
        odom.pose.pose.orientation = q_msg
        odom.twist.twist.angular = w_msg
        self._pub_odom.publish(odom)
        msg = QuaternionStamped(quaternion=q_msg)
        msg.header.stamp, msg.header.frame_id = stamp, world
        self._pub_orientation.publish(msg)
        for pub, vec, frame in ((self._pub_omega, w_b, body_frame),
                                (self._pub_l_world, l_world, world),
                                (self._pub_l_body, l_body, body_frame)):
            msg = Vector3Stamped(vector=conv.vector_msg(vec))
            msg.header.stamp, msg.header.frame_id = stamp, frame
            pub.publish(msg)
        wrench = WrenchStamped()
        wrench.header.stamp, wrench.header.frame_id = stamp, body_frame
        wrench.wrench.torque = conv.vector_msg(tau_b)
        self._pub_torque.publish(wrench)
        if self._pub_imu is not None:
            imu = Imu(orientation=q_msg, angular_velocity=w_msg)
            imu.header.stamp, imu.header.frame_id = stamp, body_frame
            imu.linear_acceleration_covariance[0] = -1.0
            self._pub_imu.publish(imu)
        if self._pub_clock is not None:
            self._pub_clock.publish(ClockMsg(clock=stamp))

    def _publish_inertia(self):
        msg = InertiaStamped()
        msg.header.stamp = conv.time_msg(getattr(self, '_start_ns', 0))
        msg.header.frame_id = self._frames[1]
        t = self._inertia.tensor
        msg.inertia.m = 0.0   # the mass is not modelled: only rotation is simulated
        msg.inertia.ixx, msg.inertia.ixy, msg.inertia.ixz = t[0, 0], t[0, 1], t[0, 2]
        msg.inertia.iyy, msg.inertia.iyz, msg.inertia.izz = t[1, 1], t[1, 2], t[2, 2]
        self._pub_inertia.publish(msg)

    def publish_diagnostics(self):
        """Publish /diagnostics and ~/real_time_factor (every DIAGNOSTIC_PERIOD s)."""
        name = self.get_name()
        hw = self.get_fully_qualified_name()
        with self._lock:
            now = time.monotonic_ns()
            then, steps_then = self._stats
            self._stats = (now, self._steps)
            achieved = (self._steps - steps_then) * self._dt_ns / max(now - then, 1)
            s = self._stepper
            t0, l0 = self._base
            t1, l1 = self._invariants()
            qnorm = abs(math.sqrt(sum(c * c for c in s.q)) - 1.0)
            g0 = math.sqrt(sum(c * c for c in l0))
            g1 = math.sqrt(sum(c * c for c in l1))
            direction = math.atan2(float(np.linalg.norm(np.cross(l0, l1))), float(np.dot(l0, l1)))
            cmd = self._command
            counts = dict(self._counts)
            paused, missed, timed_out = self._paused, self._missed, self._timed_out
            max_late, self._max_late = self._max_late / 1e6, 0
            steps, sim_time = self._steps, self._steps * self._dt
        if paused:
            level, message = DiagnosticStatus.OK, 'paused'
        elif self._rtf and achieved < 0.9 * self._rtf:
            level, message = DiagnosticStatus.WARN, (
                f'running at {achieved:.3g}x real time, {self._rtf:g}x requested')
        else:
            level, message = DiagnosticStatus.OK, 'running'
        integrator = conv.status(f'{name}: integrator', level, message, [
            ('integrator', self._integrator_name), ('dt (s)', self._dt), ('steps', steps),
            ('simulated time (s)', sim_time), ('requested real-time factor', self._rtf),
            ('achieved real-time factor', achieved),
            (f'missed deadlines (> {LATE_LIMIT * 1e3:g} ms late)', missed),
            ('latest step lateness in the last period (ms)', max_late),
            ('quaternion norm error', qnorm),
            ('energy drift since last torque (rel.)', abs(t1 - t0) / t0 if t0 else 0.0),
            ('|L| drift since last torque (rel.)', abs(g1 - g0) / g0 if g0 else 0.0),
            ('L direction drift since last torque (rad)', direction),
            ('work since reset (J)', s.work),
        ], hw)
        age = (now - cmd.received_ns) / _NS if cmd is not None else math.inf
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
            ('timeout (s)', self._timeout_ns / _NS)] + list(counts.items()), hw)
        array = DiagnosticArray(status=[integrator, torque])
        array.header.stamp = self.get_clock().now().to_msg()
        self._pub_diag.publish(array)
        self._pub_rtf.publish(Float64(data=achieved))

    # ------------------------------------------------------------------ services
    def _on_reset(self, _request, response):
        with self._lock:
            self._reset_state()
        self.get_logger().info('reset to the initial state, simulated time 0')
        response.success = True
        response.message = 'reset to the initial state; simulated time restarts at 0'
        return response

    def _on_pause(self, request, response):
        with self._lock:
            was = self._paused
            self._paused = bool(request.data)
            if was and not self._paused:
                self._anchor()
        state = 'paused' if self._paused else 'running'
        self.get_logger().info(f'simulation {state} at t = {self._steps * self._dt:.6g} s')
        response.success = True
        response.message = state
        return response


def main(args=None, early=None):
    """Run until Ctrl-C / SIGTERM; exit 0, or 1 on bad configuration (see runner.run)."""
    return run(AttitudeSimulator, NODE_NAME, args, early=early,
               on_start=lambda node: node.start(), on_stop=lambda node: node.stop())


if __name__ == '__main__':
    sys.exit(main())
