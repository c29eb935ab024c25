"""Recorder node: writes every suite topic to one rosbag2-compatible MCAP file per run.

Subscribes in raw (serialized CDR) form to :func:`att_msgs_py.qos.recorded_topics`, so messages
are stored byte-for-byte as published. The file is flushed at least every ``flush_period`` s (a
killed recorder loses at most that) and finalised (summary and index) on SIGINT/SIGTERM.

Usage: ``att-recorder --ros-args -p output:=runs/demo.mcap``
"""
from __future__ import annotations

import time
from datetime import UTC, datetime

from rclpy.node import Node

from att_msgs_py import qos, topics
from att_msgs_py.log.writer import LogWriter
from att_msgs_py.node_runner import run_node


class RecorderNode(Node):
    def __init__(self):
        super().__init__("recorder")
        stamp = datetime.now(UTC).strftime("%Y%m%d_%H%M%S")
        output = self.declare_parameter("output", f"runs/run_{stamp}.mcap").value
        flush_period = float(self.declare_parameter("flush_period", 0.5).value)
        self.log = LogWriter(output, flush_period=flush_period)
        for topic, (type_name, profile) in qos.recorded_topics().items():
            self.log.add_topic(topic, type_name, profile)
            self.create_subscription(topics.message_class(type_name), topic,
                                     lambda data, t=topic: self.on_message(t, data), profile, raw=True)
        # flush even when nothing arrives, so the file on disk is never more than a period behind
        self.create_timer(flush_period, self.log.flush)
        self.get_logger().info(f"recording {len(self.log.counts)} topics to {output}")

    def on_message(self, topic: str, data: bytes):
        self.log.write(topic, data, time.time_ns())

    def close(self):
        self.log.close()
        counts = ", ".join(f"{t}: {n}" for t, n in self.log.counts.items())
        print(f"recorder: closed {self.log.path} ({counts})", flush=True)


def main(args=None):
    run_node(RecorderNode, args)


if __name__ == "__main__":
    main()
