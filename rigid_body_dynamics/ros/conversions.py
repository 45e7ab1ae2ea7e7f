"""
Message <-> numpy conversions, in one place.

Quaternions are (x, y, z, w) on both sides. Times are integer nanoseconds.
"""


from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from geometry_msgs.msg import Quaternion, Vector3
import numpy as np

_NS = 1_000_000_000


def time_msg(ns):
    """builtin_interfaces/Time from integer nanoseconds."""
    sec, nanosec = divmod(int(ns), _NS)
    return Time(sec=sec, nanosec=nanosec)


def time_ns(msg):
    """Integer nanoseconds from builtin_interfaces/Time."""
    return msg.sec * _NS + msg.nanosec


def quaternion_msg(q):
    """geometry_msgs/Quaternion from (x, y, z, w)."""
    return Quaternion(x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3]))


def quaternion_array(msg):
    """(x, y, z, w) array from geometry_msgs/Quaternion."""
    return np.array([msg.x, msg.y, msg.z, msg.w])


def vector_msg(v):
    """geometry_msgs/Vector3 from a 3-sequence."""
    return Vector3(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def vector_array(msg):
    """3-array from geometry_msgs/Vector3."""
    return np.array([msg.x, msg.y, msg.z])


def status(name, level, message, values, hardware_id='none'):
    """
    diagnostic_msgs/DiagnosticStatus with values as strings (REP 107).

    ``values`` is a mapping or a sequence of (key, value) pairs; floats are
    written with enough digits to be read back.
    """
    items = values.items() if hasattr(values, 'items') else values
    out = []
    for key, value in items:
        if isinstance(value, (bool, np.bool_)):
            text = 'true' if value else 'false'
        elif isinstance(value, (float, np.floating)):
            text = repr(float(value))
        elif isinstance(value, np.integer):
            text = str(int(value))
        else:
            text = str(value)
        out.append(KeyValue(key=str(key), value=text))
    return DiagnosticStatus(level=level, name=name, message=message, hardware_id=hardware_id,
                            values=out)


def status_values(msg):
    """Return the key -> string value mapping of a DiagnosticStatus."""
    return {kv.key: kv.value for kv in msg.values}
