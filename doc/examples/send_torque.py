"""Send attitude_simulator a torque of 0.1 N m about its body z axis for 2 s, then stop."""
import time

from geometry_msgs.msg import WrenchStamped
import rclpy

rclpy.init()
node = rclpy.create_node('torque_sender')
pub = node.create_publisher(WrenchStamped, 'torque_cmd', 10)
# wait (at most 10 s) until the simulator's subscription has matched: sent before, lost
deadline = time.monotonic() + 10.0
while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.1)


def send():
    msg = WrenchStamped()
    msg.header.stamp = node.get_clock().now().to_msg()
    msg.header.frame_id = 'base_link'      # the body frame; 'odom': fixed in the world
    msg.wrench.torque.z = 0.1              # N m
    pub.publish(msg)


node.create_timer(0.05, send)              # 20 Hz, well within torque_timeout (0.5 s)
end = node.get_clock().now().nanoseconds + 2_000_000_000
while rclpy.ok() and node.get_clock().now().nanoseconds < end:
    rclpy.spin_once(node, timeout_sec=0.1)
node.destroy_node()
rclpy.shutdown()
