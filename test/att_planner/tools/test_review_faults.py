"""The faults of a recorded run (att_planner.tools.review.faults): injections, detections paired with
their onset for the latency, the re-plans flown after the first detection, the marks drawn on the
time histories and the maneuver the recovery re-planned."""
from __future__ import annotations

import numpy as np
import pytest

from att_msgs_py.log import TopicLog
from att_msgs_py.topics import CONTROLLER_FAULTS, SIM_FAULTS
from att_planner.tools.review.faults import COLORS, faults_of, faults_summary, interrupted_plan, marks
from att_planner.tools.review.summary import fault_lines


def topic(name: str, **fields) -> TopicLog:
    n = len(next(iter(fields.values())))
    return TopicLog(name, "", np.arange(n, dtype=float), {k: np.asarray(v) for k, v in fields.items()})


LOG = {
    SIM_FAULTS: topic(SIM_FAULTS, **{"header.stamp": [40.0, 70.0], "component": ["wheel", "gyro"], "index": [2, 1],
                                     "kind": ["seized", "stuck"], "source": ["service", "scenario"]}),
    CONTROLLER_FAULTS: topic(CONTROLLER_FAULTS, **{
        "header.stamp": [41.5, 90.0], "detected_at": [41.5, 41.5], "fault_id": ["wheel_torque", "wheel_torque"],
        "component": ["wheel", "wheel"], "index": [2, 2], "detector": ["wheel_torque"] * 2,
        "evidence": ["0.04 N m not delivered", "cleared"], "response": ["exclude_wheel"] * 2,
        "active": [True, False]}),
}
CMD_T = np.array([10.0, 30.0, 41.0, 42.0, 60.0, 61.0])
CMD_PLAN = np.array(["", "a", "a", "", "b", "b"])


def test_each_detection_is_paired_with_its_onset_and_the_re_plans_follow_the_first():
    f = faults_of(LOG, CMD_T, CMD_PLAN)
    assert [(i["t"], i["component"], i["index"], i["kind"]) for i in f.injected] == [(40.0, "wheel", 2, "seized"),
                                                                                     (70.0, "gyro", 1, "stuck")]
    first, cleared = f.detected
    assert first["latency_s"] == pytest.approx(1.5) and first["response"] == "exclude_wheel"
    assert cleared["t"] == 90.0 and not cleared["active"] and cleared["latency_s"] is None
    assert f.replans == [{"t": 60.0, "plan_id": "b"}]
    assert interrupted_plan(f, CMD_T, CMD_PLAN) == "a"
    assert faults_summary(f)["replans"] == ["b"]


def test_the_marks_are_times_from_the_segment_start_with_their_colour():
    drawn = marks(faults_of(LOG, CMD_T, CMD_PLAN), 30.0)
    assert [(t, c) for t, _, c in drawn] == [(10.0, COLORS["injected"]), (40.0, COLORS["injected"]),
                                             (11.5, COLORS["detected"]), (60.0, COLORS["cleared"]),
                                             (30.0, COLORS["replan"])]
    assert drawn[2][1] == "detected: wheel_torque on wheel 2 -> exclude_wheel"
    assert marks(None, 0.0) == []


def test_a_log_without_faults_has_none_and_a_fault_without_a_detection_no_re_plan():
    assert faults_of({}, CMD_T, CMD_PLAN) is None
    only = faults_of({SIM_FAULTS: LOG[SIM_FAULTS]}, CMD_T, CMD_PLAN)
    assert only.detected == [] and only.replans == [] and interrupted_plan(only, CMD_T, CMD_PLAN) is None
    lines = fault_lines(faults_summary(faults_of(LOG, CMD_T, CMD_PLAN)))
    assert lines[0].startswith("fault injected        wheel 2 seized at t = 40.00 s")
    assert "1.50 s after the onset" in lines[2] and "response exclude_wheel" in lines[2]
    assert lines[-1] == "re-planned            flown: b"
