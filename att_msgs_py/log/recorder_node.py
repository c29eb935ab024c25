"""Recorder node: writes every suite topic to one rosbag2-compatible MCAP file per run.

Subscribes in raw (serialized CDR) form to :func:`att_msgs_py.qos.recorded_topics`, so messages
are stored byte-for-byte as published. The file is flushed at least every ``flush_period_s`` s (a
killed recorder loses at most that) and finalised (summary and index) on SIGINT/SIGTERM, once what
its subscriptions already hold is written (:func:`drain`). A file left at ``output`` by a recorder
that did not finish is first repaired to ``OUT.repaired.mcap`` (``att-log repair``), and a complete
log there is moved to ``OUT.previous.mcap`` (each ``.N.mcap`` when the name is taken), so starting
again on the same path, as often as it happens, loses nothing. A file there that is not an MCAP log,
or a leftover that cannot be repaired, stops the node (exit 2) and is left as it is.

Spun by rclpy's events executor: the recorder listens to every topic, and the default executor's
per-message wait-set rebuild made it the busiest process of a fast run.

Usage: ``att-recorder --ros-args -p output:=runs/demo.mcap``
"""
from __future__ import annotations

import os
import time
from datetime import UTC, datetime
from pathlib import Path

from rclpy.experimental import EventsExecutor
from rclpy.node import Node

from att_msgs_py import memory, qos, topics
from att_msgs_py.errors import ConfigError, ErrorCode
from att_msgs_py.log.log_parameters import RECORDER
from att_msgs_py.log.repair import LogFileError, NotMcapError, Scan, repair, scan_records, unused_output
from att_msgs_py.log.writer import LogWriter
from att_msgs_py.node_runner import ParameterReader, run_node


class RecorderNode(Node):
    def __init__(self):
        super().__init__("recorder")
        stamp = datetime.now(UTC).strftime("%Y%m%d_%H%M%S")
        param = ParameterReader(self, RECORDER, {})
        output = param("output", f"runs/run_{stamp}.mcap")
        flush_period = param("flush_period_s")
        param.refuse_unknown()
        try:
            if Path(output).is_file():
                self.keep_leftover(Path(output))
            self.log = LogWriter(output, flush_period=flush_period)
        except OSError as err:              # a directory, a path under a file, no permission, a full disk
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"output: {output} cannot be written "
                                                        f"({err.strerror or err})") from None
        for topic, (type_name, profile) in qos.recorded_topics().items():
            self.log.add_topic(topic, type_name, profile)
            self.create_subscription(topics.message_class(type_name), topic,
                                     lambda data, t=topic: self.on_message(t, data), profile, raw=True)
        # flush even when nothing arrives, so the file on disk is never more than a period behind
        self.create_timer(flush_period, self.log.flush)
        self.get_logger().info(f"recording {len(self.log.counts)} topics to {output}")

    def keep_leftover(self, path: Path) -> None:
        """Keep what a file already at ``path`` holds before it is recorded over: a complete log is
        moved aside to ``OUT.previous.mcap`` and an unfinished one repaired aside to
        ``OUT.repaired.mcap`` (each ``.N`` when the name is taken); a file that holds no message is
        recorded over (logged); a file that is not an MCAP log, or an unfinished log that cannot be
        repaired, stops the node (:class:`ConfigError`) and is left as it is."""
        def refuse(why: str) -> ConfigError:
            return ConfigError(ErrorCode.INVALID_CONFIG, f"output: {path} {why}; it is left as it is: move it or "
                                                         "choose another output")

        scan = Scan(path, 0)
        try:
            for _ in scan_records(path, scan):
                pass
        except NotMcapError:
            raise refuse("is a file that is not an MCAP log") from None
        except LogFileError as err:                 # empty, or cut inside the magic: nothing was recorded
            self.get_logger().warning(f"recording over {path}: {err}")
            return
        if scan.complete and scan.messages:
            aside = unused_output(path, "previous")
            os.replace(path, aside)
            self.get_logger().warning(f"{path} holds a complete log ({scan.messages} messages): kept as {aside}")
            return
        if scan.messages == 0:
            self.get_logger().warning(f"recording over {path}: it holds no message ({scan.problem})")
            return
        try:
            done = repair(path, unused_output(path))
        except LogFileError as err:
            raise refuse(f"holds an unfinished log that could not be repaired aside ({err})") from None
        self.get_logger().warning(f"{path} was left unfinished ({scan.problem}): repaired into {done.output} "
                                  f"({done.result.messages} messages) before recording over it")

    def on_message(self, topic: str, data: bytes):
        self.log.write(topic, data, time.time_ns())

    def close(self):
        self.log.close()
        counts = ", ".join(f"{t}: {n}" for t, n in self.log.counts.items())
        print(f"recorder: closed {self.log.path} ({counts})", flush=True)


def drain(node: RecorderNode, executor, quiet_s: float = 0.2, limit_s: float = 5.0) -> None:
    """Write what the subscriptions already hold before the file is finalised: spin until no message
    arrived for ``quiet_s`` s (at most ``limit_s``). A reliable publisher's message is acknowledged once
    it is in the reader's queue, before the node takes it; a recorder stopped right after its publisher
    saw the acknowledgement would otherwise close without it."""
    end = time.monotonic() + limit_s
    written, quiet_since = sum(node.log.counts.values()), time.monotonic()
    while time.monotonic() < end and time.monotonic() - quiet_since < quiet_s and executor.context.ok():
        executor.spin_once(timeout_sec=0.05)
        now = sum(node.log.counts.values())
        if now != written:
            written, quiet_since = now, time.monotonic()


def main(args=None):
    memory.reexec_with_c_allocator()
    # rclpy's events executor (C++): each message costs a callback, not a Python rebuild of the wait set
    # over every recorded topic; it serves raw subscriptions, timers and the parameter services
    run_node(RecorderNode, args, make_executor=EventsExecutor, drain=drain)


if __name__ == "__main__":
    main()
