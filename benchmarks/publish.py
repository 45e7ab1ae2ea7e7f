"""
Publishing serialised state: what one state message costs the publishing thread.

In one process, per message, least of five runs of 2000 messages: building the message object
as the simulator did before (stamp, quaternion and vector messages) and ``Publisher.publish``
of it, against ``Prepacked.pack`` (the message serialised once by rclpy, refilled in place)
and ``Publisher.publish`` of the bytes. For nav_msgs/Odometry, geometry_msgs/Vector3Stamped and
sensor_msgs/Imu; with one publisher, and round robin over 96 publishers (a fleet's odom topics);
with no subscriber, and with a subscriber in another process (rclpy, raw callbacks), where the
publish includes handing the message to DDS for it. ``./dev bench --only publish`` (about 1
minute).
"""

import itertools
import os
import sys
import textwrap
import time

from geometry_msgs.msg import Vector3Stamped
from nav_msgs.msg import Odometry
import rclpy
from sensor_msgs.msg import Imu

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from nodes import Process, script  # noqa: E402, I100 (after the path set-up)
from rigid_body_dynamics.ros import conversions as conv  # noqa: E402
from rigid_body_dynamics.ros.prepacked import Prepacked  # noqa: E402
from rigid_body_dynamics.ros.state_publisher import STATE_QOS  # noqa: E402

SUBSCRIBER = textwrap.dedent("""
    import sys
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from nav_msgs.msg import Odometry
    from geometry_msgs.msg import Vector3Stamped
    from sensor_msgs.msg import Imu
    from rigid_body_dynamics.ros.state_publisher import STATE_QOS
    rclpy.init()
    node = rclpy.create_node('bench_publish_sink')
    count = int(sys.argv[1])
    for k in range(count):
        for msg_type, topic in ((Odometry, 'odom'), (Vector3Stamped, 'vector'), (Imu, 'imu')):
            node.create_subscription(msg_type, f'/b{k}/{topic}', lambda _m: None, STATE_QOS,
                                     raw=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
""")

Q, W, STAMP = (0.1, -0.2, 0.3, 0.927), (0.3, 1.5, -0.4), 1_234_567_890_123


def _objects(kind):
    """Build the message of ``kind`` as the simulator did before: a new object each tick."""
    if kind == 'odom':
        def make(msg=Odometry()):
            msg.header.stamp = conv.time_msg(STAMP)
            msg.pose.pose.orientation = conv.quaternion_msg(Q)
            msg.twist.twist.angular = conv.vector_msg(W)
            return msg
    elif kind == 'vector':
        def make():
            msg = Vector3Stamped(vector=conv.vector_msg(W))
            msg.header.stamp, msg.header.frame_id = conv.time_msg(STAMP), 'body'
            return msg
    else:
        def make():
            msg = Imu(orientation=conv.quaternion_msg(Q), angular_velocity=conv.vector_msg(W))
            msg.header.stamp, msg.header.frame_id = conv.time_msg(STAMP), 'body'
            for i in (0, 4, 8):
                msg.angular_velocity_covariance[i] = 1e-6
                msg.orientation_covariance[i] = 1e-8
            msg.linear_acceleration_covariance[0] = -1.0
            return msg
    return make


def _prepacked(kind):
    """Pack the message of ``kind`` from its Prepacked template."""
    if kind == 'odom':
        msg = Odometry()
        msg.header.frame_id, msg.child_frame_id = 'world', 'body'
        packed = Prepacked(msg, ('header.stamp', 'pose.pose.orientation', 'twist.twist.angular'))
        return lambda: packed.pack(STAMP, Q, W)
    if kind == 'vector':
        msg = Vector3Stamped()
        msg.header.frame_id = 'body'
        packed = Prepacked(msg, ('header.stamp', 'vector'))
        return lambda: packed.pack(STAMP, W)
    msg = Imu()
    msg.header.frame_id = 'body'
    msg.linear_acceleration_covariance[0] = -1.0
    packed = Prepacked(msg, ('header.stamp', 'orientation', 'angular_velocity',
                             'orientation_covariance', 'angular_velocity_covariance'))
    diagonal = (1e-6, 0.0, 0.0, 0.0, 1e-6, 0.0, 0.0, 0.0, 1e-6)
    return lambda: packed.pack(STAMP, Q, W, diagonal, diagonal)


def _least(run, n=2000, rounds=5):
    """Least time per call (us) of ``run(n)`` over ``rounds`` runs."""
    best = float('inf')
    for _ in range(rounds):
        t0 = time.perf_counter()
        run(n)
        best = min(best, (time.perf_counter() - t0) / n)
    return best * 1e6


def _row(pubs, kind):
    """(us per message: object + publish, pack + publish bytes, pack alone)."""
    make, pack = _objects(kind), _prepacked(kind)

    def objects(n):
        for pub in itertools.islice(itertools.cycle(pubs), n):
            pub.publish(make())

    def raw(n):
        for pub in itertools.islice(itertools.cycle(pubs), n):
            pub.publish(pack())

    def packing(n):
        for _ in range(n):
            pack()
    return _least(objects), _least(raw), _least(packing)


def measure():
    """Markdown lines of the table."""
    rclpy.init()
    types = {'odom': Odometry, 'vector': Vector3Stamped, 'imu': Imu}
    nodes = [rclpy.create_node('bench_publish', namespace=f'/b{k}') for k in range(96)]
    pubs = {kind: [n.create_publisher(t, kind, STATE_QOS) for n in nodes]
            for kind, t in types.items()}
    lines = ['| message | publishers | subscriber | object + publish (us) | '
             'pack + publish bytes (us) | pack alone (us) | ratio |',
             '|---|---|---|---|---|---|---|']
    try:
        for subscriber in (False, True):
            sink = Process(script(SUBSCRIBER) + ['96']) if subscriber else None
            try:
                if sink is not None:
                    end = time.monotonic() + 30.0
                    while (any(p.get_subscription_count() < 1 for ps in pubs.values()
                               for p in ps) and time.monotonic() < end):
                        time.sleep(0.2)
                for kind, type_ in types.items():
                    for count in (1, 96):
                        obj, raw, pack = _row(pubs[kind][:count], kind)
                        lines.append(f'| {type_.__name__} | {count} | '
                                     f'{"yes" if subscriber else "no"} | {obj:.1f} | {raw:.1f} | '
                                     f'{pack:.1f} | {obj / raw:.1f}x |')
                        print(lines[-1], flush=True)
            finally:
                if sink is not None:
                    sink.close()
    finally:
        for node in nodes:
            node.destroy_node()
        rclpy.shutdown()
    return lines
