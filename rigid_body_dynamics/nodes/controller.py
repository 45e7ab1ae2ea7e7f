"""
attitude_controller: an example attitude controller for attitude_simulator.

It answers states, not a wall-clock timer: each ``odom`` message whose stamp
is at least one control period after the last answered one gets a
``torque_cmd`` stamped with that state's stamp (what lockstep needs, and
what a real controller should do anyway: the command says which state it
answers). With the simulator in lockstep the closed loop is then
deterministic; in real time it runs at ``control_rate`` of the state stream.
A state (or magnetometer reading) seen again, stamp and values, gets the same
answer again: lockstep sends its first tick again until it is answered, and an
answer lost to discovery must not stall the run.

The law lives in the physics layer (:mod:`rigid_body_dynamics.physics.control`,
ROS-free, so ``simulate(...)`` closes the same loop offline): ``slew`` is a
quaternion-feedback PD to ``target_orientation`` (shortest way, per-axis
gains 2 I_i wn^2 and 2 zeta wn I_i from the latched ``inertia``, vector
saturation at ``max_torque``); ``detumble`` damps the rate only. A
``target_orientation`` message (geometry_msgs/QuaternionStamped) overrides
the parameter. No command goes out before the inertia is known.

``actuator: wheels`` flies the same torque with reaction wheels (the ``wheel_*``
parameters as the simulator's): :class:`~rigid_body_dynamics.physics.control.WheelAllocator`
turns it into motor torques on ``wheel_cmd`` from the wheel speeds of the same
stamp (``wheel_state``), and ``torque_cmd`` (stamped, published first at every
answer) carries the momentum dump, zero unless a wheel is near its speed limit.
With the simulator in lockstep set its ``lockstep_answer`` to ``both``.

``mode: bdot`` (``actuator: magnetorquers``) detumbles with magnetorquers: each
``magnetic_field`` reading (the simulator's magnetometer, or any) is answered with
a ``magnetorquer_cmd`` stamped with the reading's stamp, m = -k dB/dt
(:class:`~rigid_body_dynamics.physics.control.BDot`), within
``magnetorquer_max_dipole``; it needs no inertia and no odom.

States are taken by a thread of their own from a wait set (ros/intake.py),
not by executor callbacks: one DDS hop less of Python overhead per period.
"""

import math
import sys
import threading

from geometry_msgs.msg import InertiaStamped, QuaternionStamped, Vector3Stamped, WrenchStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState, MagneticField
from std_msgs.msg import Float64MultiArray

from .environment_parameters import environment_params
from .wheel_parameters import wheel_params, wheels_from
from ..physics.control import BDot, QuaternionPD, RateDamper, WheelAllocator
from ..ros import conversions as conv
from ..ros.intake import Intake
from ..ros.parameters import as_vector, ConfigurationError, Param, ParameterTable
from ..ros.runner import run
from ..ros.state_publisher import LATCHED_QOS, STATE_QOS
from ..ros.throttle import ThrottledWarnings

NODE_NAME = 'attitude_controller'
#: Longest wait (s) for the wheel_state of an odom's stamp (both come from one tick).
WHEEL_STATE_WAIT = 1.0


def _target(value):
    q = as_vector('target_orientation', value, 4)
    norm = math.sqrt(sum(c * c for c in q))
    if not norm > 1e-9:
        raise ConfigurationError('target_orientation must not be the zero quaternion')
    return tuple(c / norm for c in q)


def _actuator(values, out):
    """Cross-check: bdot and the magnetorquers go together."""
    if (out['mode'] == 'bdot') != (out['actuator'] == 'magnetorquers'):
        raise ConfigurationError('mode bdot and actuator magnetorquers go together (B-dot '
                                 f'flies magnetorquers), got mode {out["mode"]} with actuator '
                                 f'{out["actuator"]}')


def _allocator(values, out):
    """Cross-check: with actuator wheels, a WheelAllocator of valid wheels (out['allocator'])."""
    out['allocator'] = None
    if out['actuator'] != 'wheels':
        return
    wheels = wheels_from(out)
    if wheels is None:
        raise ConfigurationError('actuator wheels needs the wheels: set wheel_axes and '
                                 'wheel_inertia')
    try:
        out['allocator'] = WheelAllocator(wheels, out['dump_fraction'], out['dump_gain'])
    except ValueError as err:
        raise ConfigurationError(f'actuator wheels: {err}') from None


#: The parameters of attitude_controller (the manual's table is made from this; test_docs checks).
def law_from(values, moments):
    """
    Return the law of validated ``values``: QuaternionPD (slew), RateDamper or BDot.

    ``moments``: the body axes' moments (kg m^2; the inertia tensor's diagonal, as
    the inertia topic gives it); not used by bdot.
    """
    v = values
    if v['mode'] == 'bdot':
        return BDot(v['bdot_gain'], v['magnetorquer_max_dipole'])
    if v['mode'] == 'detumble':
        return RateDamper(moments, v['natural_frequency'], v['damping_ratio'], v['max_torque'])
    return QuaternionPD(moments, v['target_orientation'], v['natural_frequency'],
                        v['damping_ratio'], v['max_torque'])


PARAMETERS = ParameterTable([
    Param('mode', 'string', 'slew', '`slew`',
          'slew: quaternion PD to target_orientation; detumble: rate damping only; bdot: '
          'B-dot detumbling with magnetorquers from magnetic_field (actuator magnetorquers).',
          choices=('bdot', 'detumble', 'slew')),
    Param('target_orientation', 'double[4]', [0.0, 0.0, 0.0, 1.0], '[0, 0, 0, 1]',
          'Target attitude (x, y, z, w), body -> world; normalised. A message on '
          'target_orientation overrides it.', convert=_target),
    Param('natural_frequency', 'double', 1.0, '1.0 rad/s',
          'Closed-loop natural frequency wn of each axis (small angles).', low=1e-6, high=1e4),
    Param('damping_ratio', 'double', 0.7, '0.7', 'Closed-loop damping ratio zeta.',
          low=1e-6, high=1e3),
    Param('max_torque', 'double', 0.0, '0.0 N m',
          'Vector saturation: |tau| is scaled down to this (direction kept); 0 = none.',
          low=0.0, high=1e30),
    Param('control_rate', 'double', 100.0, '100.0 Hz',
          'Commands per simulated second: a state is answered when its stamp is at least '
          '1 / control_rate after the last answered one; 0 = answer every state.',
          low=0.0, high=1e6),
    Param('actuator', 'string', 'torque', '`torque`',
          "torque: the law's torque on torque_cmd; wheels: flown by the reaction wheels "
          '(wheel_cmd), torque_cmd carrying only the momentum dump; magnetorquers: the '
          'dipole of mode bdot on magnetorquer_cmd.',
          choices=('magnetorquers', 'torque', 'wheels'), read_only=True),
    *wheel_params('wheel_axes', 'wheel_inertia', 'wheel_max_torque', 'wheel_max_speed'),
    Param('dump_fraction', 'double', 0.8, '0.8',
          'Momentum dumping starts when a wheel passes this fraction of its speed limit and '
          'stops when all are under half of it.', low=0.0, high=1.0, above_low=True,
          read_only=True),
    Param('dump_gain', 'double', 0.5, '0.5 1/s',
          "Dump torque -dump_gain h_w on torque_cmd (h_w the wheels' momentum, body frame).",
          low=0.0, high=1e6, read_only=True),
    Param('bdot_gain', 'double', 1e5, '1e5 A m^2 s/T',
          'B-dot gain k: m = -k dB/dt (mode bdot).', low=0.0, high=1e15, above_low=True),
    *environment_params('magnetorquer_max_dipole'),
], cross_checks=(_actuator, _allocator))


class AttitudeController(Node):
    """The attitude_controller node; ``kwargs`` go to rclpy's Node."""

    def __init__(self, **kwargs):
        super().__init__(NODE_NAME, **kwargs)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None
        self._values = PARAMETERS.validate(PARAMETERS.declare(self))
        self._moments = None
        self._law = None
        self._next_due_ns = None
        self._last_ns = None
        self.answered = 0
        self.repeated = 0                          # answers sent again (see _repeat)
        # (what it answered: stamp and values, [(publisher, message), ...]) of the last answer
        self._answer = None
        self.dropped = 0                           # inputs with a non-finite number
        self._warnings = ThrottledWarnings(self.get_logger())
        self._bdot = self._values['mode'] == 'bdot'
        if self._bdot:
            self._pub_dipole = self.create_publisher(Vector3Stamped, 'magnetorquer_cmd',
                                                     STATE_QOS)
        self._pub = self.create_publisher(WrenchStamped, 'torque_cmd', STATE_QOS)
        self._allocator = self._values['allocator']
        self._wheel_states = {}                # stamp (ns) -> wheel speeds, recent ones
        if self._allocator is not None:
            self._pub_wheels = self.create_publisher(Float64MultiArray, 'wheel_cmd', STATE_QOS)
        self.create_subscription(InertiaStamped, 'inertia', self._on_inertia, LATCHED_QOS)
        self.create_subscription(QuaternionStamped, 'target_orientation', self._on_target,
                                 STATE_QOS)
        self._intake = Intake(self)
        # reliable by default (lockstep answers every state); a best-effort odometry source
        # needs qos_overrides./odom.subscription.reliability: best_effort
        self._intake.subscribe(Odometry, 'odom', STATE_QOS, overridable=True)
        if self._bdot:
            self._intake.subscribe(MagneticField, 'magnetic_field', STATE_QOS)
        if self._allocator is not None:
            self._intake.subscribe(JointState, 'wheel_state', STATE_QOS)
        self.add_on_set_parameters_callback(lambda params: PARAMETERS.on_set(self, params))
        self.add_post_set_parameters_callback(self._on_parameters)
        v = self._values
        if self._bdot:
            self._rebuild()
            self.get_logger().info(
                f'bdot: k = {v["bdot_gain"]:g} A m^2 s/T, dipole limits '
                f'{list(v["magnetorquer_max_dipole"])} A m^2, answering magnetic_field')
            return
        self.get_logger().info(
            f'{v["mode"]}: wn = {v["natural_frequency"]:g} rad/s, zeta = '
            f'{v["damping_ratio"]:g}, max_torque = {v["max_torque"]:g} N m, '
            f'{v["control_rate"]:g} Hz of state stamps; waiting for the inertia')

    # ------------------------------------------------------------------ law
    def _rebuild(self):
        """Make the law from the values and the inertia (call under the lock)."""
        v = self._values
        self._law = None if self._moments is None and v['mode'] != 'bdot' else \
            law_from(v, self._moments)

    def _on_inertia(self, msg):
        if self._bdot:          # B-dot needs no inertia; a new law would forget its last reading
            return
        i = msg.inertia
        moments = (i.ixx, i.iyy, i.izz)      # the body axes' moments (the diagonal)
        if not all(m > 0.0 and math.isfinite(m) for m in moments):
            self.get_logger().warning(f'inertia ignored: diagonal {moments} is not positive')
            return
        with self._lock:
            first = self._moments is None
            self._moments = moments
            self._rebuild()
        if first:
            self.get_logger().info(f'inertia diagonal {list(moments)} kg m^2: controlling')

    def _on_target(self, msg):
        try:
            target = _target(conv.quaternion_array(msg.quaternion))
        except ConfigurationError as err:
            self.get_logger().warning(f'target_orientation ignored: {err}')
            return
        with self._lock:
            self._values = dict(self._values, target_orientation=target)
            self._rebuild()
        self.get_logger().info(f'target orientation now {list(target)}')

    def _on_parameters(self, params):
        with self._lock:
            self._values = PARAMETERS.validate(PARAMETERS.values(self))
            self._rebuild()

    # ------------------------------------------------------------------ loop
    def start(self):
        """Start the thread that answers states."""
        self._thread = threading.Thread(target=self._loop, name='control', daemon=True)
        self._thread.start()

    def stop(self):
        """Stop the thread and wait for it."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)

    def _loop(self):
        if self._bdot:
            self._bdot_loop()
            return
        while not self._stop.is_set():
            if not self._intake.wait('odom', 0.1):
                continue
            raws = self._intake.take('odom')
            if not raws:
                continue
            odom = deserialize_message(raws[-1], Odometry)
            if self._allocator is None:
                self.answer(odom)
                continue
            speeds = self._speeds_at(conv.time_ns(odom.header.stamp))
            if speeds is None:
                self.get_logger().warning('no wheel_state with the stamp of odom: not answered')
                continue
            self.answer(odom, speeds)

    def _bdot_loop(self):
        while not self._stop.is_set():
            if not self._intake.wait('magnetic_field', 0.1):
                continue
            for raw in self._intake.take('magnetic_field'):
                self.answer_field(deserialize_message(raw, MagneticField))

    def answer_field(self, msg):
        """
        Answer one magnetometer reading with a magnetorquer_cmd of the reading's stamp.

        Every reading goes through the law (its dB/dt needs each); one is answered when
        due at ``control_rate``, as states are.
        """
        b = msg.magnetic_field
        if self._hostile((b.x, b.y, b.z), 'magnetic_field'):
            return
        stamp = conv.time_ns(msg.header.stamp)
        key = (stamp, b.x, b.y, b.z)
        with self._lock:
            if self._repeat(key):
                return
            law = self._law
            if self._last_ns is not None and stamp < self._last_ns:
                self._next_due_ns = None           # the simulator was reset: start over
            self._last_ns = stamp
            dipole = law.dipole(stamp * 1e-9, conv.vector_array(msg.magnetic_field))
            if self._next_due_ns is not None and stamp < self._next_due_ns:
                return
            rate = self._values['control_rate']
            self._next_due_ns = stamp + (round(1e9 / rate) if rate > 0.0 else 1)
        cmd = Vector3Stamped()
        cmd.header.stamp = msg.header.stamp
        cmd.header.frame_id = msg.header.frame_id
        cmd.vector.x, cmd.vector.y, cmd.vector.z = dipole
        self._send(key, [(self._pub_dipole, cmd)])

    def _repeat(self, key):
        """
        Publish the last answer again if ``key`` (stamp, values) is what it answered (locked).

        A simulator in lockstep sends its first state and readings again every second
        until that tick is answered: an answer published before the simulator's
        subscription knew this publisher is lost (a volatile reader gets nothing sent
        before it matched), and a state that was answered once is not due again. The
        same input gets the same answer, without going through the law a second time
        (B-dot's dB/dt keeps the last reading). Returns whether it did.
        """
        if self._answer is None or self._answer[0] != key:
            return False
        for pub, msg in self._answer[1]:
            pub.publish(msg)
        self.repeated += 1
        return True

    def _send(self, key, messages):
        """Publish the answer to ``key``: [(publisher, message), ...] in order; keep it."""
        with self._lock:
            self._answer = (key, messages)
        for pub, msg in messages:
            pub.publish(msg)
        self.answered += 1

    def _speeds_at(self, stamp_ns):
        """Return the wheel speeds stamped ``stamp_ns``, waiting for them a little; or None."""
        waited = 0.0
        while True:
            for raw in self._intake.take('wheel_state'):
                msg = deserialize_message(raw, JointState)
                self._wheel_states[conv.time_ns(msg.header.stamp)] = tuple(msg.velocity)
            if len(self._wheel_states) > 1000:            # keep the recent ones
                for old in sorted(self._wheel_states)[:-100]:
                    del self._wheel_states[old]
            if stamp_ns in self._wheel_states or waited >= WHEEL_STATE_WAIT:
                return self._wheel_states.get(stamp_ns)
            self._intake.wait('wheel_state', 0.05)
            waited += 0.05

    def _hostile(self, numbers, topic, quaternion=None):
        """
        Count and warn of (throttled per kind) an input not to answer; True if it is one.

        One with a non-finite number, or whose ``quaternion`` (4 numbers) is zero.
        """
        if not all(math.isfinite(x) for x in numbers):
            what = 'a non-finite value'
        elif quaternion is not None and not any(quaternion):
            what = 'a zero quaternion'
        else:
            return False
        self.dropped += 1
        self._warnings.warn(f'{topic}: {what}', f'{topic} with {what} dropped ({self.dropped} '
                            'so far); the last command stays in force', 5.0)
        return True

    def answer(self, odom, speeds=None):
        """
        Answer one state if it is due (the newest pending one): publish the command.

        With wheels (``speeds``: their speeds at the state's stamp, rad/s) the dump
        torque on torque_cmd first, then the motor torques on wheel_cmd.
        """
        o, w = odom.pose.pose.orientation, odom.twist.twist.angular
        if self._hostile((o.x, o.y, o.z, o.w, w.x, w.y, w.z), 'odom', (o.x, o.y, o.z, o.w)):
            return
        stamp = conv.time_ns(odom.header.stamp)
        key = (stamp, o.x, o.y, o.z, o.w, w.x, w.y, w.z)
        with self._lock:
            if self._repeat(key):
                return
            law = self._law
            rate = self._values['control_rate']
            if self._last_ns is not None and stamp < self._last_ns:
                self._next_due_ns = None           # the simulator was reset: start over
            self._last_ns = stamp
            if law is None or (self._next_due_ns is not None and stamp < self._next_due_ns):
                return
            self._next_due_ns = stamp + (round(1e9 / rate) if rate > 0.0 else 1)
        tau = law((o.x, o.y, o.z, o.w), (w.x, w.y, w.z))
        motors = None
        if self._allocator is not None:
            motors, tau = self._allocator.allocate(tau, (w.x, w.y, w.z), speeds)
        cmd = WrenchStamped()
        cmd.header.stamp = odom.header.stamp
        cmd.header.frame_id = odom.child_frame_id
        cmd.wrench.torque.x, cmd.wrench.torque.y, cmd.wrench.torque.z = tau
        messages = [(self._pub, cmd)]
        if motors is not None:
            messages.append((self._pub_wheels, Float64MultiArray(data=list(motors))))
        self._send(key, messages)

    def destroy_node(self):
        """Destroy the intake's helper node too."""
        self._intake.destroy()
        super().destroy_node()


def main(args=None, early=None):
    """Run until Ctrl-C / SIGTERM; exit 0, or 1 on bad configuration (see runner.run)."""
    return run(AttitudeController, NODE_NAME, args, early=early,
               on_start=lambda node: node.start(), on_stop=lambda node: node.stop())


if __name__ == '__main__':
    from .entry import exiting
    sys.exit(exiting(main()))
