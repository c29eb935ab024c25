"""Watchdogs over ROS: a stopped controller and a stopped simulator are each noticed by the other
side. The test stops nodes, so its suite is its own (any order of the other modules holds)."""
from __future__ import annotations

import signal
import time

import pytest
import rclpy

from att_msgs.msg import ControllerStatus, SpacecraftState
from att_msgs_py import qos, topics

pytestmark = pytest.mark.ros


@pytest.fixture(scope="module")
def suite(ros_suite):
    with ros_suite("swift_demo", nodes=("simulator", "controller"),
                   params={"simulator": {"real_time_factor": 4.0}, "controller": {"state_source": "truth"}},
                   name="watchdog_test") as s:
        yield s.suite, s.client


def wait_for(client, predicate, messages, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        rclpy.spin_once(client, timeout_sec=0.05)
        if any(predicate(m) for m in messages):
            return True
    return False


def test_watchdogs_report_silence(suite):
    """The simulator zeroes its inputs when the controller stops, and the controller reports stale
    states when the simulator stops (it stops both: the suite is this module's alone)."""
    s, client = suite
    states, statuses = [], []
    client.create_subscription(SpacecraftState, topics.STATE, states.append, qos.STREAM_QOS)
    client.create_subscription(ControllerStatus, topics.CONTROLLER_STATUS, statuses.append, qos.STREAM_QOS)
    controller = s.procs["controller"]
    controller.send_signal(signal.SIGSTOP)          # commands stop arriving
    try:
        assert wait_for(client, lambda m: m.command_timeout, states, 60), "simulator did not zero its inputs"
    finally:
        controller.send_signal(signal.SIGCONT)
    s.procs["simulator"].send_signal(signal.SIGINT)  # states stop arriving
    s.procs["simulator"].wait(10)
    statuses.clear()
    assert wait_for(client, lambda m: m.state_stale, statuses, 60), "controller did not report stale state"
