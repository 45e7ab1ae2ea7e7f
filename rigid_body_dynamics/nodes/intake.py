"""
High-rate message intake without one executor callback per message.

An executor wakes, builds its wait set and calls one Python callback per
message: at 1 kHz of Odometry that alone is about a quarter of a core here.
``Intake`` keeps its subscriptions on a hidden helper node (``_<node>_intake``,
same namespace and context) that no executor spins, so nothing takes their
messages but :meth:`Intake.take`, which drains everything pending in one go.
The owner calls it from a timer (the analyzer: every 10 ms). Messages are
taken serialised (``raw``), for :mod:`rigid_body_dynamics.cdr` to read in a
batch. rclpy has no public take(); this is the call its executor makes
(``handle.take_message`` inside ``with handle``), in one tested place.
"""

import rclpy


class Intake:
    """Subscriptions of ``node`` whose messages are taken in batches, not by callbacks."""

    def __init__(self, node):
        self.node = rclpy.create_node(f'_{node.get_name()}_intake',
                                      namespace=node.get_namespace(), context=node.context,
                                      start_parameter_services=False)
        self._subs = {}

    def subscribe(self, msg_type, topic, qos):
        """Subscribe ``topic`` (relative names resolve in the owner's namespace)."""
        self._subs[topic] = self.node.create_subscription(
            msg_type, topic, lambda _msg: None, qos, raw=True)

    def take(self, topic, limit=100_000):
        """Return the serialised messages pending on ``topic``, oldest first, at most ``limit``."""
        sub = self._subs[topic]
        out = []
        with sub.handle:
            for _ in range(limit):
                taken = sub.handle.take_message(sub.msg_type, True)
                if taken is None:
                    break
                out.append(taken[0])
        return out

    def destroy(self):
        """Destroy the helper node (before the owner's context shuts down)."""
        self.node.destroy_node()
