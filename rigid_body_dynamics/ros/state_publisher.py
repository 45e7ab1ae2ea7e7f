"""
StatePublisher: the state topics of one simulated body, as a helper that takes a node.

Like tf2_ros' ``TransformBroadcaster(node)``: the node keeps its parameters,
subscriptions and services; this object owns the publishers of ``odom``,
``orientation``, ``angular_velocity``, ``angular_momentum``,
``angular_momentum_body``, ``applied_torque``, ``imu`` and ``~/imu_bias``
(optional; from the engine's gyro samples), the latched
``inertia``, ``/clock`` (optional) and ``/tf`` (optional: world -> body
frame, when tf2_msgs is importable, as on every ROS install), and turns an engine
:class:`~rigid_body_dynamics.engine.body.Snapshot` into their messages. All
messages of one tick carry the snapshot's stamp; vectors are published in the
user's body frame (``body_frame``) or the world frame (``world_frame``).
"""

from geometry_msgs.msg import InertiaStamped, QuaternionStamped, TransformStamped
from geometry_msgs.msg import Vector3Stamped, WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.qos_overriding_options import QoSOverridingOptions
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import Imu

from . import conversions as conv
from ..engine import ImuSample
from ..physics import quaternions

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


#: The state topics besides odom, each of which a node may leave out (``state_topics``).
OPTIONAL_TOPICS = ('orientation', 'angular_velocity', 'angular_momentum',
                   'angular_momentum_body', 'applied_torque')


def tf_available():
    """Whether tf2_msgs can be imported here (always on a ROS install; not from pip)."""
    return TFMessage is not None


class StatePublisher:
    """
    The state publishers of one body on ``node``: ``frames`` = (world, body) frame ids.

    ``topics``: which of OPTIONAL_TOPICS to publish besides odom (default all).
    """

    def __init__(self, node, frames, publish_imu=True, publish_clock=False, publish_tf=False,
                 topics=OPTIONAL_TOPICS):
        self.world_frame, self.body_frame = frames
        qos_opts = QoSOverridingOptions.with_default_policies()

        def pub(msg_type, name, qos=STATE_QOS):
            if name in OPTIONAL_TOPICS and name not in topics:
                return None
            return node.create_publisher(msg_type, name, qos, qos_overriding_options=qos_opts)
        self._odom = pub(Odometry, 'odom')
        self._odom_msg = Odometry()       # building one costs ~10 us: it is reused
        self._odom_msg.header.frame_id, self._odom_msg.child_frame_id = frames
        self._orientation = pub(QuaternionStamped, 'orientation')
        self._omega = pub(Vector3Stamped, 'angular_velocity')
        self._l_world = pub(Vector3Stamped, 'angular_momentum')
        self._l_body = pub(Vector3Stamped, 'angular_momentum_body')
        self._torque = pub(WrenchStamped, 'applied_torque')
        self._vectors = [(p, kind) for p, kind in ((self._omega, 'omega'),
                                                   (self._l_world, 'l_world'),
                                                   (self._l_body, 'l_body')) if p is not None]
        self._imu = pub(Imu, 'imu') if publish_imu else None
        self._imu_bias = node.create_publisher(Vector3Stamped, '~/imu_bias', STATE_QOS) \
            if publish_imu else None
        self._inertia = pub(InertiaStamped, 'inertia', LATCHED_QOS)
        self._clock = node.create_publisher(ClockMsg, '/clock', CLOCK_QOS) \
            if publish_clock else None
        self._tf = node.create_publisher(TFMessage, '/tf', TF_QOS) \
            if publish_tf and tf_available() else None

    def publish(self, snapshot):
        """Publish one engine item: a Snapshot's state topics, or an ImuSample's imu and bias."""
        if isinstance(snapshot, ImuSample):
            self.publish_imu(snapshot)
            return
        inertia = snapshot.inertia
        q_p, w_p = snapshot.q, snapshot.omega
        stamp = conv.time_msg(snapshot.stamp_ns)
        q_b = inertia.attitude_to_body(np.array(q_p))
        w_b = inertia.to_body(np.array(w_p))
        q_msg = conv.quaternion_msg(q_b)
        w_msg = conv.vector_msg(w_b)

        odom = self._odom_msg          # one message, refilled (publish serialises it at once)
        odom.header.stamp = stamp
        odom.pose.pose.orientation = q_msg
        odom.twist.twist.angular = w_msg
        self._odom.publish(odom)
        if not snapshot.odom_only:   # (lockstep's tick between publish ticks: odom only)
            self._publish_others(snapshot, stamp, q_msg, w_b)
        self._publish_clock_and_tf(stamp, q_msg)

    def _publish_others(self, snapshot, stamp, q_msg, w_b):
        """Publish the optional state topics of one tick (those this publisher has)."""
        inertia, world, body_frame = snapshot.inertia, self.world_frame, self.body_frame
        if self._orientation is not None:
            msg = QuaternionStamped(quaternion=q_msg)
            msg.header.stamp, msg.header.frame_id = stamp, world
            self._orientation.publish(msg)
        if self._vectors:
            m_p = tuple(i * w for i, w in zip(inertia.moments, snapshot.omega))
            vectors = {'omega': (w_b, body_frame),
                       'l_world': (quaternions.rotate_components(snapshot.q, m_p), world),
                       'l_body': (inertia.to_body(np.array(m_p)), body_frame)}
            for pub, kind in self._vectors:
                vec, frame = vectors[kind]
                msg = Vector3Stamped(vector=conv.vector_msg(vec))
                msg.header.stamp, msg.header.frame_id = stamp, frame
                pub.publish(msg)
        if self._torque is not None:
            wrench = WrenchStamped()
            wrench.header.stamp, wrench.header.frame_id = stamp, body_frame
            wrench.wrench.torque = conv.vector_msg(inertia.to_body(np.array(snapshot.torque)))
            self._torque.publish(wrench)

    def _publish_clock_and_tf(self, stamp, q_msg):
        if self._clock is not None:
            self._clock.publish(ClockMsg(clock=stamp))
        if self._tf is not None:
            tf = TransformStamped()
            tf.header.stamp = stamp
            tf.header.frame_id, tf.child_frame_id = self.world_frame, self.body_frame
            tf.transform.rotation = q_msg
            self._tf.publish(TFMessage(transforms=[tf]))

    @property
    def broadcasts_tf(self):
        """Whether this publisher broadcasts world -> body on /tf."""
        return self._tf is not None

    def stop_tf(self, node):
        """Stop broadcasting /tf (the fleet does so for bodies that share a body frame)."""
        if self._tf is not None:
            node.destroy_publisher(self._tf)
            self._tf = None

    def publish_imu(self, sample):
        """
        Publish sensor_msgs/Imu (REP 145) and ~/imu_bias from an engine ImuSample.

        Covariances: angular velocity N^2 * rate on the diagonal (the white noise
        per sample; the bias is published apart on ~/imu_bias), orientation the
        orientation noise variance; linear acceleration -1 in element 0 (not
        simulated, as sensor_msgs/Imu says).
        """
        if self._imu is None:
            return
        stamp = conv.time_msg(sample.stamp_ns)
        imu = Imu(orientation=conv.quaternion_msg(sample.q),
                  angular_velocity=conv.vector_msg(sample.omega))
        imu.header.stamp, imu.header.frame_id = stamp, self.body_frame
        for i in (0, 4, 8):
            imu.angular_velocity_covariance[i] = sample.rate_variance
            imu.orientation_covariance[i] = sample.orientation_variance
        imu.linear_acceleration_covariance[0] = -1.0
        self._imu.publish(imu)
        bias = Vector3Stamped(vector=conv.vector_msg(sample.bias))
        bias.header.stamp, bias.header.frame_id = stamp, self.body_frame
        self._imu_bias.publish(bias)

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
