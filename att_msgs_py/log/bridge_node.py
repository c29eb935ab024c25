"""Bridge node: relays every suite topic live to Foxglove over its WebSocket protocol.

Subscribes in raw (serialized CDR) form to :func:`att_msgs_py.qos.recorded_topics`, like the
recorder, and logs the bytes unchanged, stamped with their receive time, on one ``foxglove-sdk``
channel per topic: ``cdr`` encoding and the ``ros2msg`` schema the recorder writes to the MCAP, so
Foxglove decodes the live view exactly as it decodes a log. The server stops on SIGINT/SIGTERM.

Usage: ``att-bridge --ros-args -p port:=8765``, then in Foxglove: Open connection → Foxglove
WebSocket → ``ws://localhost:8765``.
"""
from __future__ import annotations

import time

import foxglove
from rclpy.node import Node

from att_msgs_py import qos, topics
from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_msgs_py.log.definitions import message_definition
from att_msgs_py.node_runner import parameter_reader, run_node


class BridgeNode(Node):
    def __init__(self):
        super().__init__("bridge")
        param = parameter_reader(self, {})
        host = param("host", "127.0.0.1")
        port = param("port", 8765, 0, 65535)
        param.refuse_unknown()
        self.sinks = foxglove.Context()        # the node's own channels, not the SDK's global ones
        try:
            self.server = foxglove.start_server(name="att_suite", host=host, port=port, context=self.sinks)
        except RuntimeError as exc:                 # the SDK's FoxgloveError: address in use, unknown host
            raise ConfigError(ErrorCode.INVALID_PARAMETER,
                              f"parameters 'host', 'port': cannot serve on {clip(host, 80)}:{port}: "
                              f"{clip(str(exc).removeprefix('FoxgloveError: '), 200)}") from None
        self.channels = {}
        for topic, (type_name, profile) in qos.recorded_topics().items():
            schema = foxglove.Schema(name=type_name, encoding="ros2msg", data=message_definition(type_name).encode())
            self.channels[topic] = foxglove.Channel(topic, schema=schema, message_encoding="cdr", context=self.sinks)
            self.create_subscription(topics.message_class(type_name), topic,
                                     lambda data, t=topic: self.on_message(t, data), profile, raw=True)
        self.get_logger().info(f"serving {len(self.channels)} topics on ws://{host}:{self.server.port} "
                               "(Foxglove: Open connection -> Foxglove WebSocket)")

    def on_message(self, topic: str, data: bytes):
        self.channels[topic].log(data, log_time=time.time_ns())

    def close(self):
        self.server.stop()
        print("bridge: server stopped", flush=True)


def main(args=None):
    run_node(BridgeNode, args)


if __name__ == "__main__":
    main()
