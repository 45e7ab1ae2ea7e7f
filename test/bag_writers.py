"""
Bags for the tests, written two independent ways: rosbags, and the mcap / mcap-ros2 packages.

Both take a trajectory (t_ns absolute, q, omega body, torque body, inertia
tensor) and write nav_msgs/Odometry on ``odom``, geometry_msgs/WrenchStamped on
``applied_torque`` and a latched geometry_msgs/InertiaStamped on ``inertia``,
as attitude_simulator publishes them. The mcap writer builds its message
definitions from the .msg files the ROS message wheels install (share/), so it
shares nothing with rosbags but the format.
"""

import os
import re

import numpy as np
from rigid_body_dynamics.messages import bags

ODOM_FRAME, BODY_FRAME = 'odom', 'base_link'


def _stamp(cls, t_ns):
    return cls(sec=int(t_ns // 1_000_000_000), nanosec=int(t_ns % 1_000_000_000))


def rosbags_messages(t_ns, q, w, tensor, torque=None, child=BODY_FRAME, inertia_frame=BODY_FRAME):
    """Serialise messages with rosbags' typestore: (topic, t_ns, cdr) in publishing order."""
    store = bags._typestore()
    T = store.types
    Time = T['builtin_interfaces/msg/Time']
    Header = T['std_msgs/msg/Header']
    Vector3 = T['geometry_msgs/msg/Vector3']
    Quaternion, Point = T['geometry_msgs/msg/Quaternion'], T['geometry_msgs/msg/Point']
    Pose, Twist = T['geometry_msgs/msg/Pose'], T['geometry_msgs/msg/Twist']
    PoseCov, TwistCov = (T['geometry_msgs/msg/PoseWithCovariance'],
                         T['geometry_msgs/msg/TwistWithCovariance'])
    Odometry, Wrench, WrenchStamped = (T['nav_msgs/msg/Odometry'], T['geometry_msgs/msg/Wrench'],
                                       T['geometry_msgs/msg/WrenchStamped'])
    Inertia, InertiaStamped = T['geometry_msgs/msg/Inertia'], T['geometry_msgs/msg/InertiaStamped']
    zero3 = Vector3(x=0.0, y=0.0, z=0.0)
    cov = np.zeros(36)
    ixx, iyy, izz, ixy, ixz, iyz = tensor
    inertia = InertiaStamped(
        header=Header(stamp=_stamp(Time, t_ns[0]), frame_id=inertia_frame),
        inertia=Inertia(m=1.0, com=zero3, ixx=ixx, ixy=ixy, ixz=ixz, iyy=iyy, iyz=iyz, izz=izz))
    out = [('inertia', int(t_ns[0]), store.serialize_cdr(inertia, bags.INERTIA))]
    for k, t in enumerate(t_ns):
        header = Header(stamp=_stamp(Time, t), frame_id=ODOM_FRAME)
        odom = Odometry(
            header=header, child_frame_id=child,
            pose=PoseCov(pose=Pose(position=Point(x=0.0, y=0.0, z=0.0), orientation=Quaternion(
                x=q[k][0], y=q[k][1], z=q[k][2], w=q[k][3])), covariance=cov),
            twist=TwistCov(twist=Twist(linear=zero3, angular=Vector3(
                x=w[k][0], y=w[k][1], z=w[k][2])), covariance=cov))
        out.append(('odom', int(t), store.serialize_cdr(odom, bags.ODOMETRY)))
        if torque is not None:
            tau = torque[k]
            msg = WrenchStamped(header=Header(stamp=_stamp(Time, t), frame_id=BODY_FRAME),
                                wrench=Wrench(force=zero3, torque=Vector3(
                                    x=tau[0], y=tau[1], z=tau[2])))
            out.append(('applied_torque', int(t), store.serialize_cdr(msg, bags.WRENCH)))
    return out


TOPICS = {'odom': (bags.ODOMETRY, False), 'applied_torque': (bags.WRENCH, False),
          'inertia': (bags.INERTIA, True)}


def write_rosbags(path, messages, storage='mcap'):
    """Write (topic, t_ns, cdr) with rosbags through the package's BagWriter."""
    with bags.BagWriter(str(path), TOPICS, storage) as writer:
        for topic, t, raw in messages:
            writer.write(topic, t, raw)
    return path


# ---------------------------------------------------------------- the independent writer

def _share():
    import nav_msgs
    # the wheels install share/<package>/msg/*.msg beside lib/ (the venv's prefix)
    here = os.path.dirname(nav_msgs.__file__)
    while here != os.path.dirname(here):
        candidate = os.path.join(here, 'share')
        if os.path.isdir(os.path.join(candidate, 'nav_msgs', 'msg')):
            return candidate
        here = os.path.dirname(here)
    raise RuntimeError('no share/nav_msgs/msg beside the message wheels')


def _msg_text(name):
    pkg, _, typ = name.split('/')
    with open(os.path.join(_share(), pkg, 'msg', f'{typ}.msg')) as f:
        return f.read()


def _dependencies(name, seen):
    pkg = name.split('/')[0]
    for line in _msg_text(name).splitlines():
        line = line.split('#', 1)[0].strip()
        if not line:
            continue
        field_type = re.sub(r'\[.*\]$', '', line.split()[0])
        if field_type.split('/')[0] in ('bool', 'byte', 'char', 'float32', 'float64', 'int8',
                                        'uint8', 'int16', 'uint16', 'int32', 'uint32', 'int64',
                                        'uint64', 'string', 'wstring') or '=' in line.split()[1]:
            continue
        full = field_type if '/' in field_type else f'{pkg}/{field_type}'
        full = full.replace('/msg/', '/')
        full = '/'.join([full.split('/')[0], 'msg', full.split('/')[1]])
        if full not in seen:
            seen.append(full)
            _dependencies(full, seen)
    return seen


def msgdef(name):
    """Return the ros2msg definition text of ``name`` (pkg/msg/Type) with its dependencies."""
    text = _msg_text(name)
    for dep in _dependencies(name, []):
        short = dep.replace('/msg/', '/')
        text += '\n' + '=' * 80 + f'\nMSG: {short}\n' + _msg_text(dep)
    return text


def write_mcap_ros2(path, t_ns, q, w, tensor, torque=None):
    """Write a bare .mcap with mcap-ros2-support (dict messages; it sets no QoS metadata)."""
    from mcap_ros2.writer import Writer
    with open(path, 'wb') as f:
        writer = Writer(f)
        schemas = {name: writer.register_msgdef(name, msgdef(name))
                   for name in (bags.ODOMETRY, bags.WRENCH, bags.INERTIA)}
        zero3 = {'x': 0.0, 'y': 0.0, 'z': 0.0}
        ixx, iyy, izz, ixy, ixz, iyz = tensor

        def header(t, frame):
            return {'stamp': {'sec': int(t // 1_000_000_000), 'nanosec': int(t % 1_000_000_000)},
                    'frame_id': frame}
        writer.write_message('inertia', schemas[bags.INERTIA], {
            'header': header(t_ns[0], BODY_FRAME),
            'inertia': {'m': 1.0, 'com': zero3, 'ixx': ixx, 'ixy': ixy, 'ixz': ixz, 'iyy': iyy,
                        'iyz': iyz, 'izz': izz}}, log_time=int(t_ns[0]), publish_time=int(t_ns[0]))
        for k, t in enumerate(t_ns):
            writer.write_message('odom', schemas[bags.ODOMETRY], {
                'header': header(t, ODOM_FRAME), 'child_frame_id': BODY_FRAME,
                'pose': {'pose': {'position': zero3, 'orientation': dict(zip('xyzw', map(
                    float, q[k])))}, 'covariance': [0.0] * 36},
                'twist': {'twist': {'linear': zero3, 'angular': dict(zip('xyz', map(
                    float, w[k])))}, 'covariance': [0.0] * 36}},
                log_time=int(t), publish_time=int(t))
            if torque is not None:
                writer.write_message('applied_torque', schemas[bags.WRENCH], {
                    'header': header(t, BODY_FRAME),
                    'wrench': {'force': zero3, 'torque': dict(zip('xyz', map(
                        float, torque[k])))}}, log_time=int(t), publish_time=int(t))
        writer.finish()
    return path
