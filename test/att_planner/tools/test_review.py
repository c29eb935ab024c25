"""``att-review``: the regression log reviewed (summary against independent figures, figures,
HTML page) and a synthetic magnetorquer run's settling time."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from att_msgs_py.log import TopicLog, read_log
from att_msgs_py.types import Cone
from att_planner.cones import margins
from att_planner.tools.review import extract_run, settling_time, summarize
from att_planner.tools.review import main as review_main
from att_sim import rotations as rot
from att_sim import scenario as scen
from helpers.regression_log import FIXTURE, GOAL, TOPIC_TYPES


@pytest.fixture(scope="module")
def log():
    return read_log(FIXTURE)


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
    first = np.flatnonzero(cmd["plan_id"] == run.plan.plan_id)[0]
    assert run.t0 == cmd["header.stamp"][first] and run.t[0] >= 0 and run.t[-1] > run.plan.duration
