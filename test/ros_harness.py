"""
Helpers for tests that talk to the nodes over real topics.

Nodes start as separate processes the way a user starts them
(``python -m rigid_body_dynamics.nodes.<name> --ros-args ...``), in the DDS
domain the session fixture reserved, with discovery kept on this machine. The
test side is an rclpy node in its own Context. Every wait has a deadline.
"""

import os
import subprocess
import time

from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rigid_body_dynamics.physics import FreeRigidBody, quaternions
from rigid_body_dynamics.ros.client import interrupt, RosClient, start_node  # noqa: F401
from rigid_body_dynamics.ros.conversions import quaternion_array, quaternion_msg, status_values
from rigid_body_dynamics.ros.conversions import time_msg, time_ns, vector_array, vector_msg

#: Subscriber QoS for the tests: reliable with a deep queue, so nothing is dropped.
DEEP = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10000,
                  reliability=ReliabilityPolicy.RELIABLE)
#: Torque per round-trip number in ``command_round_trips`` (N m): leaves the motion nearly free.
TORQUE_UNIT = 1e-9
LATCHED = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                     reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


def stamp(msg):
    """Header stamp in seconds."""
    return msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec


def odom_arrays(msgs):
    """(t, q, omega) arrays from Odometry messages."""
    t = np.array([stamp(m) for m in msgs])
    q = np.array([quaternion_array(m.pose.pose.orientation) for m in msgs])
    w = np.array([vector_array(m.twist.twist.angular) for m in msgs])
    return t, q, w


def exact_errors(msgs, moments, omega0, q0=(0.0, 0.0, 0.0, 1.0)):
    """
    Largest errors of Odometry messages against the exact torque-free motion at their stamps.

    Returns (attitude, rad; body rate, rad/s); stamps are simulated time from 0.
    """
    t, q, w = odom_arrays(msgs)
    q_ref, w_ref = FreeRigidBody(moments, omega0, q0).state_at(t)
    return (float(np.max(quaternions.angle_between(q, q_ref))),
            float(np.max(np.abs(w - w_ref))))


def assert_exact(msgs, moments, omega0, q0=(0.0, 0.0, 0.0, 1.0), tol=1e-9):
    """Every Odometry message matches the exact torque-free motion: tol rad, tol |omega0|."""
    attitude, rate = exact_errors(msgs, moments, omega0, q0)
    assert attitude <= tol
    assert rate <= tol * np.linalg.norm(omega0)


def odom_msg(t, q, w):
    """Odometry odom -> base_link at ``t`` (s): attitude ``q`` (x, y, z, w), body rate ``w``."""
    msg = Odometry()
    msg.header.stamp = time_msg(int(round(t * 1e9)))
    msg.header.frame_id, msg.child_frame_id = 'odom', 'base_link'
    msg.pose.pose.orientation = quaternion_msg(q)
    msg.twist.twist.angular = vector_msg(w)
    return msg


def relative(msgs, start_ns):
    """
    Copy Odometry messages with stamps made relative to ``start_ns`` (the node's start).

    The simulator stamps start + simulated time, start being the ROS time at start-up;
    its latched inertia carries start. Integer ns: float seconds since 1970 keep 0.2 us.
    """
    out = []
    for m in msgs:
        copy = Odometry()
        copy.pose, copy.twist = m.pose, m.twist
        copy.header.stamp = time_msg(time_ns(m.header.stamp) - start_ns)
        out.append(copy)
    return out


def status_count(probe, name, key):
    """Integer ``key`` of the newest /diagnostics status ``name`` (0 before there is one)."""
    found = probe.newest_status(name)
    return int(found[2].get(key, 0)) if found else 0


def analyzer_heard(probe):
    """Tell whether the analyzer's diagnostics count any odom (needs /diagnostics subscribed)."""
    return status_count(probe, 'input', 'messages received') > 0


def command_round_trips(probe, rounds, period):
    """
    Seconds from publishing torque_cmd k to receiving the simulator's applied_torque with it.

    Command k carries k * TORQUE_UNIT about x; a first command (about y) is
    repeated until it comes back, so none is lost to discovery. Commands that
    never came back are left out (compare the count with ``rounds``).
    """
    arrivals = {}

    def on_applied(msg):
        key = 'hello' if msg.wrench.torque.y else round(msg.wrench.torque.x / TORQUE_UNIT)
        arrivals.setdefault(key, time.monotonic())
    probe.node.create_subscription(WrenchStamped, 'applied_torque', on_applied,
                                   QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE))
    pub = probe.publisher(WrenchStamped, 'torque_cmd')
    hello = WrenchStamped()
    hello.wrench.torque.y = TORQUE_UNIT
    probe.handshake(pub, hello, lambda: 'hello' in arrivals)
    sent = {}
    for k in range(1, rounds + 1):
        msg = WrenchStamped()
        msg.wrench.torque.x = k * TORQUE_UNIT
        sent[k] = time.monotonic()
        pub.publish(msg)
        probe.spin_for(period)
    probe.spin_for(0.5)
    return [arrivals[k] - sent[k] for k in sent if k in arrivals]


class NodeProcess:
    """A node started as its own process; ``stop()`` sends SIGINT and returns the exit code."""

    def __init__(self, module, ros_args=(), log_dir=None, name='node', env=None):
        self.handled = False            # the test stopped it or waited for it (stop, wait)
        self.log_path = os.path.join(log_dir or os.environ['ROS_LOG_DIR'], f'{name}.log')
        self._log = open(self.log_path, 'w')
        self.proc = start_node(module, ros_args, stdout=self._log, stderr=subprocess.STDOUT,
                               env=dict(os.environ, **(env or {})))

    def output(self):
        """Everything the process printed so far."""
        if not self._log.closed:
            self._log.flush()
        with open(self.log_path) as f:
            return f.read()

    def stop(self, timeout=10.0):
        """SIGINT, then wait; kill after ``timeout`` s. Returns (exit code, seconds taken)."""
        self.handled = True
        start = time.monotonic()
        code = interrupt(self.proc, timeout)
        self._log.close()
        return code, time.monotonic() - start

    def kill(self):
        """SIGKILL the process (a crash the test makes: its exit code is not checked)."""
        self.handled = True
        self.proc.kill()

    def wait(self, timeout):
        """Wait for the process to end by itself; returns its exit code."""
        self.handled = True
        code = self.proc.wait(timeout)
        self._log.close()
        return code


class Probe(RosClient):
    """A test-side node in its own Context: subscribe, publish, call services, with deadlines."""

    def __init__(self, name='probe'):
        super().__init__(name)
        self.messages = {}
        self._clients = {}          # (service type, name) -> client: see call()

    def subscribe(self, msg_type, topic, qos=DEEP):
        """Collect every message on ``topic`` into ``self.messages[topic]``; returns that list."""
        store = self.messages.setdefault(topic, [])
        self.node.create_subscription(msg_type, topic, store.append, qos)
        return store

    def wait_for(self, topic, count=1, timeout=20.0):
        """Spin until ``count`` messages arrived on ``topic``; returns the list."""
        store = self.messages[topic]
        self.spin_until(lambda: len(store) >= count, timeout, f'{count} messages on {topic}')
        return store

    def publisher(self, msg_type, topic, qos=10, subscribers=1, timeout=20.0):
        """Create a publisher and return it once ``subscribers`` subscriptions matched it."""
        pub = self.node.create_publisher(msg_type, topic, qos)
        self.spin_until(lambda: pub.get_subscription_count() >= subscribers, timeout,
                        f'a subscriber on {topic}')
        return pub

    def handshake(self, pub, msg, heard, timeout=20.0, period=0.5):
        """
        Publish ``msg`` every ``period`` s until ``heard()`` holds; return how many were sent.

        ``publisher()`` returns once our writer has matched the node's reader, but
        discovery is two one-way exchanges: the node's reader may not know our writer
        yet, and a volatile reader loses what it is sent until it does (seen in CI: a
        whole burst of 600 messages lost). So the first message that matters is
        repeated until ``heard`` (a predicate on what the probe received) shows the
        node took it; from then on the pair is matched both ways.
        """
        sent = 0
        deadline = time.monotonic() + timeout
        while not heard():
            if time.monotonic() > deadline:
                raise AssertionError(f'timed out after {timeout} s: {sent} messages on '
                                     f'{pub.topic_name} never reached the node')
            pub.publish(msg)
            sent += 1
            until = min(time.monotonic() + period, deadline)
            while not heard() and time.monotonic() < until:
                self.executor.spin_once(timeout_sec=0.02)
        return sent

    def endpoints(self, kind, node, namespace='/'):
        """
        Return {name: type} of a node's publishers, subscriptions or services on the graph.

        ``kind``: 'pub', 'sub' or 'srv'. Empty until the node is discovered (rclpy
        raises for a node it does not know yet).
        """
        call = {'pub': self.node.get_publisher_names_and_types_by_node,
                'sub': self.node.get_subscriber_names_and_types_by_node,
                'srv': self.node.get_service_names_and_types_by_node}[kind]
        try:
            return {name: types[0] for name, types in call(node, namespace)}
        except _rclpy.NodeNameNonExistentError:
            return {}

    def call(self, srv_type, name, request, timeout=20.0):
        """
        Call a service and return its response.

        One client per service and type, kept: a new client is a new response reader, and
        a server that answers a reader it has not discovered yet drops the response
        (rmw_fastrtps waits 100 ms for the match), which a busy machine can outlast.
        """
        client = self._clients.get((srv_type, name))
        if client is None:
            client = self._clients[srv_type, name] = self.node.create_client(srv_type, name)
        self.spin_until(client.service_is_ready, timeout, f'service {name}')
        future = client.call_async(request)
        self.spin_until(future.done, timeout, f'the response of {name}')
        return future.result()

    def newest_status(self, name):
        """
        Return (level, message, values) of the newest /diagnostics status called ``name``.

        ``name`` is the full status name or its end (e.g. 'torque command');
        None until one arrived. Needs ``subscribe(DiagnosticArray, '/diagnostics')``.
        """
        for array in reversed(self.messages.get('/diagnostics', [])):
            for status in array.status:
                if status.name.endswith(name):
                    return status.level, status.message, status_values(status)
        return None


def listen_tf(tf2_msgs_env, count, odom):
    """
    Run test/tf_listener.py (a process that can import the built tf2_msgs); its JSON report.

    ``count`` /tf and ``odom`` messages: {'tf': [...], 'odom': [...], 'publishers': [...]}.
    """
    import json
    import sys
    listener = subprocess.run(
        [sys.executable, os.path.join(os.path.dirname(__file__), 'tf_listener.py'),
         '--count', str(count), '--odom', odom], env=dict(os.environ, **tf2_msgs_env),
        capture_output=True, text=True, timeout=90)
    assert listener.returncode == 0, listener.stderr[-3000:]
    return json.loads(listener.stdout)
