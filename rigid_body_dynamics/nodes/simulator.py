"""
attitude_simulator: integrates Euler's equations and publishes the attitude state.

Topics, frames and parameters are listed in the manual's node page (made from
:mod:`.interfaces` and ``PARAMETERS`` in :mod:`.simulator_parameters`).
The node is thin: it keeps the parameters, the torque subscription, the
services and the diagnostics; the body is an engine
:class:`~rigid_body_dynamics.engine.body.BodySimulation` (ROS-free), paced by
an engine :class:`~rigid_body_dynamics.engine.pacer.Pace`, and its state
messages come from a :class:`~.state_publisher.StatePublisher`.

Threads. Integration and state publishing run on one steady-clock thread,
woken at the body's ticks (a step that publishes, and at least every
COMMAND_LOOK = 20 ms): it takes the torque commands that came, with their
receive times, and integrates the due steps, each with the command newest at
its deadline (see
:class:`~rigid_body_dynamics.engine.pacer.Pace`). Services, parameter changes
and diagnostics run on the executor; both sides share the body under its
lock.

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

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Vector3Stamped, WrenchStamped
import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64, Float64MultiArray
from std_srvs.srv import SetBool, Trigger

from .simulator_diagnostics import SimulatorReport
from .simulator_parameters import body_from, PARAMETERS, state_topics
from ..engine import Lockstep, Loop, Member, Pace
from ..physics import presets
from ..ros import simulator_interface
from ..ros.command_decoder import decode_dipoles, decode_wheels, steady_times, TorqueDecoder
from ..ros.intake import Intake
from ..ros.runner import run
from ..ros.state_publisher import StatePublisher, tf_available
from ..ros.throttle import ThrottledWarnings

NODE_NAME = 'attitude_simulator'
#: torque_cmd: reliable, depth 1000, so that every command between two wakes of the body
#: (at most COMMAND_LOOK = 20 ms apart: 200 at 10 kHz) is counted whole, with room for a
#: stall; the state uses the newest command at each step's deadline.
TORQUE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                        reliability=ReliabilityPolicy.RELIABLE)
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


def integration_loop(loop, stop, priority, logger, context):
    """
    Run the engine ``loop`` until the event ``stop`` is set: the body of an integration thread.

    Applies the SCHED_FIFO ``priority`` first (0: none). An error after
    shutdown began (a publisher closed under the loop) ends it quietly; any
    other is logged on ``logger`` and raised.
    """
    use_thread_priority(priority, logger)
    try:
        loop.run(stop)
    except Exception as err:
        if rclpy.ok(context=context) and not stop.is_set():
            logger.error(f'integration thread stopped: {err!r}')
            raise


class AttitudeSimulator(Node):
    """
    The attitude_simulator node. ``kwargs`` go to rclpy's Node (context, overrides).

    :meth:`start` starts its integration thread (an engine Loop of this one
    body) and diagnostics timer. A host of many bodies (attitude_fleet) puts
    every body's :meth:`member` on one Loop instead.
    """

    def __init__(self, frame_prefix_default='', simulation_interfaces_default=True,
                 defer_first_state=False, **kwargs):
        # the defaults attitude_fleet changes: frame_prefix (each body's name) and
        # simulation_interfaces (off: their endpoints cost a large fleet its start and exit)
        self.frame_prefix_default = frame_prefix_default
        self.simulation_interfaces_default = simulation_interfaces_default
        super().__init__(NODE_NAME, **kwargs)
        self._stop = threading.Event()
        self._thread = None
        values = PARAMETERS.validate(PARAMETERS.declare(self))
        self._preset = presets.get(values['preset'])
        prefix = values['frame_prefix']
        self._frames = (prefix + values['world_frame'], prefix + values['body_frame'])
        self._publish_clock = values['publish_clock']
        self.thread_priority = values['thread_priority']
        self._rate = rate = values['integration_rate']
        self._warnings = ThrottledWarnings(self.get_logger())
        start_ns = 0 if self._publish_clock else self.get_clock().now().nanoseconds
        self.lockstep = values['lockstep']
        self.body = body_from(values, self._publish_every(values['publish_rate']), start_ns)
        self._lvlh_frame = prefix + values['lvlh_frame']
        self._publish_rate = values['publish_rate']
        self._decoder = TorqueDecoder(self._frames)
        self._refused_frame = ''
        if self.lockstep:
            self.pace = Lockstep(self.body, values['control_every'], values['lockstep_timeout'],
                                 inbox=self._inbox,
                                 wait=lambda timeout: self._intake.wait(self._commands, timeout),
                                 answer=values['answer'])
        else:
            self.pace = Pace(self.body, values['real_time_factor'], on_backlog=self._on_backlog,
                             inbox=self._inbox)
        self._report = SimulatorReport(self.body, self.pace, self.lockstep)
        self._make_interfaces()
        self.state.publish_inertia(self.body.inertia, start_ns)
        if not defer_first_state:
            self.publish_first_state()
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
        env = values['disturbances']
        if env.active:
            self.get_logger().info(f'disturbances: {env}')
        if env.orbit is not None:
            self.get_logger().info(
                f'orbit: {env.orbit.summary()}; magnetic field: '
                f'{values["magnetic_field_model"]}'
                + ('; magnetorquers on magnetorquer_cmd' if self.body.max_dipole else ''))
        if self.body.wheels is not None:
            w = self.body.wheels
            self.get_logger().info(
                f'{w.count} reaction wheels: axes {[list(g) for g in w.axes]}, J '
                f'{list(w.inertia)} kg m^2, speeds {list(self.body.wheel_speeds0)} rad/s; motor '
                'torques on wheel_cmd')

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
            self, self._frames, publish_clock=self._publish_clock, publish_tf=publish_tf,
            topics=state_topics(self.get_parameter('state_topics').value),
            wheels=self.body.wheels.count if self.body.wheels is not None else 0,
            orbit=self.body.disturbances.orbit is not None, lvlh_frame=self._lvlh_frame,
            magnetorquers=self.body.max_dipole is not None,
            sensors=[sensor.name for _, sensor in self.body.sensors])
        if publish_tf and not tf_available():
            self.get_logger().info('publish_tf: tf2_msgs is not importable here (no tf2_msgs '
                                   'wheel exists; on a ROS install it is), so /tf is not '
                                   'broadcast; odom carries the same pose')
        self._pub_diag = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self._pub_rtf = self.create_publisher(Float64, '~/real_time_factor', 10)
        # the integration thread takes its commands itself: no executor hop, no callback each
        self._intake = Intake(self)
        # the command topics and their decoders (raws, steady receive times) -> command value
        self._decoders = {'torque_cmd': self._decode_torques}
        self._intake.subscribe(WrenchStamped, 'torque_cmd', TORQUE_QOS, overridable=True)
        if self.body.wheels is not None:
            self._intake.subscribe(Float64MultiArray, 'wheel_cmd', TORQUE_QOS, overridable=True)
            self._decoders['wheel_cmd'] = decode_wheels
        if self.body.max_dipole is not None:
            self._intake.subscribe(Vector3Stamped, 'magnetorquer_cmd', TORQUE_QOS,
                                   overridable=True)
            self._decoders['magnetorquer_cmd'] = self._decode_dipoles
        self._commands = tuple(self._decoders)
        self.create_service(Trigger, '~/reset', self._on_reset)
        self.create_service(SetBool, '~/pause', self._on_pause)
        self.simulator_interface = None
        if not self.get_parameter('simulation_interfaces').value:
            pass
        elif simulator_interface.available():
            self.simulator_interface = simulator_interface.SimulatorInterface(
                self, self.body, self.pace, self.state.publish, self._frames, self.get_logger())
        else:
            simulator_interface.say_unavailable(self.get_logger())

    # ------------------------------------------------------------------ torque
    def _inbox(self):
        """
        Return the command messages pending, decoded into command values (the pace's inbox).

        Called by the integration thread at every wake (under the body's lock);
        one value per command topic with messages; everything after decoding is
        the engine's (:meth:`BodySimulation.check`, :meth:`BodySimulation.hold`).
        """
        out = []
        for topic, decode in self._decoders.items():
            received = []
            raws = self._intake.take(topic, received=received)
            if raws:
                out.append(decode(raws, steady_times(received)))
        return out

    def _decode_torques(self, raws, received_ns):
        """Decode torque_cmd messages; those in an unknown frame are counted here."""
        commands, refused = self._decoder.decode(raws, received_ns)
        for frame, count in refused.items():
            self._refused_frame = frame
            self.body.reject('rejected_frame', count)
        return commands

    def _decode_dipoles(self, raws, received_ns):
        """Decode magnetorquer_cmd messages; those in a frame other than the body's are counted."""
        commands, refused = decode_dipoles(raws, received_ns, self._decoder.body_frame)
        if refused:
            self.body.reject('rejected_frame', refused, 'dipole')
        return commands

    def _warn_events(self, events):
        """Warn (throttled) about the command events the body reported."""
        warn = self._warnings.warn
        if 'rejected_non_finite' in events:
            warn('non-finite', 'torque_cmd rejected: non-finite torque; state unchanged')
        if 'rejected_frame' in events:
            frame = self._refused_frame
            shown = frame if len(frame) <= 64 else frame[:64] + '...'
            warn('frame', f'torque_cmd rejected: unknown frame_id {shown!r}; use '
                 f'{self._decoder.body_frame!r}, {self._decoder.world_frame!r} or "" (= body)')
        if 'clipped' in events:
            warn('clipped', f'torque_cmd clipped to max_torque = {self.body.max_torque:g} N m '
                 'per axis')
        if 'force_ignored' in events:
            warn('force', 'torque_cmd carries a force; only the torque is used (the body '
                 'does not translate)', period=math.inf)
        if 'wheel_rejected' in events:
            warn('wheel', f'wheel_cmd rejected: it needs {self.body.wheels.count} finite motor '
                 'torques (N m, one per wheel); state unchanged')
        if 'dipole_rejected_non_finite' in events:
            warn('dipole', 'magnetorquer_cmd rejected: non-finite dipole; state unchanged')
        if 'dipole_rejected_frame' in events:
            warn('dipole_frame', 'magnetorquer_cmd rejected: its frame_id must be '
                 f'{self._decoder.body_frame!r} or "" (the rods are fixed in the body)')
        if 'dipole_clipped' in events:
            warn('dipole_clipped', 'magnetorquer_cmd clipped to magnetorquer_max_dipole = '
                 f'{list(self.body.max_dipole)} A m^2 per body axis')
        if 'stale' in events or 'dipole_stale' in events:
            warn('stale', 'lockstep: torque_cmd stamped before the current tick dropped '
                 '(an answer that came after its tick was missed)')

    def destroy_node(self):
        """Destroy the torque intake's helper node too."""
        if getattr(self, '_intake', None) is not None:
            self._intake.destroy()
            self._intake = None
        if getattr(self, 'simulator_interface', None) is not None:
            self.simulator_interface.destroy()
            self.simulator_interface = None
        super().destroy_node()

    # ------------------------------------------------------------------ stepping
    def start(self):
        """
        Start the integration thread and the 1 Hz diagnostics timer (steady clock).

        Also shortens the GIL switch interval, process-wide.
        """
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(DIAGNOSTIC_PERIOD, self.publish_diagnostics, clock=steady)
        sys.setswitchinterval(SWITCH_INTERVAL)
        self._thread = threading.Thread(
            target=integration_loop, name='integration', daemon=True,
            args=(Loop([self.member()]), self._stop, self.thread_priority, self.get_logger(),
                  self.context))
        self._thread.start()

    def publish_first_state(self):
        """
        Publish the state at simulated time 0 (odom, /tf, ...; lockstep's first question).

        The node does so when it is made, unless told to defer it (``defer_first_state``:
        attitude_fleet first decides which bodies broadcast /tf).
        """
        with self.body.lock:
            items = self.pace.first_items()
        for item in items:
            self.state.publish(item)

    @property
    def publishes_clock(self):
        """Whether this body publishes /clock (``publish_clock``)."""
        return self._publish_clock

    def member(self, diagnostics=False):
        """Return this body as a member of an engine Loop (diagnostics: the Loop sends them)."""
        return Member(self.pace, self.state.publish, self.log_notes,
                      self.publish_diagnostics if diagnostics else None)

    def stop(self):
        """Stop the integration thread and wait for it."""
        self._stop.set()                  # (a lockstep wait ends within WAIT_SLICE)
        if self._thread is not None:
            self._thread.join(timeout=5.0)

    def log_notes(self):
        """Log what the body noted while stepping (timeouts, misses) and warn of command events."""
        body = self.body                  # (read without the lock: a container's truth is atomic)
        if body.events:
            self._warn_events(body.take_events())
        if body.notes:
            for note in body.take_notes():
                self.get_logger().info(note)

    def _on_backlog(self, behind):
        self._warnings.warn('backlog', f'cannot keep up with real_time_factor {self.pace.rtf:g}: '
                            f'dropped a backlog of {behind} steps', period=5.0)

    # ------------------------------------------------------------------ diagnostics
    def publish_diagnostics(self):
        """Publish /diagnostics and ~/real_time_factor (every DIAGNOSTIC_PERIOD s)."""
        report = self._report
        array = DiagnosticArray(status=report.statuses(self.get_name(),
                                                       self.get_fully_qualified_name()))
        array.header.stamp = self.get_clock().now().to_msg()
        self._pub_diag.publish(array)
        self._pub_rtf.publish(Float64(data=report.achieved))

    # ------------------------------------------------------------------ services
    def _on_reset(self, _request, response):
        with self.body.lock:
            self.body.reset()
            self.pace.restart()
            items = self.pace.first_items()
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
    from .entry import exiting
    sys.exit(exiting(main()))
