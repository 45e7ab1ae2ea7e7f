"""
Recording the running nodes' state into a rosbag2 bag (``rigid_body_report --record``).

:func:`record` subscribes to ``odom``, ``applied_torque`` and the latched
``inertia`` and writes what comes as ``ros2 bag record`` would (MCAP storage,
metadata version 9, the inertia's transient-local QoS kept, so ``ros2 bag play``
latches it again). The only part of the tools that talks to ROS topics.
"""

from ..messages.bags import BagError, BagWriter, INERTIA, ODOMETRY, read_trajectory, WRENCH


def record(path, duration, timeout=60.0):
    """
    Record odom, applied_torque and the latched inertia of the running nodes into a bag.

    Messages are taken serialised and written as they came, with their
    receive time and fully qualified topic names, as ``ros2 bag record``
    does (only odom's header is decoded, to know when to stop); stops once
    ``duration`` s of odom stamps and the inertia are in. Returns the bag's
    Trajectory (read back with :func:`~rigid_body_dynamics.messages.bags.read_trajectory`).
    """
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from rclpy.serialization import deserialize_message
    from geometry_msgs.msg import InertiaStamped, WrenchStamped
    from nav_msgs.msg import Odometry
    from ..ros.client import RosClient, WaitTimeout
    from ..messages.samples import stamp_ns
    stamps, inertia, out = [], [], {}
    deep = QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE)
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    with RosClient('rigid_body_report') as client:
        node = client.node

        def keep(name):
            def on_message(raw):
                out['writer'].write(name, node.get_clock().now().nanoseconds, raw)
                if name.endswith('odom'):
                    stamps.append(stamp_ns(deserialize_message(raw, Odometry).header.stamp))
                elif name.endswith('inertia'):
                    inertia.append(True)
            return on_message
        topics = {}
        for topic, msg_type, type_name, qos in (
                ('odom', Odometry, ODOMETRY, deep),
                ('applied_torque', WrenchStamped, WRENCH, deep),
                ('inertia', InertiaStamped, INERTIA, latched)):
            # bags name topics fully qualified, as ros2 bag record does
            name = node.resolve_topic_name(topic)
            topics[name] = (type_name, qos is latched)
            node.create_subscription(msg_type, topic, keep(name), qos, raw=True)
        with BagWriter(path, topics, 'mcap') as writer:
            out['writer'] = writer
            try:
                client.spin_until(lambda: inertia and stamps and (
                    max(stamps) - min(stamps)) * 1e-9 >= duration, timeout + duration,
                    f'{duration:g} s of odom')
            except WaitTimeout:
                pass        # said below if nothing usable came
    if not inertia or len(stamps) < 3:
        raise BagError(f'nothing usable recorded into {path}: is attitude_simulator running '
                       'in this domain?')
    return read_trajectory(path)[0]
