"""
High-rate message intake without one executor callback per message.

An executor wakes, builds its wait set and calls one Python callback per
message: at 1 kHz of Odometry that alone is about a quarter of a core here.
``Intake`` keeps its subscriptions on a hidden helper node (``_<node>_intake``,
same namespace and context) that no executor spins, so nothing takes their
messages but :meth:`Intake.take`, which drains everything pending in one go.
The owner calls it from a timer (the analyzer: every 100 ms), or blocks in
:meth:`Intake.wait` until a message is pending (the simulator's lockstep
thread: no executor hop between the controller's answer and the next step).
Messages are taken serialised (``raw``), for :mod:`rigid_body_dynamics.messages.cdr`
to read in a batch or ``deserialize_message`` one by one. rclpy has no public
take() or wait set; these are the calls its executor makes
(``handle.take_message`` inside ``with handle``, ``_rclpy.WaitSet``), in
one tested place.
"""

import contextlib
import copy

import rclpy
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.qos_overriding_options import _declare_qos_parameters, QoSOverridingOptions
from rclpy.subscription import Subscription


class Intake:
    """Subscriptions of ``node`` whose messages are taken in batches, not by callbacks."""

    def __init__(self, node):
        self.node = rclpy.create_node(f'_{node.get_name()}_intake',
                                      namespace=node.get_namespace(), context=node.context,
                                      start_parameter_services=False)
        self._owner = node
        self._subs = {}
        self._waits = {}

    def subscribe(self, msg_type, topic, qos, overridable=False):
        """
        Subscribe ``topic`` (relative names resolve in the owner's namespace).

        ``overridable``: declare the owner's ``qos_overrides.<topic>.subscription.*``
        parameters (history, depth, reliability), as a subscription created with
        QoSOverridingOptions.with_default_policies() would, and use them.
        """
        if overridable:
            qos = copy.copy(qos)
            _declare_qos_parameters(Subscription, self._owner, self.node.resolve_topic_name(topic),
                                    qos, QoSOverridingOptions.with_default_policies())
        self._subs[topic] = self.node.create_subscription(
            msg_type, topic, lambda _msg: None, qos, raw=True)

    def wait(self, topics, timeout):
        """
        Block until a message is pending on one of ``topics`` or ``timeout`` s pass.

        ``topics``: a topic name or a tuple of them. Returns whether one is pending.
        """
        topics = (topics,) if isinstance(topics, str) else tuple(topics)
        subs = [self._subs[t] for t in topics]
        context = self.node.context
        with contextlib.ExitStack() as stack:
            for sub in subs:
                stack.enter_context(sub.handle)
            stack.enter_context(context.handle)
            waits = self._waits.get(topics)
            if waits is None:
                waits = _rclpy.WaitSet(len(subs), 0, 0, 0, 0, 0, context.handle)
                self._waits[topics] = waits
            waits.clear_entities()
            for sub in subs:
                waits.add_subscription(sub.handle)
            waits.wait(max(0, int(timeout * 1e9)))
            return bool(waits.get_ready_entities('subscription'))

    def take(self, topic, limit=100_000, received=None):
        """
        Return the serialised messages pending on ``topic``, oldest first, at most ``limit``.

        ``received``: a list to which each message's receive time is appended
        (int ns, system clock, as the middleware stamps it; 0 where it does not).
        """
        sub = self._subs[topic]
        out = []
        with sub.handle:
            for _ in range(limit):
                taken = sub.handle.take_message(sub.msg_type, True)
                if taken is None:
                    break
                out.append(taken[0])
                if received is not None:
                    received.append(taken[1]['received_timestamp'])
        return out

    def destroy(self):
        """Destroy the helper node (before the owner's context shuts down)."""
        self.node.destroy_node()
