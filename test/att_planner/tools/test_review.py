"""``att-review``: the regression log reviewed (summary against independent figures, figures,
HTML page), what "executed" covers, the body torque against the planning and the actuator limit,
and a synthetic magnetorquer run's settling time."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from att_msgs_py.log import TopicLog, read_log
from att_msgs_py.types import Cone
from att_planner.cones import margins
from att_planner.tools.review import extract_run, format_summary, settling_time, summarize
from att_planner.tools.review import main as review_main
from att_planner.tools.review.summary import body_torque_limits
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.dynamics import Spacecraft
from helpers.regression_log import FIXTURE, GOAL, TOPIC_TYPES

FIXTURE_SETTLE_TIME = 5.0          # the controller's settle_time_s when the fixture was recorded (make_fixture.py)


@pytest.fixture(scope="module")
def log():
    return read_log(FIXTURE)


def segment_states(log, run):
    """The state samples of the reviewed segment, selected independently of extract_run."""
    t = log["/spacecraft/state"]["header.stamp"]
    return (t >= run.t0) & (t < run.t0 + run.t[-1] + 1e-9)


def test_summary_of_the_fixture_matches_independent_figures(log):
    sc = scen.load("swift_demo").spacecraft
    s = summarize(log, sc)
    state, plans = log["/spacecraft/state"], log["/planner/plans"]
    assert s["kind"] == "maneuver" and s["plan"]["plan_id"] == plans["plan_id"][0]
    assert s["maneuver_time_s"] == pytest.approx(plans["duration"][0])
    # no change of mode or plan after the maneuver: the segment runs to the log's last state
    assert s["executed_time_s"] == pytest.approx(state["header.stamp"][-1] - s["start_sim_time_s"], abs=0.11)
    assert s["executed_time_s"] > s["maneuver_time_s"] + FIXTURE_SETTLE_TIME - 0.2
    assert s["final_attitude_error_deg"] == pytest.approx(math.degrees(rot.angle_between(state["attitude"][-1], GOAL)))
    assert s["final_attitude_error_deg"] < 0.1
    cones = [Cone(c["direction"], c["half_angle"], c["name"]) for c in plans["cones"][0]]
    segment = state["header.stamp"] >= s["start_sim_time_s"] - 1e-9         # the reviewed segment's states
    m = np.degrees(margins(state["attitude"][segment], [1, 0, 0], cones).min(axis=0))
    assert s["min_margin_deg"] == pytest.approx(dict(zip(["sun", "earth", "moon"], m)), abs=1e-9)
    assert 10 < s["min_margin_deg"]["moon"] < 20 and s["min_cone_margin_deg"] == pytest.approx(m.min())
    assert s["closest_approach_s"]["moon"] > 0.8 * s["maneuver_time_s"]     # the path ends nearest the Moon
    assert s["wheel_speed_rad_s_limit"] == sc.wheel_speed_max and 0.1 < s["wheel_speed_rad_s_ratio"] < 1.0
    assert s["peak_dipole_Am2"] == 0.0 and s["settling_time_s"] is None
    assert summarize(log)["body_torque_Nm_limit"] is None       # no spacecraft given: no limits invented


def test_executed_is_the_maneuver_then_the_settle_and_hold(log):
    """executed = the plan's duration + the time after it; the goal ends a settle time after the
    plan; the error at the plan's end is the recorded state's at t = duration."""
    s = summarize(log, scen.load("swift_demo").spacecraft)
    run = extract_run(log)
    duration = log["/planner/plans"]["duration"][0]
    assert s["maneuver_time_s"] == pytest.approx(duration)
    assert s["executed_time_s"] == pytest.approx(s["maneuver_time_s"] + s["after_plan_s"])
    assert s["after_plan_s"] >= FIXTURE_SETTLE_TIME - 0.2
    assert s["goal_end_s"] == pytest.approx(duration + FIXTURE_SETTLE_TIME, abs=0.2)
    state = log["/spacecraft/state"]
    k = np.argmin(np.abs(state["header.stamp"] - (run.t0 + duration)))
    assert s["error_at_plan_end_deg"] == pytest.approx(math.degrees(rot.angle_between(state["attitude"][k], GOAL)),
                                                       abs=1e-9)
    text = format_summary(s)
    assert f"executed              {s['executed_time_s']:.2f} s = {duration:.2f} s maneuver (the plan) + " in text
    assert "the execute goal's first command to the next change of mode or plan" in text
    assert f"ended at t = {s['goal_end_s']:.2f} s" in text


def test_peak_body_torque_against_the_planning_and_the_actuator_limit(log):
    """swift_demo plans with torque_max = 0.1 N m; its body-aligned wheels deliver 0.12 N m."""
    sc = scen.load("swift_demo").spacecraft
    s = summarize(log, sc)
    run = extract_run(log)
    applied = log["/spacecraft/state"]["applied_torque"][segment_states(log, run)]
    peak = np.abs(applied).max()
    assert s["peak_body_torque_Nm"] == pytest.approx(peak, rel=1e-12)
    assert s["body_torque_Nm_planning_limit"] == sc.body_torque_max == 0.1
    assert s["body_torque_Nm_limit"] == pytest.approx(sc.wheel_torque_max) and sc.wheel_torque_max == 0.12
    assert s["body_torque_Nm_planning_ratio"] == pytest.approx(peak / 0.1)
    assert s["body_torque_Nm_ratio"] == pytest.approx(peak / 0.12)
    assert s["body_torque_Nm_above_limit"] is False
    i = np.argmax(np.abs(applied).max(axis=1))
    assert s["peak_body_torque_Nm_t_s"] == pytest.approx(run.t[i])
    assert s["peak_body_torque_phase"] == ("maneuver" if run.t[i] <= s["maneuver_time_s"] else "settle/hold")
    text = format_summary(s)
    assert f"{peak / 0.1:.3f} x the planning limit 0.1 N m (torque_max), {peak / 0.12:.3f} x the actuator limit" in text
    assert "20% headroom" in text and "ABOVE" not in text


@pytest.mark.parametrize("peak, above", [(0.1027, False), (0.1199, False), (0.1201, True), (0.5, True)])
def test_only_a_peak_above_the_actuator_limit_is_flagged(log, peak, above):
    """The documented run's 1.027 x torque_max is within the wheels' limit; past 0.12 N m it is flagged."""
    run = extract_run(log)
    inside = segment_states(log, run)
    state = log["/spacecraft/state"]
    torque = np.array(state["applied_torque"], float)
    k = np.flatnonzero(inside)[len(run.t) // 3]
    torque[k] = [0.0, -peak, 0.0]
    scaled = dict(log)
    scaled["/spacecraft/state"] = TopicLog(state.topic, state.type_name, state.log_time,
                                           {**state.fields, "applied_torque": torque}, state.messages)
    s = summarize(scaled, scen.load("swift_demo").spacecraft)
    assert s["peak_body_torque_Nm"] == pytest.approx(peak)
    assert s["body_torque_Nm_planning_ratio"] == pytest.approx(peak / 0.1) and s["body_torque_Nm_planning_ratio"] > 1
    assert s["body_torque_Nm_above_limit"] is above
    assert ("ABOVE THE ACTUATOR LIMIT" in format_summary(s)) is above


def test_actuator_limit_of_the_body_torque_follows_the_wheel_axes():
    inertia = np.eye(3) * 10.0
    pyramid = np.array([[1, -1, 0, 0], [0, 0, 1, -1], [1, 1, 1, 1]]) / math.sqrt(2)
    four = Spacecraft(inertia, wheel_axes=pyramid, wheel_torque_max=0.2, body_torque_max=0.15)
    assert body_torque_limits(four) == pytest.approx((0.15, 0.2 * 4 / math.sqrt(2)))   # z: all four wheels
    skewed = Spacecraft(inertia, wheel_axes=np.array([[1, 0], [0, 0.6], [0, 0.8]]), wheel_torque_max=0.1,
                        body_torque_max=0.05)
    assert body_torque_limits(skewed) == pytest.approx((0.05, 0.1))
    assert body_torque_limits(Spacecraft(inertia, wheel_axes=np.zeros((3, 0)), body_torque_max=0.001)) == (0.001, 0.001)
    assert body_torque_limits(Spacecraft(inertia)) == (None, None)     # unlimited wheels: no limit shown
    assert body_torque_limits(None) == (None, None)


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
    assert page.count("data:image/png;base64,") == 4 and "final attitude error" in page   # estimation.png too
    assert "estimation error" in page
    assert page.count('<p class="note">') == 2 and "&quot;executed&quot; is the whole reviewed segment" in page
    assert "planning limit torque_max = 0.1 N m" in page and "note:" not in page
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["kind"] == "maneuver" and summary["plan"]["method"] == "eigenaxis_smooth"
    assert summary["final_attitude_error_deg"] < 0.1 and set(summary["min_margin_deg"]) == {"sun", "earth", "moon"}
    assert review_main([str(FIXTURE), "--out", str(tmp_path), "--plan-id", "nope"]) == 1


def test_review_picks_the_executed_plan_segment(log):
    run = extract_run(log)
    cmd = log["/actuator/command"]
    first = np.flatnonzero(cmd["plan_id"] == run.plan.plan_id)[0]
    assert run.t0 == cmd["header.stamp"][first] and run.t[0] >= 0 and run.t[-1] > run.plan.duration


def test_the_timeline_ends_a_park_when_the_next_slew_leaves_it():
    """The day's park at eta_carinae waited until 16 735 s but the slew to vega left at 16 317 s;
    a park the mission stays in keeps its own end."""
    from att_msgs_py.types import MissionEvent
    from att_msgs_py.types import MissionEventKind as Kind
    from att_planner.tools.review.mission import timeline_bars

    events = [MissionEvent(912.2, Kind.PARK, "3c273", 912.2, 1027.3),
              MissionEvent(935.8, Kind.SLEW, "3c273", 1152.4, 1156.4),
              MissionEvent(13652.4, Kind.PARK, "eta_carinae", 13652.4, 16734.9),
              MissionEvent(16155.8, Kind.SLEW, "vega", 16317.0, 17196.1),
              MissionEvent(17256.4, Kind.DWELL, "vega", 17256.2, 17556.2),
              MissionEvent(17300.0, Kind.MISSED, "pleiades")]
    bars = [(e.target, e.event, start, end) for e, start, end in timeline_bars(events)]
    assert bars == [("3c273", Kind.PARK, 912.2, 1027.3), ("3c273", Kind.SLEW, 1152.4, 1156.4),
                    ("eta_carinae", Kind.PARK, 13652.4, 16317.0), ("vega", Kind.SLEW, 16317.0, 17196.1),
                    ("vega", Kind.DWELL, 17256.2, 17556.2)]


def test_the_timeline_ends_a_refused_slew_at_its_refusal():
    """A slew the controller refused at its start is not drawn and does not end the park before
    it; one aborted in flight ends at its refusal."""
    from att_msgs_py.types import MissionEvent
    from att_msgs_py.types import MissionEventKind as Kind
    from att_planner.tools.review.mission import timeline_bars

    events = [MissionEvent(40.0, Kind.PARK, "vega", 40.0, 300.0),
              MissionEvent(162.0, Kind.SLEW, "polaris", 162.0, 623.3, plan_id="aa"),
              MissionEvent(162.0, Kind.REFUSED, "polaris", plan_id="aa"),
              MissionEvent(196.4, Kind.SLEW, "polaris", 285.6, 747.8, plan_id="bb"),
              MissionEvent(808.4, Kind.DWELL, "polaris", 808.0, 868.0),
              MissionEvent(902.4, Kind.SLEW, "cas_a", 988.0, 1708.0, plan_id="cc"),
              MissionEvent(1200.0, Kind.REFUSED, "cas_a", plan_id="cc")]
    bars = [(e.target, e.event, start, end) for e, start, end in timeline_bars(events)]
    assert bars == [("vega", Kind.PARK, 40.0, 285.6), ("polaris", Kind.SLEW, 285.6, 747.8),
                    ("polaris", Kind.DWELL, 808.0, 868.0), ("cas_a", Kind.SLEW, 988.0, 1200.0)]


def test_review_refuses_a_schema_it_cannot_parse_in_one_line(tmp_path, capsys):
    """The regression log with its controller status schema named ``this/msg/x``: one line naming the
    topic and the schema, exit 1, no traceback (the ros2msg parser's exception is the file's fault)."""
    from att_planner.tools.bench.hostile_logs import renamed

    path = tmp_path / "named.mcap"
    renamed(schemas={"att_msgs/msg/ControllerStatus": "this/msg/x"})(FIXTURE.read_bytes(), [], path)
    assert review_main([str(path), "--out", str(tmp_path / "review")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("att-review: ") and "schema 'this/msg/x' does not decode" in err, err


def test_a_log_without_goal_or_plan_is_reviewed_without_a_warning(tmp_path):
    """2 s of the in-process closed loop holding its attitude (no plan, no goal): the review is
    written and matplotlib warns of nothing (a warning is a second line on the terminal)."""
    import warnings

    from att_planner.tools.bench.hostile_logs import recorded_log
    from att_planner.tools.review import review

    path = recorded_log(tmp_path / "hold.mcap", seconds=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        done = review(path, tmp_path / "review")
    assert done.summary["kind"] != "maneuver" and (tmp_path / "review" / "time_histories.png").stat().st_size > 10_000


def test_the_reviewed_topics_cover_every_part_of_the_review():
    from att_msgs_py.topics import COMMAND, CONTROLLER_STATUS, PLANS, STATE
    from att_planner.tools.review import REVIEWED_TOPICS
    from att_planner.tools.review.estimation import TOPICS as ESTIMATION_TOPICS
    from att_planner.tools.review.faults import TOPICS as FAULT_TOPICS
    from att_planner.tools.review.mission import TOPICS as MISSION_TOPICS

    assert REVIEWED_TOPICS == sorted({STATE, COMMAND, PLANS, CONTROLLER_STATUS, *ESTIMATION_TOPICS, *MISSION_TOPICS,
                                      *FAULT_TOPICS})


def test_a_damaged_log_is_refused_before_the_figures_and_models_are_imported(tmp_path):
    """att-review answers a file it cannot read after importing only the reader: matplotlib, scipy
    and the planner's models (seconds on a loaded machine) are imported once there is a log to review."""
    import subprocess
    import sys

    damaged = tmp_path / "cut.mcap"
    damaged.write_bytes(FIXTURE.read_bytes()[:9])
    heavy = ("matplotlib", "scipy", "att_planner.zones", "att_planner.tools.review.figures")
    probe = ("import sys; from att_planner.tools.review import main; code = main([sys.argv[1]]); "
             f"print(code, sorted(m for m in {heavy!r} if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe, str(damaged)], capture_output=True, text=True, timeout=120)
    assert done.stdout.strip() == "1 []", done.stdout + done.stderr
    assert done.stderr.count("\n") == 1 and "at byte 8" in done.stderr, done.stderr
    assert not (tmp_path / "review").exists()
