"""The one ``main()`` body of every suite node: init, spin until SIGINT/SIGTERM, clean up.

``rclpy.init`` installs the SIGINT/SIGTERM handlers; either signal ends the spin with
``KeyboardInterrupt`` or ``ExternalShutdownException``, after which the node's ``close()`` (if it
has one, e.g. the recorder finalising its log) runs before the node is destroyed.
"""
from __future__ import annotations

from typing import Callable

import rclpy
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor


def run_node(make_node: Callable, args=None, make_executor: Callable[[], Executor] = SingleThreadedExecutor,
             loop: Callable | None = None) -> None:
    """Create node and executor after ``rclpy.init`` and run ``loop(node, executor)`` (default: spin)."""
    rclpy.init(args=args)
    node = make_node()
    executor = make_executor()
    executor.add_node(node)
    try:
        (loop or (lambda _node, ex: ex.spin()))(node, executor)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if hasattr(node, "close"):
            node.close()
        node.destroy_node()
        rclpy.try_shutdown()
