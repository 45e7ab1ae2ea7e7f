"""Prepacked messages against rclpy's own serialisation of the same messages."""

import os
import random
import subprocess
import sys

from geometry_msgs.msg import QuaternionStamped, Vector3Stamped, WrenchStamped
from nav_msgs.msg import Odometry
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from rigid_body_dynamics.ros import conversions as conv
from rigid_body_dynamics.ros.prepacked import Prepacked
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu
from std_msgs.msg import Header


def _stamp(rng):
    # every second of int32 and every nanosecond, so the split and the unsigned half are tested
    return rng.randrange(0, 2 ** 31) * 1_000_000_000 + rng.randrange(0, 1_000_000_000)


def _floats(rng, n):
    return tuple(rng.choice((rng.gauss(0.0, 1.0), rng.uniform(-1e300, 1e300), -0.0, 5e-324))
                 for _ in range(n))


def _odometry(frames):
    msg = Odometry()
    msg.header.frame_id, msg.child_frame_id = frames
    return msg


@pytest.mark.parametrize('frames', [('world', 'body'), ('w', 'b'), ('map', 'satellite_7/base')])
def test_odometry_equals_the_message_rclpy_builds(frames):
    """Every refilled field comes back from rclpy's deserialiser, and nothing else changes."""
    packed = Prepacked(_odometry(frames), ('header.stamp', 'pose.pose.orientation',
                                           'twist.twist.angular'))
    rng = random.Random(7)
    for _ in range(300):
        stamp, q, w = _stamp(rng), _floats(rng, 4), _floats(rng, 3)
        msg = _odometry(frames)
        msg.header.stamp = conv.time_msg(stamp)
        msg.pose.pose.orientation = conv.quaternion_msg(q)
        msg.twist.twist.angular = conv.vector_msg(w)
        raw = packed.pack(stamp, q, w)
        assert isinstance(raw, bytes)
        assert len(raw) == len(serialize_message(msg))
        assert deserialize_message(raw, Odometry) == msg


def test_every_state_message_of_the_simulator():
    """The stamped vectors, quaternion, wrench, imu (covariances too), clock and TF."""
    rng = random.Random(11)
    for _ in range(100):
        stamp = _stamp(rng)
        header = Header(stamp=conv.time_msg(stamp), frame_id='body')
        v, q = _floats(rng, 3), _floats(rng, 4)
        cases = [
            (Vector3Stamped(header=Header(frame_id='body')), ('header.stamp', 'vector'),
             (stamp, v), Vector3Stamped(header=header, vector=conv.vector_msg(v))),
            (QuaternionStamped(header=Header(frame_id='body')), ('header.stamp', 'quaternion'),
             (stamp, q), QuaternionStamped(header=header, quaternion=conv.quaternion_msg(q))),
            (Clock(), ('clock',), (stamp,), Clock(clock=conv.time_msg(stamp))),
        ]
        wrench = WrenchStamped(header=header)
        wrench.wrench.torque = conv.vector_msg(v)
        cases.append((WrenchStamped(header=Header(frame_id='body')),
                      ('header.stamp', 'wrench.torque'), (stamp, v), wrench))
        cov_o, cov_w = _floats(rng, 9), _floats(rng, 9)
        imu = Imu(header=header, orientation=conv.quaternion_msg(q),
                  angular_velocity=conv.vector_msg(v))
        imu.orientation_covariance[:] = cov_o
        imu.angular_velocity_covariance[:] = cov_w
        imu.linear_acceleration_covariance[0] = -1.0
        template = Imu(header=Header(frame_id='body'))
        template.linear_acceleration_covariance[0] = -1.0
        cases.append((template, ('header.stamp', 'orientation', 'angular_velocity',
                                 'orientation_covariance', 'angular_velocity_covariance'),
                      (stamp, q, v, cov_o, cov_w), imu))
        for template, fields, values, expected in cases:
            raw = Prepacked(template, fields).pack(*values)
            assert deserialize_message(raw, type(expected)) == expected, type(expected).__name__


TF_CHECK = """
from geometry_msgs.msg import TransformStamped
from rclpy.serialization import deserialize_message
from tf2_msgs.msg import TFMessage
from rigid_body_dynamics.ros import conversions as conv
from rigid_body_dynamics.ros.prepacked import Prepacked
tf = TransformStamped()
tf.header.frame_id, tf.child_frame_id = 'world', 'body'
packed = Prepacked(TFMessage(transforms=[tf]),
                   ('transforms.0.header.stamp', 'transforms.0.transform.rotation'))
tf.header.stamp = conv.time_msg(123_456_789_012)
tf.transform.rotation = conv.quaternion_msg((0.1, -0.2, 0.3, 0.9))
raw = packed.pack(123_456_789_012, (0.1, -0.2, 0.3, 0.9))
assert deserialize_message(raw, TFMessage) == TFMessage(transforms=[tf])
print('ok')
"""


def test_tf_message_with_one_transform(tf2_msgs_env):
    """A field inside a sequence element ('transforms.0....'), in a process that has tf2_msgs."""
    done = subprocess.run([sys.executable, '-c', TF_CHECK], env=dict(os.environ, **tf2_msgs_env),
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == 'ok', done.stderr


def test_the_template_is_not_kept_and_packs_do_not_leak_into_each_other():
    """Changing the template afterwards changes nothing; each pack has only its own values."""
    template = _odometry(('world', 'body'))
    packed = Prepacked(template, ('header.stamp', 'twist.twist.angular'))
    template.child_frame_id = 'other'
    first = packed.pack(5, (1.0, 2.0, 3.0))
    second = packed.pack(7, (4.0, 5.0, 6.0))
    msg = deserialize_message(first, Odometry)
    assert (msg.child_frame_id, msg.header.stamp.nanosec, msg.twist.twist.angular.x) == (
        'body', 5, 1.0)
    assert deserialize_message(second, Odometry).twist.twist.angular.z == 6.0


def test_fields_that_cannot_be_refilled_are_refused():
    """A string (its length would move every later field) is a TypeError saying why."""
    with pytest.raises(TypeError, match='not a Time or float64 fields'):
        Prepacked(_odometry(('world', 'body')), ('header',))
    with pytest.raises(AttributeError):
        Prepacked(_odometry(('world', 'body')), ('pose.pose.nothing',))


def test_cdr_field_offsets_are_where_rclpy_serialises_the_fields():
    """cdr.py's layouts (from the message definitions) agree with sentinel serialisations."""
    import struct
    from nav_msgs.msg import Odometry
    from rclpy.serialization import serialize_message
    from rigid_body_dynamics.messages import cdr

    def base_after(*frames):
        """Payload offset after the header stamp and the frame id strings, 8-aligned."""
        at = 8
        for frame in frames:
            at = (at + 3) // 4 * 4 + 4 + len(frame) + 1
        return (at + 7) // 8 * 8
    odom = Odometry()
    odom.header.frame_id, odom.child_frame_id = 'odom', 'base_link'
    values = {}
    for k, (name, path, count) in enumerate((
            ('position', 'pose.pose.position', 3), ('orientation', 'pose.pose.orientation', 4),
            ('linear', 'twist.twist.linear', 3), ('angular', 'twist.twist.angular', 3))):
        target = odom
        for part in path.split('.'):
            target = getattr(target, part)
        sentinel = [1000.0 * (k + 1) + i + 0.25 for i in range(count)]
        for attr, value in zip('xyzw', sentinel):
            setattr(target, attr, value)
        values[name] = sentinel
    odom.pose.covariance[0] = odom.twist.covariance[0] = 7.125
    raw = serialize_message(odom)
    base = base_after('odom', 'base_link')
    for name, sentinel in values.items():
        at = raw.find(struct.pack(f'<{len(sentinel)}d', *sentinel)) - cdr._HEADER
        assert at == base + cdr._ODOMETRY[name], name
    assert len(raw) - cdr._HEADER == base + cdr._ODOMETRY_TAIL
    wrench = WrenchStamped()
    wrench.header.frame_id = 'base_link'
    wrench.wrench.force.x, wrench.wrench.torque.x = 3.5, 4.5
    raw = serialize_message(wrench)
    base = base_after('base_link')
    for name, value in (('force', 3.5), ('torque', 4.5)):
        assert raw.find(struct.pack('<d', value)) - cdr._HEADER == base + cdr._WRENCH[name]
    assert len(raw) - cdr._HEADER == base + cdr._WRENCH_TAIL
