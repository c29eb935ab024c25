"""SuiteNode: its publishers and subscriptions carry no QoS event handler unless one is asked for, so
the executor's wait set holds only the node's own entities; messages still flow; every node the suite
starts on a wait-set executor is one."""
from __future__ import annotations

import time

import pytest
import rclpy
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64

from att_msgs_py.suite_node import SuiteNode

pytestmark = pytest.mark.ros


@pytest.fixture
def context():
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    yield ctx
    rclpy.shutdown(context=ctx)


def test_no_event_handlers_by_default_and_messages_still_flow(context):
    node, plain = SuiteNode("suite_node_test", context=context), Node("plain_node_test", context=context)
    got = []
    sub = node.create_subscription(Float64, "suite_node_test", got.append, 10)
    pub = node.create_publisher(Float64, "suite_node_test", 10)
    assert sub.event_handlers == [] and pub.event_handlers == []
    plain.create_subscription(Float64, "suite_node_test", lambda m: None, 10)
    plain.create_publisher(Float64, "suite_node_test", 10)
    # the plain node's two entities bring their default handlers; the suite node's bring none
    assert len(list(plain.waitables)) >= len(list(node.waitables)) + 2
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    end = time.monotonic() + 10.0
    while not got and time.monotonic() < end:
        pub.publish(Float64(data=2.5))
        executor.spin_once(timeout_sec=0.05)
    assert got and got[0].data == 2.5
    executor.shutdown()
    node.destroy_node()
    plain.destroy_node()


def test_event_callbacks_given_are_kept(context):
    node = SuiteNode("suite_node_events", context=context)
    pub = node.create_publisher(Float64, "suite_node_events", 10,
                                event_callbacks=PublisherEventCallbacks(incompatible_qos=lambda e: None))
    sub = node.create_subscription(Float64, "suite_node_events", lambda m: None, 10,
                                   event_callbacks=SubscriptionEventCallbacks(incompatible_qos=lambda e: None))
    assert len(pub.event_handlers) >= 1 and len(sub.event_handlers) >= 1
    node.destroy_node()


def test_every_node_on_a_wait_set_executor_is_a_suite_node():
    import importlib
    import inspect

    from att_planner.tools.launch import NODE_MODULES

    # the recorder spins on rclpy's events executor, which rebuilds no wait set: it keeps rclpy's defaults
    for name, module in NODE_MODULES.items():
        if name == "recorder":
            continue
        classes = [c for _, c in inspect.getmembers(importlib.import_module(module), inspect.isclass)
                   if issubclass(c, Node) and c.__module__ == module]
        assert classes and all(issubclass(c, SuiteNode) for c in classes), (name, classes)
