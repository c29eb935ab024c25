"""The one ``main()`` body of every suite node: init, spin until SIGINT/SIGTERM, clean up.

Stopping is done by rclpy alone. Its signal handler wakes the executors, then shuts the context
down, from its own thread. An executor woken before the shutdown can start a new wait that nothing
wakes again, so nodes spin with :func:`spin_until_shutdown`, whose waits are bounded, instead of
``executor.spin()`` (the planner hung this way in most runs).

Python's own SIGINT handler would also raise ``KeyboardInterrupt`` a moment later, at whatever
line runs then: a ``publish`` already failing on the dead context, or the recorder's ``close()``.
It is replaced by a handler that only notes the signal, which matters when the signal comes
before ``rclpy.init`` has installed rclpy's handler: the node then stops right after init.

An error raised after the context is shut down is the stop itself, not a fault. The node's
``close()`` (e.g. the recorder finalising its log) then runs before the node is destroyed, and the
process exits 0.
"""
from __future__ import annotations

import signal
from collections.abc import Callable

import rclpy
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor

_stop_signalled = False


def _stop_requested(_signum, _frame) -> None:
    """Python-level handler that rclpy's SIGINT/SIGTERM handler chains to. After ``rclpy.init``
    rclpy has already shut the context down; before it, only this flag knows."""
    global _stop_signalled
    _stop_signalled = True


def spin_until_shutdown(executor: Executor, poll: float = 0.2) -> None:
    """``executor.spin()`` that re-checks the context at least every ``poll`` s (see above)."""
    while executor.context.ok():
        executor.spin_once(timeout_sec=poll)


def parameter_reader(node, scenario_values: dict) -> Callable:
    """``read(name, default)`` for a node: declares ROS parameter ``name`` with the value of its
    scenario-file section (``scenario_values``) or else ``default``, and returns the parameter's
    value, so ``-p`` and ``--params-file`` overrides win over both."""
    def read(name: str, default):
        return node.declare_parameter(name, scenario_values.get(name, default)).value
    return read


def run_node(make_node: Callable, args=None, make_executor: Callable[[], Executor] = SingleThreadedExecutor,
             loop: Callable | None = None) -> None:
    """Create node and executor after ``rclpy.init`` and run ``loop(node, executor)`` (default:
    :func:`spin_until_shutdown`)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _stop_requested)      # before rclpy.init, which chains to it
    rclpy.init(args=args)
    node = None
    try:
        if _stop_signalled:
            return
        node = make_node()
        executor = make_executor()
        executor.add_node(node)
        if loop is None:
            spin_until_shutdown(executor)
        else:
            loop(node, executor)
    except ExternalShutdownException:
        pass
    except Exception:
        if rclpy.ok():
            raise
    finally:
        if node is not None:
            if hasattr(node, "close"):
                node.close()
            node.destroy_node()
        rclpy.try_shutdown()
