"""``att-replay``: the regression log played back onto an isolated domain, and the clock it
builds when a log has none."""
from __future__ import annotations

import random
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from att_msgs_py.log import read_log
from helpers.regression_log import FIXTURE, TOPIC_TYPES

pytestmark = pytest.mark.ros


@pytest.fixture(scope="module")
def log():
    return read_log(FIXTURE)


def test_replay_republishes_the_fixture_with_its_types(log):
    """att-replay as a process on its own domain; a subscriber here receives every message."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    from att_msgs_py.topics import message_class
    from att_planner.tools.launch import isolated_env

    domain = random.randint(1, 200)
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain)
    node = Node("replay_test", context=context)
    received = {t: [] for t in TOPIC_TYPES}
    for topic, type_name in TOPIC_TYPES.items():
        qos = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL if topic == "/planner/plans"
                         else DurabilityPolicy.VOLATILE)
        node.create_subscription(message_class(type_name), topic, received[topic].append, qos)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)

    spinner = threading.Thread(target=spin)
    spinner.start()
    proc = subprocess.Popen([sys.executable, "-m", "att_msgs_py.log.replay", str(FIXTURE), "--rate", "0", "--clock",
                             "--wait", "30"],
                            env=isolated_env(domain), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        out, _ = proc.communicate(timeout=40)
        expected = {t: len(v) for t, v in log.items()}
        deadline = time.monotonic() + 10
        while {t: len(v) for t, v in received.items()} != expected and time.monotonic() < deadline:
            time.sleep(0.1)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        stop.set()
        spinner.join()
        node.destroy_node()
        context.try_shutdown()
    assert proc.returncode == 0, out
    assert {t: len(v) for t, v in received.items()} == expected, out
    for topic, type_name in TOPIC_TYPES.items():
        assert all(isinstance(m, message_class(type_name)) for m in received[topic])
    stamps = [m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in received["/spacecraft/state"]]
    assert np.allclose(stamps, log["/spacecraft/state"]["header.stamp"])       # in order, unchanged
    assert received["/planner/plans"][0].plan_id == log["/planner/plans"]["plan_id"][0]


def test_replay_builds_a_clock_from_log_times_when_the_log_has_none():
    from rclpy.serialization import deserialize_message
    from rosgraph_msgs.msg import Clock

    from att_msgs_py.log.replay import CLOCK, Record, schedule

    records = [Record(1_500_000_000, "/a", b"1"), Record(1_500_000_000, "/b", b"2"),
               Record(2_999_999_999, "/a", b"3")]
    assert schedule(records, clock=False, clock_recorded=False) == records
    assert schedule(records, clock=True, clock_recorded=True) == records
    out = schedule(records, clock=True, clock_recorded=False)
    assert [r.topic for r in out] == [CLOCK, "/a", "/b", CLOCK, "/a"]
    stamps = [deserialize_message(r.data, Clock).clock for r in out if r.topic == CLOCK]
    assert [(s.sec, s.nanosec) for s in stamps] == [(1, 500_000_000), (2, 999_999_999)]
