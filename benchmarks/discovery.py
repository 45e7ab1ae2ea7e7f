"""
DDS discovery: how long until every participant knows every other, for 8, 16 and 32 participants.

Each participant is a process of its own (rclpy, Fast DDS, the default simple discovery,
localhost only) with one node and one publisher, as a fleet worker or a simulator is. Each
records the wall time its node was made and the time its graph first showed all N nodes;
the discovery time is the last participant's "knows all" minus the last one's start, i.e.
how long the graph takes to settle once the last process has joined. Every participant
sends its announcements to every other, so the discovery traffic grows with N^2;
Fast DDS's discovery server (``ROS_DISCOVERY_SERVER``) replaces that with a star.
Three runs per N; the median and the worst. ``./dev bench --only discovery`` (about 3
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
while len({name for name, _ in node.get_node_names_and_namespaces()
           if name.startswith('participant_')}) < n and time.monotonic() < deadline:
    time.sleep(0.005)
known = time.time()
print(json.dumps({'made': made, 'known': known}), flush=True)
sys.stdin.readline()            # stay on the graph until every participant knows all
node.destroy_node()
rclpy.shutdown()
"""
COUNTS = (8, 16, 32)
RUNS = 3


def discovery_time(n):
    """Start ``n`` participants; return the seconds from the last start to all-know-all."""
    procs = [subprocess.Popen([sys.executable, '-c', PARTICIPANT, str(n), str(k)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
             for k in range(n)]
    try:
        reports = [json.loads(p.stdout.readline()) for p in procs]
    finally:
        for p in procs:
            p.stdin.close()
        for p in procs:
            p.wait(30.0)
    return max(r['known'] for r in reports) - max(r['made'] for r in reports)


def measure(counts=COUNTS, runs=RUNS):
    """Measure each count ``runs`` times; Markdown lines."""
    lines = ['| participants | discovery time, median (s) | worst (s) |', '|---|---|---|']
    for n in counts:
        times = sorted(discovery_time(n) for _ in range(runs))
        lines.append(f'| {n} | {times[len(times) // 2]:.2f} | {times[-1]:.2f} |')
        print(lines[-1], flush=True)
    return lines


if __name__ == '__main__':
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    print('\n'.join(measure()))
