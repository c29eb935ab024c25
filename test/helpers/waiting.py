"""Waits on a condition with a deadline that fails the test by name: what a test synchronises on
is an event it can observe, never a fixed time."""
from __future__ import annotations

import time
from collections.abc import Callable

import pytest

POLL_PERIOD = 0.05      # s between two looks at the condition


def wait_until(condition: Callable[[], object], timeout: float, what: str, *, node=None,
               period: float = POLL_PERIOD) -> None:
    """Return as soon as ``condition()`` is true; fail the test with ``what`` after ``timeout`` s.

    Between two looks, ``node`` (an rclpy node, when given) is spun once so that its callbacks
    collect the messages the condition reads; otherwise the thread sleeps ``period``.
    """
    end = time.monotonic() + timeout
    while not condition():
        if time.monotonic() >= end:
            pytest.fail(f"{what}: not within {timeout:g} s", pytrace=False)
        if node is None:
            time.sleep(period)      # wait-ok: the poll period of a wait on a condition
        else:
            import rclpy

            rclpy.spin_once(node, timeout_sec=period)
