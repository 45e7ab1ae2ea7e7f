"""
DDS discovery: how long until every participant knows every other, for 8, 16 and 32 participants.

Each participant is a process of its own (rclpy, Fast DDS, the default simple discovery,
localhost only) with one node and one publisher, as a fleet worker or a simulator is. Each
records the wall time its node was made and the time its graph first showed all N nodes;
the discovery time is the last participant's "knows all" minus the last one's start, i.e.
how long the graph takes to settle once the last process has joined. Every participant
sends its announcements to every other, so the discovery traffic grows with N^2;
Fast DDS's discovery server (``ROS_DISCOVERY_SERVER``) replaces that with a star.
Five runs per N; the median and the worst. (Fast DDS logs a shared-memory port error
when many participants start at once on one machine, "Failed init_port ... open_and_lock_file
failed"; discovery goes on over UDP.) ``./dev bench --only discovery`` (about 5
minutes).
"""

import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
PARTICIPANT = r"""
import json, sys, time
import rclpy
from std_msgs.msg import Empty
n, k = int(sys.argv[1]), int(sys.argv[2])
rclpy.init()
node = rclpy.create_node(f'participant_{k}')
node.create_publisher(Empty, f'/discovery/p{k}', 10)
made = time.time()
deadline = time.monotonic() + 120.0
def seen():
    return len({name for name, _ in node.get_node_names_and_namespaces()
                if name.startswith('participant_')})
while seen() < n and time.monotonic() < deadline:
    time.sleep(0.005)
known = time.time()
print(json.dumps({'made': made, 'known': known, 'all': seen() >= n}), flush=True)
sys.stdin.readline()            # stay on the graph until every participant knows all
node.destroy_node()
rclpy.shutdown()
"""
COUNTS = (8, 16, 32)
RUNS = 5


def report(proc):
    """Return the participant's JSON line (None if it ended without one), past Fast DDS' lines."""
    for line in proc.stdout:
        if line.startswith('{'):
            return json.loads(line)
    return None


def discovery_time(n, timeout=120.0):
    """Start ``n`` participants; return the seconds from the last start to all-know-all."""
    procs = [subprocess.Popen([sys.executable, '-c', PARTICIPANT, str(n), str(k)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
             for k in range(n)]
    try:
        reports = [report(p) for p in procs]
    finally:
        for p in procs:
            p.stdin.close()
        for p in procs:
            try:
                p.wait(timeout)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
    if None in reports or not all(r['all'] for r in reports):
        return float('nan')             # a participant failed or never saw every other
    return max(r['known'] for r in reports) - max(r['made'] for r in reports)


def measure(counts=COUNTS, runs=RUNS):
    """Measure each count ``runs`` times; Markdown lines."""
    lines = ['| participants | discovery time, median (s) | worst (s) |', '|---|---|---|']
    for n in counts:
        times = sorted(discovery_time(n) for _ in range(runs))
        lines.append(f'| {n} | {times[len(times) // 2]:.3f} | {times[-1]:.3f} |')
        print(lines[-1], flush=True)
    return lines


if __name__ == '__main__':
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    print('\n'.join(measure()))
