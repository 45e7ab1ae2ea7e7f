"""
Messages serialised once by rclpy, then refilled in place: the state topics' hot path.

Publishing a message object costs rclpy a conversion to C and a serialisation:
12-15 us for a nav_msgs/Odometry here, against 2.7-2.9 us for publishing the
same message already serialised (``Publisher.publish(bytes)``, rclpy's public
API), and building the Python message costs more on top
(benchmarks/RESULTS.md, "Publishing serialised state"). A body's state
messages keep their frame ids, so their serialised length and the offset of
every field are fixed: :class:`Prepacked` serialises a template once with
rclpy, finds where the fields to be refilled sit (by serialising it again
with sentinel values in them, so the offsets are rclpy's own, not a
re-derivation of CDR), and :meth:`Prepacked.pack` writes new values there.
Checked against ``serialize_message`` byte for byte (test/test_prepacked.py).
"""

import copy
import struct

from builtin_interfaces.msg import Time
from rclpy.serialization import serialize_message

_NS = 1_000_000_000


def _resolve(msg, path):
    """Return the sub-message at dotted ``path`` ('header.stamp', 'transforms.0.transform')."""
    for part in path.split('.'):
        msg = msg[int(part)] if part.isdigit() else getattr(msg, part)
    return msg


def _layout(field):
    """Return (struct, sentinel setter, is a Time) of a Time, float64 fields or float64s."""
    if isinstance(field, Time):
        def sentinel(k):
            field.sec, field.nanosec = 0x5A5A0000 + k, 0x3C3C0000 + k
            return (field.sec, field.nanosec)
        return struct.Struct('<iI'), sentinel, True
    if hasattr(field, '__len__') and not hasattr(field, 'get_fields_and_field_types'):
        n = len(field)      # a fixed float64 array (a covariance)

        def sentinel(k):
            values = [1.0e300 / (7 + k) + j for j in range(n)]
            field[:] = values
            return tuple(values)
        return struct.Struct(f'<{n}d'), sentinel, False
    names = list(field.get_fields_and_field_types())
    types = set(field.get_fields_and_field_types().values())
    if types != {'double'}:
        raise TypeError(f'{type(field).__name__} is not a Time or float64 fields ({types})')

    def sentinel(k):
        values = [1.0e300 / (7 + k) + j for j in range(len(names))]
        for name, value in zip(names, values):
            setattr(field, name, value)
        return tuple(values)
    return struct.Struct(f'<{len(names)}d'), sentinel, False


class Prepacked:
    """
    A message of fixed layout, serialised once, whose ``fields`` are rewritten per publish.

    ``template``: a message with every other field (frame ids, constants) set;
    it is copied, not kept. ``fields``: dotted paths of the fields to refill,
    each a builtin_interfaces/Time (refilled from int ns), a message of
    float64 fields only (Vector3, Quaternion: refilled from a sequence of
    floats in field order) or a fixed float64 array (a covariance).
    """

    def __init__(self, template, fields):
        probe = copy.deepcopy(template)
        self.buffer = bytearray(serialize_message(template))
        layouts = [_layout(_resolve(probe, path)) for path in fields]
        sentinels = [set_sentinel(k) for k, (_, set_sentinel, _) in enumerate(layouts)]
        marked = serialize_message(probe)
        if len(marked) != len(self.buffer):
            raise ValueError('the message layout depends on the refilled values')
        self._slots = []
        for path, (fmt, _, is_time), values in zip(fields, layouts, sentinels):
            needle = fmt.pack(*values)
            at = marked.find(needle)
            if at < 0 or marked.find(needle, at + 1) >= 0:
                raise ValueError(f'cannot locate field {path!r} in the serialised message')
            self._slots.append((fmt.pack_into, at, is_time))
        self.fields = tuple(fields)

    def pack(self, *values):
        """
        Return the serialised message (bytes) with ``values`` written in, one per field.

        A Time field takes int ns (the stamp), the others a sequence of floats.
        """
        buffer = self.buffer
        for (pack_into, at, is_time), value in zip(self._slots, values):
            if is_time:
                pack_into(buffer, at, *divmod(int(value), _NS))
            else:
                pack_into(buffer, at, *value)
        return bytes(buffer)
