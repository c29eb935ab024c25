"""The suite's MCAP logs: the regression log read back, decoded by an independent reader
(``rosbags``, from the definitions in the file alone), and re-written by the current writer.

The regression log ``test/data/swift_short.mcap`` was recorded by the suite (regenerate it with
``test/data/make_fixture.py`` when the format changes on purpose): a 45° keep-out maneuver of the
swift_demo spacecraft, states and commands at 10 Hz.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from att_msgs_py.log import LogWriter, iter_records, read_log
from att_sim.models import rotations as rot
from helpers.regression_log import CHANNEL_TYPES, FIXTURE, GOAL, STATE_FIELDS, TOPIC_TYPES


@pytest.fixture(scope="module")
def log():
    return read_log(FIXTURE)


def rosbags_decode(path: Path) -> dict[str, list]:
    """Every message decoded by rosbags from the definitions embedded in the file alone."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        for connection, _, raw in reader.messages():
            out.setdefault(connection.topic, []).append(reader.deserialize(raw, connection.msgtype))
    return out, types


def test_fixture_is_small_and_read_with_expected_topics_and_fields(log):
    assert FIXTURE.stat().st_size < 1024 * 1024     # the sensors and the estimate made it 830 kB (was 210)
    assert {t: log[t].type_name for t in log} == TOPIC_TYPES
    state = log["/spacecraft/state"]
    assert set(state.fields) == STATE_FIELDS
    n = len(state)
    assert n > 500 and state.log_time.shape == (n,) and np.all(np.diff(state.log_time) >= 0)
    assert state["attitude"].shape == (n, 4) and state["wheel_speeds"].shape == (n, 3)
    assert np.allclose(np.linalg.norm(state["attitude"], axis=1), 1.0, atol=1e-9)
    assert np.all(np.diff(state["header.stamp"]) > 0), "sim-time stamps must increase"
    assert set(state["header.frame_id"]) == {"eci"} and set(state["body_frame_id"]) == {"body"}
    cmd = log["/actuator/command"]
    assert {"header.stamp", "mode", "wheel_torques", "dipole", "body_torque", "plan_id"} <= set(cmd.fields)
    assert np.allclose(log["/clock"]["clock"], state["header.stamp"])
    plans = log["/planner/plans"]
    assert len(plans) == 1 and plans["method"][0] == "eigenaxis_smooth" and plans["spacecraft"][0] == "swift_demo"
    k = len(plans["times"][0])
    assert plans["attitudes"][0].shape == (k, 4) and plans["torques"][0].shape == (k, 3)
    assert [c["name"] for c in plans["cones"][0]] == ["sun", "earth", "moon"]
    assert rot.angle_between(plans["attitudes"][0][-1], GOAL) < 1e-6
    assert plans["plan_id"][0] in set(cmd["plan_id"])


def test_rosbags_decodes_every_message_of_a_suite_log(log):
    decoded, types = rosbags_decode(FIXTURE)
    assert types == CHANNEL_TYPES
    assert {t: len(v) for t, v in decoded.items()} == {t: len(v) for t, v in log.items()}
    q = np.array([[m.attitude.x, m.attitude.y, m.attitude.z, m.attitude.w] for m in decoded["/spacecraft/state"]])
    assert np.array_equal(q, log["/spacecraft/state"]["attitude"])
    plan = decoded["/planner/plans"][0]
    assert [c.name for c in plan.cones] == ["sun", "earth", "moon"] and len(plan.times) == len(plan.attitudes)


def test_rosbags_decodes_a_log_written_by_the_current_writer(tmp_path, log):
    """Re-record the fixture's messages with the current LogWriter: schemas and layout still rosbag2's."""
    from att_msgs_py.qos import recorded_topics

    out = tmp_path / "rewritten.mcap"
    writer = LogWriter(out)
    for topic, (type_name, qos) in recorded_topics().items():
        writer.add_topic(topic, type_name, qos)
    for _, channel, message in iter_records(FIXTURE):
        writer.write(channel.topic, message.data, message.log_time)
    writer.close()
    decoded, types = rosbags_decode(out)
    assert types == {topic: type_name for topic, (type_name, _) in recorded_topics().items()}   # the view's too
    assert {t: len(v) for t, v in decoded.items()} == {t: len(v) for t, v in log.items()}
    again = read_log(out)
    assert np.array_equal(again["/spacecraft/state"]["attitude"], log["/spacecraft/state"]["attitude"])


def _log_with(path: Path, schema_name: str, definition: bytes, data: bytes) -> Path:
    """One topic, /controller/status, of the given schema name and text, holding one message."""
    from mcap.writer import Writer

    with open(path, "wb") as fh:
        writer = Writer(fh)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema(schema_name, "ros2msg", definition)
        channel = writer.register_channel("/controller/status", "cdr", schema)
        writer.add_message(channel, log_time=1, data=data, publish_time=1, sequence=7)
        writer.finish()
    return path


@pytest.mark.parametrize("schema_name", ["this/msg/x", "os/msg/Path", "x", "att_msgs/msg/\x1b[2J"])
def test_a_schema_the_reader_cannot_parse_is_refused_in_one_line_without_an_import(tmp_path, schema_name):
    """A schema whose name the ros2msg parser refuses (or whose message then does not decode) is the
    file's fault: read_log answers with one line naming the topic and the schema (escaped), and
    nothing named by the file is imported."""
    import sys

    from att_msgs_py.log.definitions import message_definition
    from att_msgs_py.log.repair import LogFileError, printable

    definition = message_definition("att_msgs/msg/ControllerStatus").encode()
    path = _log_with(tmp_path / "named.mcap", schema_name, definition, b"\x00\x01\x00\x00")
    with pytest.raises(LogFileError) as refused:
        read_log(path)
    message = str(refused.value)
    assert "\n" not in message and "\x1b" not in message, message
    assert "topic '/controller/status'" in message and "does not decode" in message, message
    assert f"'{printable(schema_name)}'" in message, message
    assert "this" not in sys.modules and "os.msg" not in sys.modules


def test_a_message_that_does_not_decode_as_its_schema_is_refused_in_one_line(tmp_path):
    from att_msgs_py.log.definitions import message_definition
    from att_msgs_py.log.repair import LogFileError

    type_name = "att_msgs/msg/ControllerStatus"
    definition = message_definition(type_name).encode()
    path = _log_with(tmp_path / "short.mcap", type_name, definition, b"\x00\x01\x00\x00\x07")
    with pytest.raises(LogFileError, match=r"message 7 of topic '/controller/status' does not decode as "
                                           r"'att_msgs/msg/ControllerStatus' \(") as refused:
        read_log(path)
    assert "\n" not in str(refused.value)
