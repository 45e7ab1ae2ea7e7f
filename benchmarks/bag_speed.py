"""
rigid_body_analyze on a bag of 1e6 nav_msgs/Odometry messages (MCAP): wall time and where it goes.

The bag (tennis racket at 1 kHz for 1000 s, plus applied_torque and the
latched inertia, written with rosbags through the package's BagWriter) is made
in a temporary folder, removed afterwards. Timed: the whole ``rigid_body_analyze`` run in a
fresh process, and inside it reading + deserialising, samples, analysis.
"""

import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'test'))

MESSAGES = 1_000_000


def make_bag(path, messages=MESSAGES):
    """Write the bag; returns seconds taken."""
    import numpy as np
    from bag_writers import rosbags_messages
    from rigid_body_dynamics.physics import presets, simulate
    body = presets.get('tennis_racket')
    start = time.perf_counter()
    run = simulate(body.moments, body.omega0, body.q0, duration=messages * 1e-3, dt=1e-3)
    t_ns = 1_764_547_200_000_000_000 + np.arange(run.t.size, dtype=np.int64) * 1_000_000
    chunk = 100_000
    from rigid_body_dynamics.messages import bags
    from bag_writers import TOPICS
    with bags.BagWriter(path, TOPICS, 'mcap') as writer:
        for i in range(0, t_ns.size, chunk):
            sl = slice(i, i + chunk)
            msgs = rosbags_messages(t_ns[sl], run.q[sl], run.omega[sl], [1, 2, 3, 0, 0, 0],
                                    torque=run.torque[sl])
            for topic, t, raw in msgs if i == 0 else msgs[1:]:
                writer.write(topic, t, raw)
    return time.perf_counter() - start


def measure():
    """Lines for RESULTS.md."""
    with tempfile.TemporaryDirectory(prefix='rbd-bag-') as folder:
        return _measure(os.path.join(folder, 'bag'))


def _measure(path):
    made = make_bag(path)
    size = sum(os.path.getsize(os.path.join(path, f)) for f in os.listdir(path))
    start = time.perf_counter()
    out = subprocess.run([sys.executable, '-m', 'rigid_body_dynamics.tools.analyze', path,
                          '--json'], capture_output=True, text=True, timeout=600)
    total = time.perf_counter() - start
    if out.returncode != 0:
        raise RuntimeError(out.stderr)
    from rigid_body_dynamics.messages import bags
    from rigid_body_dynamics.physics.analysis import analyse
    start = time.perf_counter()
    traj, info = bags.read_trajectory(path)
    read = time.perf_counter() - start
    start = time.perf_counter()
    analyse(traj)
    analysis = time.perf_counter() - start
    # the slow path for comparison: rosbags deserialises every message (first 1e5 Odometry)
    reader = bags.open_reader(path)
    conns = [c for c in reader.connections if c.topic == 'odom']
    count, start = 0, time.perf_counter()
    for conn, _, raw in reader.messages(conns):
        reader.deserialize(raw, conn.msgtype)
        count += 1
        if count == 100_000:
            break
    per_message = (time.perf_counter() - start) / count
    reader.close()
    return [f'Bag: {info.odom_messages} Odometry + {info.torque_messages} WrenchStamped messages, '
            f'{size / 1e6:.0f} MB (MCAP, uncompressed), written in {made:.0f} s.', '',
            '| step | seconds |', '|---|---|',
            f'| `rigid_body_analyze BAG --json`, whole process | {total:.1f} |',
            f'| of which: read raw messages (rosbags), CDR fields into numpy, samples | '
            f'{read:.1f} |',
            f'| of which: analyse() | {analysis:.1f} |',
            f'| for comparison: rosbags deserialising each Odometry ({per_message * 1e6:.1f} us '
            f'per message, measured on 1e5) | {per_message * info.odom_messages:.1f} for the '
            'Odometry alone |']


if __name__ == '__main__':
    print('\n'.join(measure()))
