"""
The few fields the analysis needs, read from batches of raw CDR messages straight into numpy.

Deserialising every nav_msgs/Odometry with rosbags costs about 10 us; a bag
of 1e6 messages took 33 s that way (benchmarks/RESULTS.md). A topic's
messages almost always share their frame ids, hence their length and every
field offset, so a batch is one (N, size) byte array and each field a
strided view. Layout: XCDR1 little-endian (encapsulation 00 01), alignment
relative to the payload after the 4-byte encapsulation header, strings as a
uint32 length (with the terminating NUL) and the bytes. A batch that is not
uniform (frame ids of different lengths or contents, big-endian, truncated)
raises :class:`NotUniform` and the caller deserialises it message by message.
Tested against rosbags' deserialiser (test/test_bags.py).
"""

import numpy as np

_HEADER = 4          # encapsulation bytes before the payload


def _layout(*fields):
    """
    Offsets of consecutive float64 fields after the last string: ({name: offset}, size).

    ``fields`` are (name, number of float64) in the message definition's order;
    all are 8-aligned, so each starts where the one before ends.
    """
    offsets, at = {}, 0
    for name, count in fields:
        offsets[name] = at
        at += 8 * count
    return offsets, at


#: nav_msgs/Odometry after child_frame_id: pose (geometry_msgs/PoseWithCovariance:
#: Point, Quaternion, float64[36]) then twist (TwistWithCovariance: linear, angular, float64[36]).
_ODOMETRY, _ODOMETRY_TAIL = _layout(('position', 3), ('orientation', 4),
                                    ('pose_covariance', 36), ('linear', 3), ('angular', 3),
                                    ('twist_covariance', 36))
#: geometry_msgs/WrenchStamped after header.frame_id: Wrench (force, torque).
_WRENCH, _WRENCH_TAIL = _layout(('force', 3), ('torque', 3))


class NotUniform(ValueError):
    """The batch's messages do not share one layout; deserialise them one by one."""


def _align(offset, n):
    return (offset + n - 1) // n * n


def _batch(raws):
    """(N, size) uint8 array of equally long little-endian CDR messages, or NotUniform."""
    size = len(raws[0])
    if size < _HEADER + 12 or any(len(r) != size for r in raws):
        raise NotUniform('messages of different lengths')
    buf = np.frombuffer(b''.join(raws), dtype=np.uint8).reshape(len(raws), size)
    if buf[0, 0] != 0 or buf[0, 1] != 1 or not np.all(buf[:, :2] == buf[0, :2]):
        raise NotUniform('not all little-endian CDR')
    return buf


def _string(buf, pos):
    """(text, payload offset after it) of the CDR string at payload offset ``pos``; row 0."""
    at = _HEADER + pos
    length = int(buf[0, at:at + 4].view('<u4')[0])
    end = pos + 4 + length
    if length < 1 or _HEADER + end > buf.shape[1]:
        raise NotUniform('string runs past the message')
    text = bytes(buf[0, at + 4:at + 4 + length - 1]).decode('utf-8', errors='replace')
    return text, end


def _field(buf, pos, count, dtype='<f8'):
    at = _HEADER + pos
    width = np.dtype(dtype).itemsize * count
    return np.ascontiguousarray(buf[:, at:at + width]).view(dtype).reshape(len(buf), count)


def _stamps(buf):
    sec = _field(buf, 0, 1, '<i4')[:, 0].astype(np.int64)
    nanosec = _field(buf, 4, 1, '<u4')[:, 0].astype(np.int64)
    return sec * 1_000_000_000 + nanosec


def _same_bytes(buf, start, end):
    at, to = _HEADER + start, _HEADER + end
    if not np.all(buf[:, at:to] == buf[0, at:to]):
        raise NotUniform('frame ids differ within the batch')


def odometry_arrays(raws):
    """
    Return (t_ns, q, omega, frame_id, child_frame_id) of raw nav_msgs/Odometry messages.

    ``t_ns`` (N,) int64 header stamps; q (N, 4) x-y-z-w and omega (N, 3) rad/s
    as published (twist in the child frame). NotUniform if the batch does not
    share one layout.
    """
    buf = _batch(raws)
    world, pos = _string(buf, 8)
    child, end = _string(buf, _align(pos, 4))
    _same_bytes(buf, 8, end)
    base = _align(end, 8)
    if _HEADER + base + _ODOMETRY_TAIL > buf.shape[1]:
        raise NotUniform('truncated Odometry')
    return (_stamps(buf), _field(buf, base + _ODOMETRY['orientation'], 4),
            _field(buf, base + _ODOMETRY['angular'], 3), world, child)


def wrench_arrays(raws, force=False):
    """
    Return (t_ns, torque (N, 3) N m, frame_id) of raw geometry_msgs/WrenchStamped messages.

    With ``force`` also the forces (N, 3) N, as a fourth item.
    """
    buf = _batch(raws)
    frame, end = _string(buf, 8)
    _same_bytes(buf, 8, end)
    base = _align(end, 8)
    if _HEADER + base + _WRENCH_TAIL > buf.shape[1]:
        raise NotUniform('truncated WrenchStamped')
    torque = _field(buf, base + _WRENCH['torque'], 3)
    if force:
        return _stamps(buf), torque, frame, _field(buf, base + _WRENCH['force'], 3)
    return _stamps(buf), torque, frame
