"""A recorder stopped right after a burst: every message its subscription acknowledged is in the file.

The publisher waits until the recorder's reader acknowledged the whole burst (the reliable QoS's own
handshake), and the recorder is sent SIGINT at once: what the middleware acknowledged but the node had
not yet written must still be written before the file is finalised."""
from __future__ import annotations

import os
import signal
import time

import pytest
import rclpy
from rclpy.duration import Duration
from rosgraph_msgs.msg import Clock

from att_msgs_py import qos, topics
from att_msgs_py.log import read_log
from att_planner.tools.launch import Suite, isolated_env

pytestmark = pytest.mark.ros
BURST = 900                   # below the recorder's queue depth (1000): KEEP_LAST never overwrites one


def test_a_recorder_stopped_right_after_a_burst_writes_every_acknowledged_message(tmp_path):
    path = tmp_path / "burst.mcap"
    rclpy.init()
    node = rclpy.create_node("burst_publisher")
    try:
        with Suite(isolated_env(int(os.environ["ROS_DOMAIN_ID"])), tmp_path / "logs") as suite:
            recorder = suite.start("recorder", {"output": str(path)})
            assert suite.wait_for_output("recorder", "recording", 30), suite.log_text("recorder")
            publisher = node.create_publisher(Clock, topics.CLOCK, qos.CLOCK_QOS)
            deadline = time.monotonic() + 30
            while publisher.get_subscription_count() < 1:
                assert time.monotonic() < deadline, "the recorder's /clock subscription was never matched"
                rclpy.spin_once(node, timeout_sec=0.05)
            for i in range(BURST):
                msg = Clock()
                msg.clock.sec, msg.clock.nanosec = i, 1
                publisher.publish(msg)
            assert publisher.wait_for_all_acked(Duration(seconds=30))
            recorder.send_signal(signal.SIGINT)
            assert recorder.wait(30) == 0, suite.log_text("recorder")
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    log = read_log(path, topics=[topics.CLOCK])
    stamps = sorted(int(s) for s in log[topics.CLOCK]["clock"])
    assert stamps == list(range(BURST)), f"{BURST - len(stamps)} acknowledged messages not in the file"
