"""
StatePublisher: the state topics of one simulated body, as a helper that takes a node.

Like tf2_ros' ``TransformBroadcaster(node)``: the node keeps its parameters,
subscriptions and services; this object owns the publishers of ``odom``,
``orientation``, ``angular_velocity``, ``angular_momentum``,
``angular_momentum_body``, ``applied_torque``, the sensors' topics (``imu`` and
``~/imu_bias`` from the gyro, ``magnetic_field`` from the magnetometer,
``star_tracker``, ``sun_sensor``), ``applied_dipole`` (with magnetorquers), the latched
``inertia``, ``/clock`` (optional) and ``/tf`` (optional: world -> body
frame, and world -> LVLH with an orbit, when tf2_msgs is importable, as on every
ROS install), and turns each engine item (a
:class:`~rigid_body_dynamics.engine.body.Snapshot`, a sensor sample) into its
messages, dispatching by the item's type, and a sensor's reading by the
sensor's name, from one table each. With an orbit, odom
carries the position (world) and the linear velocity (body frame). All
messages of one tick carry the snapshot's stamp; vectors are published in the
user's body frame (``body_frame``) or the world frame (``world_frame``).
The messages of the state topics are :class:`~.prepacked.Prepacked`: serialised
once per publisher with their frame ids, then refilled with each tick's stamp and
values and published as bytes (a fifth of the cost of publishing message objects).
"""

from geometry_msgs.msg import InertiaStamped, PoseWithCovarianceStamped, QuaternionStamped
from geometry_msgs.msg import TransformStamped, Vector3Stamped, WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.qos_overriding_options import QoSOverridingOptions
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import Imu, JointState, MagneticField

from . import conversions as conv
from .prepacked import Prepacked
from ..engine import SensorSample, Snapshot
from ..physics import quaternions
from ..physics.environment import lvlh_quaternion

try:
    from tf2_msgs.msg import TFMessage
except ImportError:     # pip-only installs: no tf2_msgs wheel exists
    TFMessage = None

STATE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                       reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.VOLATILE)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
CLOCK_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                       reliability=ReliabilityPolicy.BEST_EFFORT)
#: tf2_ros' TransformBroadcaster QoS (DynamicBroadcasterQoS): reliable, volatile, depth 100.
TF_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                    reliability=ReliabilityPolicy.RELIABLE,
                    durability=DurabilityPolicy.VOLATILE)


#: The position variance (m^2) of a star_tracker message: the position is not measured.
UNMEASURED = 1e12

#: The state topics besides odom, each of which a node may leave out (``state_topics``).
OPTIONAL_TOPICS = ('orientation', 'angular_velocity', 'angular_momentum',
                   'angular_momentum_body', 'applied_torque')


def tf_available():
    """Whether tf2_msgs can be imported here (always on a ROS install; not from pip)."""
    return TFMessage is not None


class StatePublisher:
    """
    The state publishers of one body on ``node``: ``frames`` = (world, body) frame ids.

    ``topics``: which of OPTIONAL_TOPICS to publish besides odom (default all);
    ``orbit``: the body has an orbit (odom's position and linear velocity, the
    LVLH frame ``lvlh_frame`` on /tf); ``magnetorquers``: publish
    ``applied_dipole``; ``sensors``: the names of the body's sensors ('gyro',
    'magnetometer', 'star_tracker', 'sun_sensor'), each of which gets its topics.
    """

    def __init__(self, node, frames, publish_clock=False, publish_tf=False,
                 topics=OPTIONAL_TOPICS, wheels=0, orbit=False, lvlh_frame='lvlh',
                 magnetorquers=False, sensors=()):
        self.world_frame, self.body_frame = frames
        self._node = node
        self._handlers = {Snapshot: self._publish_state, SensorSample: self._publish_sensor}
        # a sensor's name -> (the method that makes its publishers, the one that publishes)
        table = {'gyro': (self._make_imu, self.publish_imu),
                 'magnetometer': (self._make_magnetic, self.publish_magnetic),
                 'star_tracker': (self._make_star_tracker, self.publish_star_tracker),
                 'sun_sensor': (self._make_sun_sensor, self.publish_sun_sensor)}
        self._sensors = {}
        self._orbit = orbit
        qos_opts = QoSOverridingOptions.with_default_policies()

        def pub(msg_type, name, qos=STATE_QOS):
            if name in OPTIONAL_TOPICS and name not in topics:
                return None
            return node.create_publisher(msg_type, name, qos, qos_overriding_options=qos_opts)
        world, body = frames
        odom = Odometry()
        odom.header.frame_id, odom.child_frame_id = frames
        self._odom = pub(Odometry, 'odom')
        self._odom_bytes = Prepacked(odom, ('header.stamp', 'pose.pose.orientation',
                                            'twist.twist.angular') + (
            ('pose.pose.position', 'twist.twist.linear') if orbit else ()))
        # each message is prepacked only for a publisher that exists (two serialisations each)
        self._orientation = pub(QuaternionStamped, 'orientation')
        if self._orientation is not None:
            self._orientation_bytes = _stamped(QuaternionStamped(), world, 'quaternion')
        self._vectors = [(p, kind, _stamped(Vector3Stamped(), frame, 'vector'))
                         for p, kind, frame in (
                             (pub(Vector3Stamped, 'angular_velocity'), 'omega', body),
                             (pub(Vector3Stamped, 'angular_momentum'), 'l_world', world),
                             (pub(Vector3Stamped, 'angular_momentum_body'), 'l_body', body))
                         if p is not None]
        self._torque = pub(WrenchStamped, 'applied_torque')
        if self._torque is not None:
            self._torque_bytes = _stamped(WrenchStamped(), body, 'wrench.torque')
        for name in sensors:
            make, publish = table[name]
            make(pub)
            self._sensors[name] = publish
        self._dipole = pub(Vector3Stamped, 'applied_dipole') if magnetorquers else None
        if magnetorquers:
            self._dipole_bytes = _stamped(Vector3Stamped(), body, 'vector')
        self._inertia = pub(InertiaStamped, 'inertia', LATCHED_QOS)
        self._wheel_state = pub(JointState, 'wheel_state') if wheels else None
        if wheels:
            self._joints = JointState(name=[f'wheel_{i}' for i in range(wheels)])
        self._clock = node.create_publisher(ClockMsg, '/clock', CLOCK_QOS) \
            if publish_clock else None
        if self._clock is not None:
            self._clock_bytes = Prepacked(ClockMsg(), ('clock',))
        self._tf = node.create_publisher(TFMessage, '/tf', TF_QOS) \
            if publish_tf and tf_available() else None
        if self._tf is not None:
            tf = TransformStamped()
            tf.header.frame_id, tf.child_frame_id = frames
            transforms, fields = [tf], ['transforms.0.header.stamp',
                                        'transforms.0.transform.rotation']
            if orbit:
                lvlh = TransformStamped()
                lvlh.header.frame_id, lvlh.child_frame_id = world, lvlh_frame
                transforms.append(lvlh)
                fields += ['transforms.0.transform.translation', 'transforms.1.header.stamp',
                           'transforms.1.transform.translation',
                           'transforms.1.transform.rotation']
            self._tf_bytes = Prepacked(TFMessage(transforms=transforms), tuple(fields))

    def publish(self, item):
        """Publish one engine item (a Snapshot, a SensorSample): its topics."""
        self._handlers[type(item)](item)

    def _publish_sensor(self, sample):
        """Publish a SensorSample on its sensor's topics."""
        self._sensors[sample.sensor](sample.stamp_ns, sample.reading)

    # ------------------------------------------------------------------ sensors
    def _make_imu(self, pub):
        """Make the gyro's publishers: imu (REP 145) and ~/imu_bias."""
        body = self.body_frame
        self._imu = pub(Imu, 'imu')
        self._imu_bias = self._node.create_publisher(Vector3Stamped, '~/imu_bias', STATE_QOS)
        imu = Imu()
        imu.header.frame_id = body
        imu.linear_acceleration_covariance[0] = -1.0    # not simulated (sensor_msgs/Imu)
        self._imu_bytes = Prepacked(imu, ('header.stamp', 'orientation', 'angular_velocity',
                                          'orientation_covariance',
                                          'angular_velocity_covariance'))
        self._bias_bytes = _stamped(Vector3Stamped(), body, 'vector')

    def _make_magnetic(self, pub):
        """Make the magnetometer's publisher: magnetic_field (body frame)."""
        self._magnetic = pub(MagneticField, 'magnetic_field')
        magnetic = MagneticField()
        magnetic.header.frame_id = self.body_frame
        self._magnetic_bytes = Prepacked(magnetic, ('header.stamp', 'magnetic_field',
                                                    'magnetic_field_covariance'))

    def _make_star_tracker(self, pub):
        """Make the star tracker's publisher: star_tracker (world frame, orientation only)."""
        self._star = pub(PoseWithCovarianceStamped, 'star_tracker')
        msg = PoseWithCovarianceStamped()
        msg.header.frame_id = self.world_frame
        self._star_bytes = Prepacked(msg, ('header.stamp', 'pose.pose.orientation',
                                           'pose.covariance'))

    def _make_sun_sensor(self, pub):
        """Make the sun sensor's publisher: sun_sensor (body frame, unit vector)."""
        self._sun = pub(Vector3Stamped, 'sun_sensor')
        self._sun_bytes = _stamped(Vector3Stamped(), self.body_frame, 'vector')

    def _publish_state(self, snapshot):
        """Publish a Snapshot's state topics."""
        inertia = snapshot.inertia
        q_b, w_b = snapshot.q_principal, snapshot.omega_principal
        if not inertia.is_principal_frame:
            q_b = inertia.attitude_to_body(np.array(q_b))
            w_b = inertia.to_body(np.array(w_b))
        stamp = snapshot.stamp_ns
        if self._orbit:
            r, v = snapshot.position
            v_b = quaternions.rotate_components((-q_b[0], -q_b[1], -q_b[2], q_b[3]), v)
            self._odom.publish(self._odom_bytes.pack(stamp, q_b, w_b, r, v_b))
        else:
            self._odom.publish(self._odom_bytes.pack(stamp, q_b, w_b))
        if snapshot.wheels is not None and self._wheel_state is not None:
            # with odom at every tick (lockstep's too): a controller needs the wheel speeds
            joints, wheels = self._joints, snapshot.wheels
            joints.header.stamp = conv.time_msg(stamp)
            joints.position, joints.velocity = list(wheels.angles), list(wheels.speeds)
            joints.effort = list(wheels.applied)
            self._wheel_state.publish(joints)
        if not snapshot.odom_only:   # (lockstep's tick between publish ticks: odom only)
            self._publish_others(snapshot, stamp, q_b, w_b)
        if self._clock is not None:
            self._clock.publish(self._clock_bytes.pack(stamp))
        if self._tf is not None:
            if self._orbit:
                r, v = snapshot.position
                self._tf.publish(self._tf_bytes.pack(stamp, q_b, r, stamp, r,
                                                     lvlh_quaternion(r, v)))
            else:
                self._tf.publish(self._tf_bytes.pack(stamp, q_b))

    def _publish_others(self, snapshot, stamp, q_b, w_b):
        """Publish the optional state topics of one tick (those this publisher has)."""
        inertia = snapshot.inertia
        if self._orientation is not None:
            self._orientation.publish(self._orientation_bytes.pack(stamp, q_b))
        wheels = snapshot.wheels
        if self._vectors:
            m_p = tuple(i * w for i, w in zip(inertia.moments, snapshot.omega_principal))
            if wheels is not None:          # H = I omega + sum J Omega g: the whole gyrostat
                m_p = tuple(a + b for a, b in zip(m_p, wheels.momentum_principal))
            vectors = {'omega': w_b,
                       'l_world': quaternions.rotate_components(snapshot.q_principal, m_p),
                       'l_body': m_p if inertia.is_principal_frame else
                       inertia.to_body(np.array(m_p))}
            for pub, kind, packed in self._vectors:
                pub.publish(packed.pack(stamp, vectors[kind]))
        if self._torque is not None:
            torque = snapshot.torque_principal if inertia.is_principal_frame else \
                inertia.to_body(np.array(snapshot.torque_principal))
            self._torque.publish(self._torque_bytes.pack(stamp, torque))
        if self._dipole is not None:
            self._dipole.publish(self._dipole_bytes.pack(stamp, snapshot.dipole))

    @property
    def broadcasts_tf(self):
        """Whether this publisher broadcasts world -> body on /tf."""
        return self._tf is not None

    def stop_tf(self, node):
        """Stop broadcasting /tf (the fleet does so for bodies that share a body frame)."""
        if self._tf is not None:
            node.destroy_publisher(self._tf)
            self._tf = None

    def publish_imu(self, stamp_ns, reading):
        """
        Publish sensor_msgs/Imu (REP 145) and ~/imu_bias from a GyroReading stamped stamp_ns.

        Covariances: angular velocity N^2 * rate on the diagonal (the white noise
        per sample; the bias is published apart on ~/imu_bias), orientation the
        orientation noise variance; linear acceleration -1 in element 0 (not
        simulated, as sensor_msgs/Imu says).
        """
        rate, orientation = (reading.rate_variance,) * 3, (reading.orientation_variance,) * 3
        self._imu.publish(self._imu_bytes.pack(
            stamp_ns, reading.q_body, reading.omega_body,
            _diagonal(orientation), _diagonal(rate)))
        self._imu_bias.publish(self._bias_bytes.pack(stamp_ns, reading.bias_body))

    def publish_magnetic(self, stamp_ns, reading):
        """Publish sensor_msgs/MagneticField (T, body frame) from a MagnetometerReading."""
        self._magnetic.publish(self._magnetic_bytes.pack(
            stamp_ns, reading.field, _diagonal((reading.variance,) * 3)))

    def publish_star_tracker(self, stamp_ns, reading):
        """
        Publish geometry_msgs/PoseWithCovarianceStamped from a StarTrackerReading.

        The orientation is the measured body attitude in the world frame; its
        covariance (rad^2, about the world's fixed axes) fills the lower right 3 x
        3 block; the position is not measured: 0, with UNMEASURED on its diagonal.
        """
        c = reading.covariance
        u = UNMEASURED
        cov = (u, 0.0, 0.0, 0.0, 0.0, 0.0,
               0.0, u, 0.0, 0.0, 0.0, 0.0,
               0.0, 0.0, u, 0.0, 0.0, 0.0,
               0.0, 0.0, 0.0, c[0], c[1], c[2],
               0.0, 0.0, 0.0, c[3], c[4], c[5],
               0.0, 0.0, 0.0, c[6], c[7], c[8])
        self._star.publish(self._star_bytes.pack(stamp_ns, reading.q, cov))

    def publish_sun_sensor(self, stamp_ns, reading):
        """Publish geometry_msgs/Vector3Stamped (unit, body frame) from a SunSensorReading."""
        self._sun.publish(self._sun_bytes.pack(stamp_ns, reading.direction))

    def publish_inertia(self, inertia, stamp_ns):
        """Publish the latched inertia tensor (kg m^2, body frame; the mass is not modelled)."""
        msg = InertiaStamped()
        msg.header.stamp = conv.time_msg(stamp_ns)
        msg.header.frame_id = self.body_frame
        t = inertia.tensor
        msg.inertia.m = 0.0
        msg.inertia.ixx, msg.inertia.ixy, msg.inertia.ixz = t[0, 0], t[0, 1], t[0, 2]
        msg.inertia.iyy, msg.inertia.iyz, msg.inertia.izz = t[1, 1], t[1, 2], t[2, 2]
        self._inertia.publish(msg)


def _stamped(msg, frame, field):
    """Prepack a header-stamped message in ``frame``, refilling its stamp and ``field``."""
    msg.header.frame_id = frame
    return Prepacked(msg, ('header.stamp', field))


def _diagonal(values):
    """Return a row-major 3 x 3 covariance (9 floats) with ``values`` on the diagonal."""
    a, b, c = values
    return (a, 0.0, 0.0, 0.0, b, 0.0, 0.0, 0.0, c)
