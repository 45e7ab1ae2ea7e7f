"""
rosbag2 bags (sqlite3 or MCAP folders) and bare .mcap / .db3 files <-> Trajectory.

Reading and writing go through the ``rosbags`` library (pure Python, no ROS
install needed): the bags are what ``ros2 bag record`` writes on Jazzy
(metadata version 9, MCAP by default) and what ``ros2 bag play``, Foxglove and
PlotJuggler open. Messages become samples through :mod:`rigid_body_dynamics.messages.samples`,
exactly as the live analyzer takes them (frames honoured, stamps in integer
ns). Every failure is a :class:`BagError` whose text is one line.
"""

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import samples
from ..physics.analysis import Trajectory
from ..physics.inertia import Inertia

ODOMETRY = 'nav_msgs/msg/Odometry'
WRENCH = 'geometry_msgs/msg/WrenchStamped'
INERTIA = 'geometry_msgs/msg/InertiaStamped'


class BagError(ValueError):
    """A bag that cannot be analysed; the text is one line saying why."""


def _typestore():
    from rosbags.typesys import get_typestore, Stores
    return get_typestore(Stores.ROS2_JAZZY)


@dataclass
class BagInfo:
    """What was read: topics used, counts of samples taken and dropped (and why), segments."""

    path: str
    odom_topic: str
    torque_topic: object = None
    inertia_source: str = ''
    odom_messages: int = 0
    torque_messages: int = 0
    dropped: dict = field(default_factory=dict)
    segments: int = 1
    segment_start_ns: int = 0


def _namespace(topic):
    return topic.rsplit('/', 1)[0]


def _pick(connections, wanted, msgtype, role, default_name=None, near=None):
    """Pick the topic for ``role``: the named one, or the only one of its type (or None)."""
    by_topic = {}
    for c in connections:
        by_topic.setdefault(c.topic, c.msgtype)
    if wanted is not None:
        if wanted not in by_topic:
            raise BagError(f'no topic {wanted!r} in the bag (topics: '
                           f'{", ".join(sorted(by_topic)) or "none"})')
        if by_topic[wanted] != msgtype:
            raise BagError(f'topic {wanted!r} is {by_topic[wanted]}, not {msgtype}')
        return wanted
    typed = sorted(t for t, ty in by_topic.items() if ty == msgtype)
    if near is not None:
        close = [t for t in typed if _namespace(t) == near]
        if default_name and f'{near}/{default_name}' in close:
            return f'{near}/{default_name}'
        if len(close) == 1:
            return close[0]
    if len(typed) == 1:
        return typed[0]
    if not typed:
        return None
    raise BagError(f'{len(typed)} {msgtype} topics ({", ".join(typed)}): choose the {role} '
                   f'topic with --{role}-topic')


def open_reader(path):
    """Open a rosbags AnyReader on a bag folder or a bare .mcap / .db3 file; BagError if not."""
    from rosbags.highlevel import AnyReader
    p = Path(path)
    if not p.exists():
        raise BagError(f'{path}: no such file or folder')
    try:
        reader = AnyReader([p], default_typestore=_typestore())
        reader.open()
    except Exception as err:   # rosbags raises several types (and struct/OS errors) here
        raise BagError(f'{path}: not a readable rosbag2 bag or MCAP file '
                       f'({_one_line(err)})') from None
    return reader


def _one_line(err):
    text = ' '.join(str(err).split()) or type(err).__name__
    return text if len(text) <= 200 else text[:197] + '...'


def read_trajectory(path, odom_topic=None, torque_topic=None, inertia=None, start=None,
                    end=None, reset_jump=0.5, max_gap=1.0):
    """
    Read the attitude samples of one body from a bag; returns (Trajectory, BagInfo).

    ``odom_topic``: default the only nav_msgs/Odometry topic. ``torque_topic``:
    default the WrenchStamped ``applied_torque`` beside the odom topic (or the
    only WrenchStamped), none if absent. ``inertia``: 3 principal moments or 6
    tensor elements (kg m^2); default the bag's latched InertiaStamped beside
    the odom topic. As the live analyzer does, a stamp more than
    ``reset_jump`` s before the newest (in recording order) or a gap over
    ``max_gap`` s starts a new segment; the last segment is analysed.
    ``start`` / ``end`` (s from that segment's first stamp) cut it. Raises
    BagError (one line) for an unreadable bag, a missing or wrong topic, no
    inertia or no usable sample.
    """
    reader = open_reader(path)
    try:
        conns = reader.connections
        odom = _pick(conns, odom_topic, ODOMETRY, 'odom')
        if odom is None:
            raise BagError(f'{path}: no {ODOMETRY} topic in the bag (topics: '
                           f'{", ".join(sorted({c.topic for c in conns})) or "none"})')
        ns = _namespace(odom)
        torque = _pick(conns, torque_topic, WRENCH, 'torque', 'applied_torque', ns)
        info = BagInfo(str(path), odom, torque)
        body, body_frame = _inertia(reader, conns, inertia, ns, info)
        selected = [c for c in conns if c.topic in (odom, torque)]
        t, q, w, tau_t, tau, seg_start = _samples(reader, selected, odom, body_frame, info,
                                                  int(reset_jump * 1e9), int(max_gap * 1e9))
    except BagError:
        raise
    except Exception as err:   # a corrupt chunk or message in the middle of the bag
        raise BagError(f'{path}: cannot read the bag ({_one_line(err)})') from None
    finally:
        reader.close()
    if not len(t):
        raise BagError(f'{path}: no usable {ODOMETRY} sample on {odom}')
    t = np.asarray(t, dtype=np.int64)
    torque_at = np.zeros((t.size, 3))
    if tau_t:
        order = np.argsort(tau_t, kind='stable')
        tt, tv = np.array(tau_t, dtype=np.int64)[order], np.array(tau)[order]
        idx = np.searchsorted(tt, t, side='right') - 1
        known = idx >= 0
        torque_at[known] = tv[idx[known]]
    traj = Trajectory.from_samples(t, q, w, body, torque_at, title=Path(path).name)
    info.dropped['non-finite or zero quaternion'] = traj.dropped
    info.segment_start_ns = seg_start
    traj = traj.between(start, end)
    if len(traj) == 0:
        raise BagError(f'{path}: no sample between --start and --end')
    return traj, info


def _inertia(reader, conns, given, ns, info):
    """(Inertia, body frame id or None) from the argument or the bag's InertiaStamped."""
    if given is not None:
        values = [float(v) for v in given]
        try:
            body = Inertia(values) if len(values) == 3 else Inertia.from_tensor(values)
        except (TypeError, ValueError) as err:
            raise BagError(f'--inertia: {err}') from None
        info.inertia_source = 'argument'
        return body, None
    topic = _pick(conns, None, INERTIA, 'inertia', 'inertia', ns)
    if topic is None:
        raise BagError(f'{info.path}: no {INERTIA} in the bag: give the moments with --inertia')
    last = None
    for conn, _, raw in reader.messages([c for c in conns if c.topic == topic]):
        last = reader.deserialize(raw, conn.msgtype)
    if last is None:
        raise BagError(f'{info.path}: topic {topic} holds no message: give --inertia')
    tensor, frame = samples.inertia_tensor(last)
    try:
        body = Inertia.from_tensor(tensor)
    except ValueError as err:
        raise BagError(f'{info.path}: the inertia on {topic} is refused: {err}') from None
    info.inertia_source = topic
    return body, frame or None


def _samples(reader, connections, odom, body_frame, info, reset_jump, max_gap):
    """
    Odometry and torque samples of the last segment, from the raw CDR of the messages.

    Messages are taken in recording order in chunks; :func:`cdr.odometry_arrays`
    reads the few fields needed straight into numpy (20x faster than
    deserialising each message; tested against rosbags' deserialiser), and
    falls back to rosbags per message where a chunk's frame ids differ.
    """
    odom_chunks, torque_chunks = [], []
    pending = {odom: [], 'torque': []}
    seq = 0

    def flush():
        if pending[odom]:
            raws, order = zip(*pending[odom])
            odom_chunks.append((np.array(order), *_odometry(reader, raws, body_frame, info)))
        if pending['torque']:
            raws, order = zip(*pending['torque'])
            torque_chunks.append((np.array(order), *_torques(reader, raws, body_frame, info)))
        pending[odom], pending['torque'] = [], []
    for conn, _, raw in reader.messages(connections):
        pending[odom if conn.topic == odom else 'torque'].append((raw, seq))
        seq += 1
        if seq % CHUNK == 0:
            flush()
    flush()
    info.odom_messages = sum(c[0].size for c in odom_chunks) + info.dropped.get(
        'odom in another frame', 0)
    info.torque_messages = sum(c[0].size for c in torque_chunks)
    if not odom_chunks:
        return [], [], [], [], [], 0
    order, t, q, w = (np.concatenate(parts) for parts in zip(*odom_chunks))
    if not t.size:
        return [], [], [], [], [], 0
    start = _last_segment(t, reset_jump, max_gap, info)
    tau_t, tau = np.zeros(0, dtype=np.int64), np.zeros((0, 3))
    if torque_chunks:
        t_order, tau_t, tau = (np.concatenate(parts) for parts in zip(*torque_chunks))
        after = t_order > order[start] if start else np.ones(t_order.size, dtype=bool)
        tau_t, tau = tau_t[after], tau[after]
    return t[start:], q[start:], w[start:], list(tau_t), list(tau), int(t[start])


#: Messages parsed per numpy batch.
CHUNK = 100_000


def _last_segment(t, reset_jump, max_gap, info):
    """Index where the last segment starts: after the last reset (time back) or gap."""
    start = 0
    while True:
        newest = np.maximum.accumulate(t[start:])
        jump = (t[start + 1:] < newest[:-1] - reset_jump) | (t[start + 1:] > newest[:-1] + max_gap)
        hits = np.flatnonzero(jump)
        if not hits.size:
            return start
        info.segments += 1
        start += int(hits[0]) + 1


def _odometry(reader, raws, body_frame, info):
    """(t_ns, q, omega body) arrays of raw Odometry messages; frames as samples.py says."""
    t, q, w, dropped = samples.odometry_batch(raws, lambda raw: reader.deserialize(
        raw, ODOMETRY), body_frame)
    if dropped:
        info.dropped['odom in another frame'] = info.dropped.get('odom in another frame', 0) \
            + dropped
    return t, q, w


def _torques(reader, raws, body_frame, info):
    """(t_ns, torque body) arrays of raw WrenchStamped messages."""
    t, tau, dropped = samples.torque_batch(raws, lambda raw: reader.deserialize(raw, WRENCH),
                                           body_frame)
    if dropped:
        info.dropped['torque in another frame'] = \
            info.dropped.get('torque in another frame', 0) + dropped
    return t, tau


# ---------------------------------------------------------------------------- writing

def latched_qos():
    """Return the QoS of a latched topic (transient local, depth 1) as rosbags records it."""
    from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness,
                                    QosReliability, QosTime)
    zero = QosTime(0, 0)
    return Qos(QosHistory.KEEP_LAST, 1, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL,
               zero, zero, QosLiveliness.AUTOMATIC, zero, False)


def stream_qos():
    """Return the reliable, volatile, keep-last QoS of the state and torque topics."""
    from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness,
                                    QosReliability, QosTime)
    zero = QosTime(0, 0)
    return Qos(QosHistory.KEEP_LAST, 10, QosReliability.RELIABLE, QosDurability.VOLATILE,
               zero, zero, QosLiveliness.AUTOMATIC, zero, False)


class BagWriter:
    """
    Write a rosbag2 bag (metadata version 9, MCAP or sqlite3 storage) of serialised messages.

    ``topics`` maps topic -> (message type, latched). Use as a context
    manager; :meth:`write` takes CDR bytes (e.g. from an rclpy subscription
    with ``raw=True``, or rosbags' serializer) and the receive time (ns).
    """

    def __init__(self, path, topics, storage='mcap'):
        from rosbags.rosbag2 import StoragePlugin, Writer
        plugin = {'mcap': StoragePlugin.MCAP, 'sqlite3': StoragePlugin.SQLITE3}[storage]
        if Path(path).exists():
            raise BagError(f'{path} exists already: choose a new folder for the bag')
        self._writer = Writer(path, version=9, storage_plugin=plugin)
        self._topics = topics
        self._connections = {}

    def __enter__(self):
        """Open the bag and add its topics."""
        store = _typestore()
        self._writer.open()
        for topic, (msgtype, latched) in self._topics.items():
            self._connections[topic] = self._writer.add_connection(
                topic, msgtype, typestore=store,
                offered_qos_profiles=[latched_qos() if latched else stream_qos()])
        return self

    def write(self, topic, t_ns, raw):
        """Append one serialised message of ``topic`` received at ``t_ns``."""
        self._writer.write(self._connections[topic], int(t_ns), bytes(raw))

    def __exit__(self, *_exc):
        """Close the bag (writes metadata.yaml)."""
        self._writer.close()
