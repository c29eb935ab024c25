"""Review and replay of recorded runs (issue 8).

The regression log ``test/data/swift_short.mcap`` was recorded by the suite (regenerate it with
``test/data/make_fixture.py`` when the format changes on purpose): a 45° keep-out maneuver of the
swift_demo spacecraft, states and commands at 10 Hz.
"""
from __future__ import annotations

import json
import math
import random
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from att_msgs_py.mcap_log import LogWriter, TopicLog, iter_records, read_log
from att_msgs_py.review import extract_run, main as review_main, settling_time, summarize
from att_planner.cones import Cone, margins
from att_sim import rotations as rot
from att_sim import scenario as scen

FIXTURE = Path(__file__).parent / "data" / "swift_short.mcap"
TOPIC_TYPES = {"/clock": "rosgraph_msgs/msg/Clock", "/spacecraft/state": "att_msgs/msg/SpacecraftState",
               "/actuator/command": "att_msgs/msg/ActuatorCommand", "/controller/status": "att_msgs/msg/ControllerStatus",
               "/planner/plans": "att_msgs/msg/ManeuverPlan"}
STATE_FIELDS = {"header.stamp", "header.frame_id", "body_frame_id", "attitude", "body_rate", "wheel_speeds",
                "wheel_torques", "magnetic_field_body", "dipole", "applied_torque", "position", "command_timeout"}
GOAL = rot.from_axis_angle([0, 1, 0], math.radians(-45))      # the fixture's maneuver (make_fixture.py)


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
    assert FIXTURE.stat().st_size < 300 * 1024
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
    assert types == TOPIC_TYPES
    assert {t: len(v) for t, v in decoded.items()} == {t: len(v) for t, v in log.items()}
    q = np.array([[m.attitude.x, m.attitude.y, m.attitude.z, m.attitude.w] for m in decoded["/spacecraft/state"]])
    assert np.array_equal(q, log["/spacecraft/state"]["attitude"])
    plan = decoded["/planner/plans"][0]
    assert [c.name for c in plan.cones] == ["sun", "earth", "moon"] and len(plan.times) == len(plan.attitudes)


def test_rosbags_decodes_a_log_written_by_the_current_writer(tmp_path, log):
    """Re-record the fixture's messages with today's LogWriter: schemas and layout still rosbag2's."""
    from att_msgs_py.topics import recorded_topics

    out = tmp_path / "rewritten.mcap"
    writer = LogWriter(out)
    for topic, (type_name, qos) in recorded_topics().items():
        writer.add_topic(topic, type_name, qos)
    for _, channel, message in iter_records(FIXTURE):
        writer.write(channel.topic, message.data, message.log_time)
    writer.close()
    decoded, types = rosbags_decode(out)
    assert types == TOPIC_TYPES
    assert {t: len(v) for t, v in decoded.items()} == {t: len(v) for t, v in log.items()}
    again = read_log(out)
    assert np.array_equal(again["/spacecraft/state"]["attitude"], log["/spacecraft/state"]["attitude"])


def test_summary_of_the_fixture_matches_independent_figures(log):
    sc = scen.load("swift_demo").spacecraft
    s = summarize(log, sc)
    state, plans = log["/spacecraft/state"], log["/planner/plans"]
    assert s["kind"] == "maneuver" and s["plan"]["plan_id"] == plans["plan_id"][0]
    assert s["maneuver_time_s"] == pytest.approx(plans["duration"][0])
    assert s["maneuver_time_s"] < s["executed_time_s"] < s["maneuver_time_s"] + 10
    assert s["final_attitude_error_deg"] == pytest.approx(math.degrees(rot.angle_between(state["attitude"][-1], GOAL)))
    assert s["final_attitude_error_deg"] < 0.1
    cones = [Cone(c["direction"], c["half_angle"], c["name"]) for c in plans["cones"][0]]
    m = np.degrees(margins(state["attitude"], [1, 0, 0], cones).min(axis=0))
    assert s["min_margin_deg"] == pytest.approx(dict(zip(["sun", "earth", "moon"], m)), abs=1e-9)
    assert 10 < s["min_margin_deg"]["moon"] < 20 and s["min_cone_margin_deg"] == pytest.approx(m.min())
    assert s["closest_approach_s"]["moon"] > 0.8 * s["maneuver_time_s"]     # the path ends nearest the Moon
    assert s["body_torque_Nm_limit"] == sc.body_torque_max and s["wheel_speed_rad_s_limit"] == sc.wheel_speed_max
    assert 0.5 < s["body_torque_Nm_ratio"] < 1.1 and 0.1 < s["wheel_speed_rad_s_ratio"] < 1.0
    assert s["peak_dipole_Am2"] == 0.0 and s["settling_time_s"] is None
    assert summarize(log)["body_torque_Nm_limit"] is None       # no spacecraft given: no limits invented


def test_settling_time_of_a_magnetorquer_run():
    """Synthetic magnetorquer-PD log: angle θ0 e^(-t/τ) about x; settled once sin(θ/2) ≤ ν = 0.05."""
    t = np.arange(0.0, 600.0, 0.5)
    theta0, tau = math.radians(60), 80.0
    q = rot.from_axis_angle(np.array([1.0, 0.0, 0.0]), theta0 * np.exp(-t / tau))
    n = len(t)
    zeros3 = np.zeros((n, 3))
    log = {
        "/spacecraft/state": TopicLog("/spacecraft/state", TOPIC_TYPES["/spacecraft/state"], t, {
            "header.stamp": t, "attitude": q, "body_rate": zeros3, "wheel_speeds": zeros3, "wheel_torques": zeros3,
            "dipole": np.full((n, 3), 2.0), "applied_torque": zeros3, "command_timeout": np.zeros(n, bool)}),
        "/actuator/command": TopicLog("/actuator/command", TOPIC_TYPES["/actuator/command"], t, {
            "header.stamp": t, "mode": np.r_[np.zeros(10, int), np.ones(n - 10, int)],
            "plan_id": np.full(n, ""), "wheel_torques": zeros3, "dipole": np.full((n, 3), 2.0)}),
    }
    s = summarize(log, scen.load("swift_demo").spacecraft)
    expected = tau * math.log(theta0 / (2 * math.asin(0.05))) - t[10]
    assert s["kind"] == "magnetorquer" and s["settling_time_s"] == pytest.approx(expected, abs=0.5)
    assert s["final_attitude_error_deg"] < 1.0 and s["dipole_Am2_ratio"] == pytest.approx(0.2)
    assert settling_time(t, q[::-1]) is None                       # diverging: never settles


def test_review_cli_writes_figures_html_and_summary(tmp_path, capsys):
    assert review_main([str(FIXTURE), "--out", str(tmp_path)]) == 0
    printed = capsys.readouterr().out
    assert "min margin moon" in printed and f"HTML: {tmp_path / 'index.html'}" in printed
    for name in ("overview", "sky", "time_histories"):
        png = (tmp_path / f"{name}.png").read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    page = (tmp_path / "index.html").read_text()
    assert page.count("data:image/png;base64,") == 3 and "final attitude error" in page
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["kind"] == "maneuver" and summary["plan"]["method"] == "eigenaxis_smooth"
    assert summary["final_attitude_error_deg"] < 0.1 and set(summary["min_margin_deg"]) == {"sun", "earth", "moon"}
    assert review_main([str(FIXTURE), "--out", str(tmp_path), "--plan-id", "nope"]) == 1


def test_review_picks_the_executed_plan_segment(log):
    run = extract_run(log)
    cmd = log["/actuator/command"]
    first = np.flatnonzero(cmd["plan_id"] == run.plan["plan_id"])[0]
    assert run.t0 == cmd["header.stamp"][first] and run.t[0] >= 0 and run.t[-1] > run.plan["duration"]


def test_replay_republishes_the_fixture_with_its_types(log):
    """att-replay as a process on its own domain; a subscriber here receives every message."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    from att_msgs_py.topics import message_class
    from att_planner.launch import isolated_env

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
    proc = subprocess.Popen([sys.executable, "-m", "att_msgs_py.replay", str(FIXTURE), "--rate", "0", "--clock",
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

    from att_msgs_py.replay import CLOCK, Record, schedule

    records = [Record(1_500_000_000, "/a", b"1"), Record(1_500_000_000, "/b", b"2"),
               Record(2_999_999_999, "/a", b"3")]
    assert schedule(records, clock=False, clock_recorded=False) == records
    assert schedule(records, clock=True, clock_recorded=True) == records
    out = schedule(records, clock=True, clock_recorded=False)
    assert [r.topic for r in out] == [CLOCK, "/a", "/b", CLOCK, "/a"]
    stamps = [deserialize_message(r.data, Clock).clock for r in out if r.topic == CLOCK]
    assert [(s.sec, s.nanosec) for s in stamps] == [(1, 500_000_000), (2, 999_999_999)]
