"""The base of every suite node spun by one of rclpy's wait-set executors (single- or multi-threaded):
an rclpy ``Node`` whose publishers and subscriptions carry no QoS event handlers unless a caller asks
for some.

rclpy gives every publisher and subscription, by default, two event handlers (incompatible QoS and
incompatible type), each of which only logs a warning. Both are waitables: a wait-set executor
rebuilds its wait set before every wait, visiting each one, so they are most of a flight node's
entities (14 of the 26 the estimator's executor visits) and cost it some 4 µs each per message it
takes. A QoS or type mismatch with a suite topic is still reported: by the other side's handler (a
user's rclpy node keeps its defaults), and the suite's QoS of each topic is on its node's page.

>>> import rclpy
>>> from std_msgs.msg import Float64
>>> _ = rclpy.init()
>>> node = SuiteNode("example")
>>> pub = node.create_publisher(Float64, "x", 10)
>>> len(pub.event_handlers)
0
>>> node.destroy_node(); rclpy.shutdown()
"""
from __future__ import annotations

from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node


class SuiteNode(Node):
    """``rclpy.node.Node`` with ``event_callbacks`` defaulting to none (module docstring); a caller's
    own ``event_callbacks`` are used as given."""

    def create_publisher(self, *args, event_callbacks: PublisherEventCallbacks | None = None, **kwargs):
        return super().create_publisher(
            *args, event_callbacks=event_callbacks or PublisherEventCallbacks(use_default_callbacks=False), **kwargs)

    def create_subscription(self, *args, event_callbacks: SubscriptionEventCallbacks | None = None, **kwargs):
        return super().create_subscription(
            *args, event_callbacks=event_callbacks or SubscriptionEventCallbacks(use_default_callbacks=False),
            **kwargs)
