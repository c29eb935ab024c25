"""Bridge node: relays every suite topic live to Foxglove over its WebSocket protocol.

Subscribes in raw (serialized CDR) form to :func:`att_msgs_py.qos.recorded_topics`, like the
recorder, and logs the bytes unchanged, stamped with their receive time, on one ``foxglove-sdk``
channel per topic: ``cdr`` encoding and the ``ros2msg`` schema the recorder writes to the MCAP, so
Foxglove decodes the live view exactly as it decodes a log. A latched topic's kept messages are
sent again when a client subscribes to it (so a client that connects later sees the latest plan).
The server stops on SIGINT/SIGTERM.

Usage: ``att-bridge --ros-args -p port:=8765``, then in Foxglove: Open connection → Foxglove
WebSocket → ``ws://localhost:8765``.
"""
from __future__ import annotations

import threading
import time
from collections import deque

import foxglove
from foxglove.websocket import ServerListener
from rclpy.qos import DurabilityPolicy

from att_msgs_py import memory, qos, topics
from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_msgs_py.log.definitions import message_definition
from att_msgs_py.log.log_parameters import BRIDGE
from att_msgs_py.node_runner import ParameterReader, run_node
from att_msgs_py.suite_node import SuiteNode


class Latch(ServerListener):
    """The last messages of the latched topics, logged again on a channel when a client subscribes
    to it (the SDK cannot send to one client: its other subscribers get them again, harmless for
    plans and marker arrays, which replace). Called from the server's thread: hence the lock."""

    def __init__(self):
        self.kept: dict[str, deque] = {}
        self.channels: dict[int, foxglove.Channel] = {}
        self.lock = threading.Lock()

    def add(self, channel: foxglove.Channel, depth: int) -> None:
        self.kept[channel.topic()] = deque(maxlen=depth)
        self.channels[channel.id()] = channel

    def keep(self, topic: str, data: bytes, log_time: int) -> None:
        if topic in self.kept:
            with self.lock:
                self.kept[topic].append((data, log_time))

    def on_subscribe(self, client, channel) -> None:
        if channel.id in self.channels:
            with self.lock:
                kept = list(self.kept[channel.topic])
            for data, log_time in kept:
                self.channels[channel.id].log(data, log_time=log_time)


class BridgeNode(SuiteNode):
    def __init__(self):
        super().__init__("bridge")
        param = ParameterReader(self, BRIDGE, {})
        host = param("host")
        port = param("port")
        param.refuse_unknown()
        self.sinks = foxglove.Context()        # the node's own channels, not the SDK's global ones
        self.latch = Latch()
        try:
            self.server = foxglove.start_server(name="att_suite", host=host, port=port, context=self.sinks,
                                                server_listener=self.latch)
        except RuntimeError as exc:                 # the SDK's FoxgloveError: address in use, unknown host
            raise ConfigError(ErrorCode.INVALID_PARAMETER,
                              f"parameters 'host', 'port': cannot serve on {clip(host, 80)}:{port}: "
                              f"{clip(str(exc).removeprefix('FoxgloveError: '), 200)}") from None
        self.channels = {}
        for topic, (type_name, profile) in qos.recorded_topics().items():
            schema = foxglove.Schema(name=type_name, encoding="ros2msg", data=message_definition(type_name).encode())
            self.channels[topic] = foxglove.Channel(topic, schema=schema, message_encoding="cdr", context=self.sinks)
            if profile.durability == DurabilityPolicy.TRANSIENT_LOCAL:
                self.latch.add(self.channels[topic], profile.depth)
            self.create_subscription(topics.message_class(type_name), topic,
                                     lambda data, t=topic: self.on_message(t, data), profile, raw=True)
        self.get_logger().info(f"serving {len(self.channels)} topics on ws://{host}:{self.server.port} "
                               "(Foxglove: Open connection -> Foxglove WebSocket)")

    def on_message(self, topic: str, data: bytes):
        now = time.time_ns()
        self.latch.keep(topic, data, now)
        self.channels[topic].log(data, log_time=now)

    def close(self):
        self.server.stop()
        print("bridge: server stopped", flush=True)


def main(args=None):
    memory.reexec_with_c_allocator()
    run_node(BridgeNode, args)


if __name__ == "__main__":
    main()
