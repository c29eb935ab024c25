"""The live view: ``att-bridge`` beside a running simulator, a Foxglove WebSocket client connected to
it (``websockets``, not the SDK: the protocol as Foxglove speaks it), every suite topic advertised
with the log's schema, and the states received, decoded both from the advertised schema text (as
Foxglove decodes them) and by rclpy; a latched plan path published before the client connected is
sent on subscription. A second bridge on the same port stops with one line."""
from __future__ import annotations

import json
import math
import socket
import struct
import subprocess
import sys
import time

import pytest
import rclpy
from mcap.records import Schema
from mcap_ros2.decoder import DecoderFactory
from rclpy.duration import Duration
from rclpy.serialization import deserialize_message
from visualization_msgs.msg import Marker, MarkerArray
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from att_msgs.msg import SpacecraftState
from att_msgs_py import qos, topics
from att_msgs_py.log.definitions import message_definition
from att_planner.tools.launch import NODE_MODULES, isolated_env

pytestmark = pytest.mark.ros

SUBPROTOCOL = "foxglove.sdk.v1"      # the Foxglove WebSocket protocol as foxglove-sdk names it (was .websocket.v1)
MESSAGE_DATA = 1                     # binary opcode: uint32 subscription id, uint64 timestamp (ns), payload


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def advertised(ws, timeout: float = 10.0) -> tuple[dict, dict]:
    """The ``serverInfo`` and every channel advertised (topic -> channel) until all suite topics are."""
    info, channels = None, {}
    end = time.monotonic() + timeout
    while (info is None or set(channels) < set(topics.RECORDED)) and time.monotonic() < end:
        msg = json.loads(ws.recv(timeout=end - time.monotonic()))
        if msg["op"] == "serverInfo":
            info = msg
        elif msg["op"] == "advertise":
            channels.update({c["topic"]: c for c in msg["channels"]})
    return info, channels


def message_data(ws, counts: dict[int, int], timeout: float = 10.0) -> dict[int, list[tuple[int, bytes]]]:
    """subscription id -> (timestamp, payload) of its first message-data frames, until each has ``counts``."""
    out = {sub: [] for sub in counts}
    end = time.monotonic() + timeout
    while any(len(out[k]) < n for k, n in counts.items()) and time.monotonic() < end:
        try:
            frame = ws.recv(timeout=max(0.0, end - time.monotonic()))
        except TimeoutError:
            break
        if isinstance(frame, bytes) and frame[0] == MESSAGE_DATA:
            sub, stamp = struct.unpack_from("<IQ", frame, 1)
            out.setdefault(sub, []).append((stamp, frame[13:]))
    return out


def publish_latched_path(client) -> None:
    """A plan path on the latched topic, received by the bridge before any Foxglove client connects."""
    pub = client.create_publisher(MarkerArray, topics.PLAN_MARKERS, qos.LATCHED_QOS)
    pub.publish(MarkerArray(markers=[Marker(ns="live_test_path", id=3)]))
    end = time.monotonic() + 10
    while pub.get_subscription_count() < 1 and time.monotonic() < end:
        rclpy.spin_once(client, timeout_sec=0.05)
    assert pub.get_subscription_count() == 1, "the bridge did not subscribe to the plan path"
    # reliable QoS: acknowledged once the bridge's reader holds the path (before any Foxglove client connects)
    assert pub.wait_for_all_acked(Duration(seconds=10)), "the bridge did not acknowledge the plan path"


def test_a_foxglove_client_receives_the_suite_live(ros_suite):
    port = free_port()
    with ros_suite("swift_demo", nodes=("simulator", "bridge"), params={"bridge": {"port": port}},
                   name="live_bridge") as s:
        assert s.suite.wait_for_output("bridge", f"ws://127.0.0.1:{port}", 20), s.suite.log_text("bridge")
        publish_latched_path(s.client)
        url = f"ws://127.0.0.1:{port}"
        with pytest.raises(InvalidStatus):       # the old subprotocol alone is refused (HTTP 400)
            connect(url, subprotocols=["foxglove.websocket.v1"], open_timeout=5).close()
        with connect(url, subprotocols=[SUBPROTOCOL], open_timeout=5) as ws:
            assert ws.subprotocol == SUBPROTOCOL
            info, channels = advertised(ws)
            assert info is not None and info["name"] == "att_suite"
            assert set(channels) == set(topics.RECORDED)
            for topic, type_name in topics.RECORDED.items():
                c = channels[topic]
                assert (c["encoding"], c["schemaEncoding"], c["schemaName"]) == ("cdr", "ros2msg", type_name)
                assert c["schema"] == message_definition(type_name), topic
            state, path = channels[topics.STATE], channels[topics.PLAN_MARKERS]
            ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": state["id"]},
                                                                      {"id": 8, "channelId": path["id"]}]}))
            received = message_data(ws, {7: 5, 8: 1})
            frames = received[7]
        bridge_again = subprocess.run([sys.executable, "-m", NODE_MODULES["bridge"], "--ros-args", "-p",
                                       f"port:={port}"], env=isolated_env(), capture_output=True, text=True,
                                      timeout=30)
        codes = s.stop()
    assert len(frames) == 5, f"{len(frames)} states in 10 s"
    assert [deserialize_message(p, MarkerArray).markers[0].ns for _, p in received[8]] == ["live_test_path"], \
        "the latched path was not sent on subscription"
    decode = DecoderFactory().decoder_for("cdr", Schema(id=1, name=state["schemaName"], encoding="ros2msg",
                                                        data=state["schema"].encode()))
    stamps = []
    for log_time, payload in frames:
        msg = deserialize_message(payload, SpacecraftState)
        dyn = decode(payload)
        assert msg.header.frame_id == dyn.header.frame_id == "eci"
        assert abs(log_time - time.time_ns()) < 60e9                  # the bridge's receive time (wall clock)
        q = (msg.attitude.x, msg.attitude.y, msg.attitude.z, msg.attitude.w)
        assert math.isclose(math.hypot(*q), 1.0, abs_tol=1e-6) and q[3] == dyn.attitude.w
        stamps.append(msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec)
    assert stamps == sorted(stamps) and 0.0 <= stamps[0] < 3600.0 and stamps[-1] > stamps[0]   # sim time, advancing
    assert bridge_again.returncode == 2 and "Traceback" not in bridge_again.stderr, bridge_again.stderr
    lines = bridge_again.stderr.strip().splitlines()
    assert len(lines) == 1 and "INVALID_PARAMETER" in lines[0] and "in use" in lines[0], lines
    assert codes["bridge"] == 0 and "server stopped" in s.suite.log_text("bridge"), s.suite.log_text("bridge")
    with pytest.raises(OSError):
        connect(url, subprotocols=[SUBPROTOCOL], open_timeout=2)
