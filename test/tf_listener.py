"""
Listen to /tf and odom in a process that can import the built tf2_msgs; print JSON.

Run by test_simulator_node's TF test with tf2_msgs_build.environment(): the
test process itself cannot load a type support added to LD_LIBRARY_PATH after
it started. Prints one JSON object: the /tf transforms and odom stamps
received, and the type hashes of the /tf publishers.
"""

import argparse
import json
import sys

from nav_msgs.msg import Odometry
from ros_harness import DEEP, Probe, time_ns
from tf2_msgs.msg import TFMessage


def main():
    """Collect ``--count`` /tf messages (or fail after ``--timeout`` s) and print them."""
    parser = argparse.ArgumentParser()
    parser.add_argument('--count', type=int, default=50)
    parser.add_argument('--timeout', type=float, default=30.0)
    parser.add_argument('--odom', default='odom', help='the odometry topic to collect')
    options = parser.parse_args()
    with Probe('tf_listener') as probe:
        tf = probe.subscribe(TFMessage, '/tf', DEEP)
        odom = probe.subscribe(Odometry, options.odom, DEEP)
        probe.spin_until(lambda: len(tf) >= options.count and len(odom) >= options.count,
                         options.timeout, f'{options.count} /tf and odom messages')
        publishers = probe.node.get_publishers_info_by_topic('/tf')
        out = {
            'tf': [[(time_ns(t.header.stamp), t.header.frame_id, t.child_frame_id,
                     [t.transform.translation.x, t.transform.translation.y,
                      t.transform.translation.z],
                     [t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
                      t.transform.rotation.w]) for t in m.transforms] for m in tf],
            'odom': [(time_ns(m.header.stamp), [m.pose.pose.orientation.x,
                      m.pose.pose.orientation.y, m.pose.pose.orientation.z,
                      m.pose.pose.orientation.w]) for m in odom],
            'publishers': [(p.node_name, p.topic_type, str(p.topic_type_hash),
                            p.qos_profile.reliability.name, p.qos_profile.durability.name)
                           for p in publishers],
        }
    json.dump(out, sys.stdout)
    return 0


if __name__ == '__main__':
    sys.exit(main())
