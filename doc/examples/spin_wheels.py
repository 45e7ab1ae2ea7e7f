"""Drive all four wheels of doc/examples/wheels.yaml with 0.01 N m each for 2 s, then stop."""
import time

import rclpy
from std_msgs.msg import Float64MultiArray

rclpy.init()
node = rclpy.create_node('wheel_driver')
pub = node.create_publisher(Float64MultiArray, 'wheel_cmd', 10)
# wait (at most 10 s) until the simulator's subscription has matched: sent before, lost
deadline = time.monotonic() + 10.0
while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.1)
# one motor torque per wheel (N m), in wheel_axes order; held until torque_timeout (0.5 s)
node.create_timer(0.05, lambda: pub.publish(Float64MultiArray(data=[0.01] * 4)))
end = node.get_clock().now().nanoseconds + 2_000_000_000
while rclpy.ok() and node.get_clock().now().nanoseconds < end:
    rclpy.spin_once(node, timeout_sec=0.1)
node.destroy_node()
rclpy.shutdown()
