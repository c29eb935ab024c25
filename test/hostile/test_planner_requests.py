"""Hostile PlanManeuver and PlanSchedule requests: every one refused with its code and a sentence
naming the field (ROS-free, against the service logic), a closed sky refused as INFEASIBLE before
any solving while a barely open one is not, and over ROS: a planner that keeps serving through
them and signs every plan it issues."""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest
import rclpy

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import ManeuverPlan
from att_msgs.srv import ImageStrip, ImageTarget
from att_msgs_py import convert, qos, signing, topics
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Cone, PointingMode
from att_planner.nodes.client import check_strings, maneuver_request
from att_planner.service.planning import plan_maneuver, run_method
from att_planner.service.requests import MAX_CONES, MAX_OPTIONS, MAX_TARGETS, validate_schedule
from att_planner.service.worker import run_isolated, warm_up
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from helpers.maneuver_requests import GOAL, INF, NAN, request, validate

TINY = 5e-324                   # the smallest denormal
LONG = "x" * 129                # one above the name cap
X = np.array([1.0, 0.0, 0.0])
DIAGONAL = np.ones(3) / math.sqrt(3.0)


def ring(center, radius_deg: float = 45.0, half_deg: float = 20.0, n: int = 8, skip: int | None = None) -> list:
    """``n`` cones of ``half_deg`` on a circle of ``radius_deg`` about ``center`` (adjacent ones
    overlap at the defaults: a closed wall around ``center``), leaving out cone ``skip``."""
    w = np.asarray(center, float) / np.linalg.norm(center)
    u, v = rot.orthonormal_basis(w)
    b = math.radians(radius_deg)
    return [(math.cos(b) * w + math.sin(b) * (math.cos(a) * u + math.sin(a) * v), math.radians(half_deg), f"r{k}")
            for k, a in enumerate(np.linspace(0, 2 * math.pi, n, endpoint=False)) if k != skip]


SIX_AXES = [(s * np.eye(3)[i], math.radians(50.0), f"{'+-'[s < 0]}{'xyz'[i]}") for i in range(3) for s in (1, -1)]
QUARTER_Z = rot.from_axis_angle([0, 0, 1], math.pi / 2)     # takes the diagonal pocket to the next one

# name: (request fields, code, words the message must contain: the field, and the reason)
MANEUVER_CASES = {
    # attitudes: NaN, Inf, zero, huge, denormal, off-unit
    "initial nan": (dict(q_initial=[NAN, 0, 0, 1]), ErrorCode.INVALID_ATTITUDE, "initial_attitude has NaN"),
    "initial +inf": (dict(q_initial=[0, INF, 0, 1]), ErrorCode.INVALID_ATTITUDE, "initial_attitude has NaN or Inf"),
    "final -inf": (dict(q_final=[0, 0, -INF, 1]), ErrorCode.INVALID_ATTITUDE, "final_attitude has NaN or Inf"),
    "final nan w": (dict(q_final=[0, 0, 0, NAN]), ErrorCode.INVALID_ATTITUDE, "final_attitude"),
    "initial zero": (dict(q_initial=[0, 0, 0, 0]), ErrorCode.INVALID_ATTITUDE, "initial_attitude is the zero"),
    "final zero": (dict(q_final=[0.0, -0.0, 0.0, -0.0]), ErrorCode.INVALID_ATTITUDE, "final_attitude is the zero"),
    "initial huge": (dict(q_initial=[1e308, 0, 0, 0]), ErrorCode.INVALID_ATTITUDE, "initial_attitude has norm"),
    "final overflowing norm": (dict(q_final=[1e308, 1e308, 0, 0]), ErrorCode.INVALID_ATTITUDE,
                               "final_attitude has norm inf"),
    "initial denormal": (dict(q_initial=[0, 0, 0, TINY]), ErrorCode.INVALID_ATTITUDE, "initial_attitude is the zero"),
    "final all denormal": (dict(q_final=[TINY] * 4), ErrorCode.INVALID_ATTITUDE, "final_attitude is the zero"),
    "initial norm 0.5": (dict(q_initial=[0, 0, 0, 0.5]), ErrorCode.INVALID_ATTITUDE, "initial_attitude has norm 0.5"),
    "final norm 1.01": (dict(q_final=[0, 0, 0, 1.01]), ErrorCode.INVALID_ATTITUDE, "final_attitude has norm 1.01"),
    # sensor axis and semi-free target
    "sensor nan": (dict(sensor_axis=[NAN, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "sensor_axis has NaN"),
    "sensor zero": (dict(sensor_axis=[0, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "sensor_axis is the zero vector"),
    "sensor denormal": (dict(sensor_axis=[TINY, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "sensor_axis is the zero"),
    "sensor huge": (dict(sensor_axis=[1e300, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "sensor_axis has norm"),
    "sensor half": (dict(sensor_axis=[0.5, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "sensor_axis has norm 0.5"),
    "target zero": (dict(semi_free=True, sensor_target=[0, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS,
                    "sensor_target is the zero vector"),
    "target inf": (dict(semi_free=True, sensor_target=[0, INF, 0]), ErrorCode.INVALID_SENSOR_AXIS,
                   "sensor_target has NaN or Inf"),
    "target not unit": (dict(semi_free=True, sensor_target=[0, 3, 0]), ErrorCode.INVALID_SENSOR_AXIS,
                        "sensor_target has norm 3"),
    # cones
    "17 cones": (dict(cones=[([0, 0, 1], 0.1, "c")] * (MAX_CONES + 1)), ErrorCode.SIZE_LIMIT, "17 cones given"),
    "cone direction nan": (dict(cones=[([NAN, 0, 1], 0.3, "c")]), ErrorCode.INVALID_CONE, "cones[0] ('c').direction"),
    "cone direction zero": (dict(cones=[([0, 0, 0], 0.3, "c")]), ErrorCode.INVALID_CONE, "cones[0] ('c').direction"),
    "cone direction long": (dict(cones=[([0, 0, 1], 0.3, "a"), ([0, 0, -2], 0.3, "b")]), ErrorCode.INVALID_CONE,
                            "cones[1] ('b').direction has norm 2"),
    "cone half-angle inf": (dict(cones=[([0, 0, 1], INF, "c")]), ErrorCode.INVALID_CONE, "cones[0] ('c').half_angle"),
    "cone half-angle -0": (dict(cones=[([0, 0, 1], -0.0, "c")]), ErrorCode.INVALID_CONE, "half_angle = -0.0"),
    "cone half-angle 3 rad": (dict(cones=[([0, 0, 1], 3.0, "c")]), ErrorCode.INVALID_CONE, "outside (0, pi/2)"),
    # strings: control characters in every string field, and over-long ones
    "frame_id \\x01": (dict(frame_id="eci\x01"), ErrorCode.INVALID_TEXT, "header.frame_id contains"),
    "frame_id newline": (dict(frame_id="eci\n"), ErrorCode.INVALID_TEXT, "header.frame_id contains"),
    "frame_id NEL": (dict(frame_id="e\x85ci"), ErrorCode.INVALID_TEXT, "U+0085 at position 1"),
    "method escape": (dict(method="eigenaxis\x1b[31m"), ErrorCode.INVALID_TEXT, "method contains"),
    "spacecraft DEL": (dict(spacecraft="swift_demo\x7f"), ErrorCode.INVALID_TEXT, "spacecraft contains"),
    "cone name \\x01": (dict(cones=[([0, 0, -1], 0.3, "earth\x01")]), ErrorCode.INVALID_TEXT, "cones[0].name"),
    "option name \\x01": (dict(option_names=["samples\x01"], option_values=[100.0]), ErrorCode.INVALID_TEXT,
                          "option_names[0] contains"),
    "spacecraft surrogate": (dict(spacecraft="swift\ud800"), ErrorCode.INVALID_TEXT, "U+D800"),
    "frame_id too long": (dict(frame_id=LONG), ErrorCode.SIZE_LIMIT, "header.frame_id has 129 characters"),
    "method too long": (dict(method="m" * 5000), ErrorCode.SIZE_LIMIT, "method has 5000 characters"),
    "spacecraft too long": (dict(spacecraft="s" * 100_000), ErrorCode.SIZE_LIMIT, "spacecraft has 100000"),
    "cone name too long": (dict(cones=[([0, 0, -1], 0.3, LONG)]), ErrorCode.SIZE_LIMIT, "cones[0].name has 129"),
    "option name too long": (dict(option_names=[LONG], option_values=[1.0]), ErrorCode.SIZE_LIMIT,
                             "option_names[0] has 129"),
    # options
    "duplicate option": (dict(option_names=["samples", "samples"], option_values=[100.0, 100.0]),
                         ErrorCode.INVALID_OPTION, "option_names[1] repeats option 'samples'"),
    "duplicate option, other value": (dict(option_names=["samples", "samples"], option_values=[100.0, 4000.0]),
                                      ErrorCode.INVALID_OPTION, "given once"),
    "option nan": (dict(option_names=["samples"], option_values=[NAN]), ErrorCode.INVALID_OPTION, "samples"),
    "option +inf": (dict(option_names=["samples"], option_values=[INF]), ErrorCode.INVALID_OPTION, "samples"),
    "option -inf": (dict(option_names=["samples"], option_values=[-INF]), ErrorCode.INVALID_OPTION, "samples"),
    "option 1e308": (dict(option_names=["samples"], option_values=[1e308]), ErrorCode.INVALID_OPTION, "outside"),
    "option denormal": (dict(option_names=["samples"], option_values=[TINY]), ErrorCode.INVALID_OPTION, "outside"),
    "samples above the plan cap": (dict(option_names=["samples"], option_values=[100_000.0]),
                                   ErrorCode.INVALID_OPTION, "samples (knots"),
    "option of another method": (dict(method="eigenaxis", option_names=["samples"], option_values=[100.0]),
                                 ErrorCode.INVALID_OPTION, "not an option of method 'eigenaxis'"),
    "empty option name": (dict(option_names=[""], option_values=[1.0]), ErrorCode.INVALID_OPTION,
                          "option_names[0] is empty"),
    "too many options": (dict(option_names=[f"o{i}" for i in range(MAX_OPTIONS + 1)],
                              option_values=[1.0] * (MAX_OPTIONS + 1)), ErrorCode.SIZE_LIMIT, "17 options given"),
    "option lists differ": (dict(option_names=["samples"], option_values=[]), ErrorCode.INVALID_OPTION,
                            "option_values has 0"),
    # a sky closed by cones: refused before any solving
    "ring around the start": (dict(cones=ring(X)), ErrorCode.INFEASIBLE, "cones: the 8 keep-out cones close the sky"),
    "ring around the goal": (dict(cones=ring(rot.dcm_NB(GOAL) @ X)), ErrorCode.INFEASIBLE, "start and goal sensor"),
    "ring around the semi-free target": (dict(cones=ring([0, 1, 0]), semi_free=True, sensor_target=[0, 1, 0]),
                                         ErrorCode.INFEASIBLE, "start and sensor_target sensor directions"),
    "six 50 deg cones, pocket to pocket": (dict(cones=SIX_AXES, sensor_axis=DIAGONAL, q_final=QUARTER_Z),
                                           ErrorCode.INFEASIBLE, "6 keep-out cones close the sky"),
    "six 60 deg cones cover the sky": (dict(cones=[(d, math.radians(60), n) for d, _, n in SIX_AXES]),
                                       ErrorCode.SENSOR_IN_CONE, "start sensor direction is inside cone"),
    # budgets
    "budget nan": (dict(time_budget=NAN), ErrorCode.INVALID_TIME_BUDGET, "time_budget = nan"),
    "budget inf": (dict(time_budget=INF), ErrorCode.INVALID_TIME_BUDGET, "time_budget = inf"),
    "budget negative": (dict(time_budget=-1e-9), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
    "budget above 600 s": (dict(time_budget=600.5), ErrorCode.INVALID_TIME_BUDGET, "outside [0, 600"),
    "budget 1e308": (dict(time_budget=1e308), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
    # names that are not what they claim
    "unknown method": (dict(method="teleport"), ErrorCode.UNKNOWN_METHOD, "method 'teleport' is unknown"),
    "path-like method": (dict(method="../eigenaxis"), ErrorCode.UNKNOWN_METHOD, "method '../eigenaxis'"),
    "unknown spacecraft": (dict(spacecraft="no_such_craft"), ErrorCode.UNKNOWN_SPACECRAFT, "no_such_craft"),
    "path-like spacecraft": (dict(spacecraft="../x"), ErrorCode.UNKNOWN_SPACECRAFT, "spacecraft '../x' must be"),
    "absolute path spacecraft": (dict(spacecraft="/etc/passwd"), ErrorCode.UNKNOWN_SPACECRAFT, "configuration name"),
    "yaml file spacecraft": (dict(spacecraft="swift_demo.yaml"), ErrorCode.UNKNOWN_SPACECRAFT, "configuration name"),
    "wrong frame": (dict(frame_id="map"), ErrorCode.INVALID_FRAME, "header.frame_id 'map' is not"),
    # the wheels at the start (swift_demo: three, 630 rad/s)
    "wheel speeds short": (dict(wheel_speeds=[0.0, 0.0]), ErrorCode.INVALID_WHEEL_SPEEDS, "wheel_speeds has 2 values"),
    "wheel speeds long": (dict(wheel_speeds=[0.0] * 10_000), ErrorCode.INVALID_WHEEL_SPEEDS, "10000 values"),
    "wheel speed nan": (dict(wheel_speeds=[0.0, NAN, 0.0]), ErrorCode.INVALID_WHEEL_SPEEDS, "wheel_speeds has NaN"),
    "wheel speed -inf": (dict(wheel_speeds=[-INF, 0.0, 0.0]), ErrorCode.INVALID_WHEEL_SPEEDS, "wheel_speeds"),
    "wheel speed beyond": (dict(wheel_speeds=[0.0, -630.5, 0.0]), ErrorCode.INVALID_WHEEL_SPEEDS,
                           "wheel_speeds[1] = -630.5 rad/s is beyond"),
    # a slew that ends on a pointing mode
    "end pointing, other method": (dict(end_pointing=PointingMode("nadir")), ErrorCode.INVALID_OPTION,
                                   "end_pointing: a slew that ends on a pointing mode is planned by time_optimal"),
    "end pointing, semi-free": (dict(end_pointing=PointingMode("nadir"), method="time_optimal", semi_free=True,
                                     sensor_target=[0, 1, 0]), ErrorCode.INVALID_OPTION, "semi_free"),
    "end pointing, unknown kind": (dict(end_pointing=PointingMode("sideways"), method="time_optimal"),
                                   ErrorCode.INVALID_POINTING, "pointing.kind 'sideways' is not one of"),
    "end pointing, control character": (dict(end_pointing=PointingMode("nadir\x7f"), method="time_optimal"),
                                        ErrorCode.INVALID_TEXT, "pointing.kind contains the control"),
    "end pointing, ground nan": (dict(end_pointing=PointingMode("ground", latitude=NAN), method="time_optimal"),
                                 ErrorCode.INVALID_POINTING, "pointing.latitude"),
    "end pointing, parallel axes": (dict(end_pointing=PointingMode("nadir", secondary_axis=np.array([0, 0, 1.0])),
                                         method="time_optimal"), ErrorCode.INVALID_POINTING, "pointing"),
}


@pytest.mark.parametrize("name", sorted(MANEUVER_CASES))
def test_hostile_maneuver_request_is_refused_with_its_code_naming_the_field(name):
    fields, code, words = MANEUVER_CASES[name]
    with pytest.raises(RequestError) as err:
        validate(request(**fields))
    assert (err.value.code, words in err.value.message) == (code, True), err.value.message
    assert len(err.value.message) <= 400


def schedule(**fields):
    """validate_schedule of two distinct targets on the wheeled olivares_staffetti spacecraft,
    with ``fields`` replaced."""
    args = dict(names=["a", "b"], targets=[rot.from_axis_angle([0, 0, 1], 1.0), rot.from_axis_angle([1, 0, 0], 1.0)],
                q_start=rot.IDENTITY, q_end=None, spacecraft="olivares_staffetti", time_budget=5.0, request_frame="")
    args.update(fields)
    return validate_schedule(args.pop("names"), args.pop("targets"), args.pop("q_start"), args.pop("q_end"),
                             args.pop("spacecraft"), args.pop("time_budget"), frame_id="eci",
                             default_spacecraft="olivares_staffetti", default_budget=5.0, **args)


Q1 = rot.from_axis_angle([0, 1, 0], 0.7)
SCHEDULE_CASES = {
    "same target twice": (dict(names=["a", "b", "c"], targets=[Q1, rot.IDENTITY, Q1]), ErrorCode.INVALID_ATTITUDE,
                          "targets[0] ('a') and targets[2] ('c') are the same attitude"),
    "q and -q": (dict(targets=[Q1, -Q1]), ErrorCode.INVALID_ATTITUDE, "targets[0] ('a') and targets[1] ('b')"),
    "targets 1e-7 rad apart": (dict(targets=[Q1, rot.multiply(Q1, rot.from_axis_angle([0, 0, 1], 1e-7))]),
                               ErrorCode.INVALID_ATTITUDE, "same attitude"),
    "target name \\x01": (dict(names=["a", "b\x01"]), ErrorCode.INVALID_TEXT, "target_names[1] contains"),
    "target name too long": (dict(names=["a", LONG]), ErrorCode.SIZE_LIMIT, "target_names[1] has 129"),
    "target names repeat": (dict(names=["a", "a"]), ErrorCode.INVALID_ATTITUDE, "target_names[1] is a repeat"),
    "target name empty": (dict(names=["", "b"]), ErrorCode.INVALID_ATTITUDE, "target_names[0] is empty"),
    "21 targets": (dict(names=[f"t{i}" for i in range(MAX_TARGETS + 1)],
                        targets=[rot.from_axis_angle([0, 0, 1], 0.1 * i) for i in range(MAX_TARGETS + 1)]),
                   ErrorCode.SIZE_LIMIT, "21 targets given"),
    "target nan": (dict(targets=[Q1, [0, NAN, 0, 1]]), ErrorCode.INVALID_ATTITUDE, "targets[1] ('b') has NaN"),
    "names and targets differ": (dict(names=["a"]), ErrorCode.INVALID_ATTITUDE, "1 target_names for 2 targets"),
    "schedule frame \\x01": (dict(request_frame="eci\x01"), ErrorCode.INVALID_TEXT, "header.frame_id contains"),
    "schedule spacecraft \\x01": (dict(spacecraft="olivares\x01"), ErrorCode.INVALID_TEXT, "spacecraft contains"),
    "schedule start zero": (dict(q_start=[0, 0, 0, 0]), ErrorCode.INVALID_ATTITUDE, "start_attitude is the zero"),
    "schedule end huge": (dict(q_end=[0, 0, 0, 1e200]), ErrorCode.INVALID_ATTITUDE, "end_attitude has norm"),
    "schedule budget nan": (dict(time_budget=NAN), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
    "dwell for one of two": (dict(observations=([10.0], [], [])), ErrorCode.INVALID_OBSERVATION,
                             "dwell_times has 1 values for 2 targets"),
    "dwell negative": (dict(observations=([10.0, -1.0], [], [])), ErrorCode.INVALID_OBSERVATION,
                       "dwell_times[1] ('b') = -1.0 s"),
    "dwell nan": (dict(observations=([NAN, 1.0], [], [])), ErrorCode.INVALID_OBSERVATION, "dwell_times[0] ('a')"),
    "dwell inf": (dict(observations=([1.0, INF], [], [])), ErrorCode.INVALID_OBSERVATION, "dwell_times[1] ('b')"),
    "window opens only": (dict(observations=([], [0.0, 0.0], [])), ErrorCode.INVALID_OBSERVATION,
                          "window_opens and window_closes go together"),
    "window closes before it opens": (dict(observations=([], [100.0, 0.0], [50.0, INF])),
                                      ErrorCode.INVALID_OBSERVATION, "window_closes[0] ('a') = 50.0 s"),
    "window shorter than the dwell": (dict(observations=([60.0, 0.0], [100.0, 0.0], [130.0, INF])),
                                      ErrorCode.INVALID_OBSERVATION, "needs 60 s"),
    "window opens at -inf": (dict(observations=([], [-INF, 0.0], [10.0, 10.0])), ErrorCode.INVALID_OBSERVATION,
                             "window_opens[0] ('a') = -inf"),
    "window closes nan": (dict(observations=([], [0.0, 0.0], [NAN, 10.0])), ErrorCode.INVALID_OBSERVATION,
                          "window_closes[0] ('a') = nan"),
    "windows long": (dict(observations=([], [0.0] * 10_000, [1.0] * 10_000)), ErrorCode.INVALID_OBSERVATION,
                     "window_opens has 10000 values"),
}


@pytest.mark.parametrize("name", sorted(SCHEDULE_CASES))
def test_hostile_schedule_request_is_refused_with_its_code_naming_the_field(name):
    fields, code, words = SCHEDULE_CASES[name]
    with pytest.raises(RequestError) as err:
        schedule(**fields)
    assert (err.value.code, words in err.value.message) == (code, True), err.value.message


def test_there_are_more_than_fifty_distinct_hostile_requests():
    assert len(MANEUVER_CASES) + len(SCHEDULE_CASES) >= 50


def test_a_valid_schedule_passes_the_same_checks():
    assert sorted(schedule().problem.targets) == ["a", "b"]
    observing = schedule(observations=([30.0, 0.0], [0.0, 100.0], [INF, 200.0])).problem
    assert observing.target_dwell == {"a": 30.0}
    assert observing.target_windows == {"a": (0.0, INF), "b": (100.0, 200.0)}


def narrow_gap(gap_deg: float) -> list:
    """The closed ring around +x with one gap of about ``gap_deg`` between its first and last cone."""
    cones = ring(X)
    separation = math.degrees(math.acos(np.clip(cones[0][0] @ cones[-1][0], -1, 1)))
    half = math.radians((separation - gap_deg) / 2)
    return [(cones[0][0], half, "r0"), *cones[1:-1], (cones[-1][0], half, "r7")]


OPEN_SKIES = {"ring with a missing cone": ring(X, skip=3), "ring with a 0.2 deg gap": narrow_gap(0.2),
              "ring with a 0.01 deg gap": narrow_gap(0.01), "cones that just miss each other": ring(X, half_deg=15.6),
              "half a ring": ring(X)[:4]}


@pytest.mark.parametrize("name", sorted(OPEN_SKIES))
def test_a_sky_that_is_open_however_narrowly_is_not_refused(name):
    """The closed-sky rule is conservative: a gap of any width, even far below the lattice spacing, passes."""
    valid = validate(request(cones=OPEN_SKIES[name]))
    assert len(valid.problem.cones) == len(OPEN_SKIES[name])


def test_a_sky_closed_by_16_overlapping_cones_is_refused():
    with pytest.raises(RequestError):
        validate(request(cones=ring(X) + ring(-X)))           # 16 overlapping cones: the full check


@pytest.mark.parametrize("method", ["eigenaxis", "constrained_axis", "time_optimal"])
def test_a_denormal_budget_is_answered_at_once_with_a_code(method):
    warm_up()
    valid = validate(request(method=method, cones=[], time_budget=TINY))
    start = time.monotonic()
    outcome = plan_maneuver(valid, runner=run_method if valid.method.cheap else run_isolated)
    assert time.monotonic() - start < 1.5
    assert outcome.code in (ErrorCode.OK, ErrorCode.SOLVER_FAILED), outcome.message
    if outcome.code == ErrorCode.OK:
        assert outcome.verification is not None


def test_an_in_process_method_that_raises_on_a_crafted_problem_is_answered():
    """The service never lets a method's exception escape (the node answers SOLVER_FAILED or falls back)."""
    valid = validate(request(cones=[]))
    broken = replace(valid, options={"no_such_keyword": 1})
    outcome = plan_maneuver(broken, runner=run_method)
    assert outcome.code == ErrorCode.SOLVER_FAILED and "no_such_keyword" in outcome.message


# -- over ROS: a planner node that keeps serving and signs its plans ---------------------------

@pytest.fixture(scope="module")
def planner(ros_suite):
    with ros_suite("swift_demo", nodes=("planner",), name="hostile_planner") as s:
        assert s.client.plan_client.wait_for_service(timeout_sec=60)
        yield s


def good_request(**kw):
    return maneuver_request(rot.IDENTITY, rot.from_axis_angle([0, 0, 1], 0.5), X, [], method="eigenaxis_smooth",
                            **kw)


@pytest.mark.ros
@pytest.mark.parametrize("field, value, code", [
    ("header.frame_id", "eci\x01junk", ErrorCode.INVALID_TEXT),
    ("method", "eigenaxis\x1b", ErrorCode.INVALID_TEXT),
    ("spacecraft", "s" * 4000, ErrorCode.SIZE_LIMIT),
])
def test_the_node_refuses_hostile_strings_and_keeps_serving(planner, field, value, code):
    req = good_request()
    target, attr = (req.header, "frame_id") if field == "header.frame_id" else (req, field)
    setattr(target, attr, value)
    bad = planner.client.plan(req)              # the client leaves all but NUL to the server
    assert (bad.success, bad.error_code) == (False, code) and field in bad.message, bad.message
    assert len(bad.message) <= 400
    assert planner.client.plan(good_request()).success
    assert planner.suite.alive()["planner"]


@pytest.mark.ros
def test_the_node_refuses_a_closed_sky_and_nan_attitudes(planner):
    closed = maneuver_request(rot.IDENTITY, GOAL, X, [Cone(*c) for c in ring(X)], method="time_optimal",
                              time_budget=30.0)
    start = time.monotonic()
    answer = planner.client.plan(closed)
    assert answer.error_code == ErrorCode.INFEASIBLE and "close the sky" in answer.message
    assert time.monotonic() - start < 5.0                  # refused before solving, not after 30 s
    req = good_request()
    req.initial_attitude.w = NAN
    assert planner.client.plan(req).error_code == ErrorCode.INVALID_ATTITUDE
    req.initial_attitude.w, req.method = 1.0, "eigenaxis\0_smooth"
    with pytest.raises(ValueError, match="method contains a NUL character at position 9"):
        planner.client.plan(req)                # never sent as 'eigenaxis'
    assert planner.suite.alive()["planner"]


def test_the_client_refuses_a_nul_before_sending():
    with pytest.raises(ValueError, match="header.frame_id contains the control, format or unassigned character U"):
        good_request(frame_id="eci\0junk")
    with pytest.raises(ValueError, match=r"cones\[0\].name"):
        maneuver_request(rot.IDENTITY, GOAL, X, [Cone([0, 0, 1], 0.3, "sun\0")])
    with pytest.raises(ValueError, match=r"option_names\[0\]"):
        good_request(options={"samples\0": 100})
    with pytest.raises(ValueError, match="goal.plan_id"):
        check_strings(ExecuteManeuver.Goal(plan_id="abc\0def"), "goal")
    goal = ExecuteManeuver.Goal(use_inline_plan=True)
    goal.plan.cones = [convert.cone_msg(Cone([0, 0, 1], 0.3, "ok")), convert.cone_msg(Cone([0, 0, 1], 0.3, "\x02"))]
    with pytest.raises(ValueError, match=r"goal.plan.cones\[1\].name"):
        check_strings(goal, "goal")


@pytest.mark.ros
def test_plans_are_signed_and_bound_to_their_spacecraft_and_published_as_answered(planner):
    node = planner.client
    published = []
    sub = node.create_subscription(ManeuverPlan, topics.PLANS, published.append, qos.LATCHED_QOS)
    try:
        response = node.plan(good_request())
        assert response.success, response.message
        plan = response.plan
        public = signing.load_public_key(signing.default_key_dir() / signing.PUBLIC_NAME)
        assert signing.check(signing.payload(plan), plan.signature, plan.key_id, public) is None
        assert plan.spacecraft_digest == scen.load("swift_demo").spacecraft.digest
        end = time.monotonic() + 10
        while time.monotonic() < end and not any(p.plan_id == plan.plan_id for p in published):
            rclpy.spin_once(node, timeout_sec=0.1)
        sent = next(p for p in published if p.plan_id == plan.plan_id)
        assert bytes(sent.signature) == bytes(plan.signature)
        assert signing.check(signing.payload(sent), sent.signature, sent.key_id, public) is None
        forged = convert.plan_msg(convert.plan_from_msg(plan))
        forged.times = [2 * t for t in plan.times]
        assert signing.check(signing.payload(forged), forged.signature, forged.key_id, public) is not None
    finally:
        node.destroy_subscription(sub)


@pytest.mark.ros
def test_the_node_slows_a_plan_for_its_wheels_says_so_and_refuses_a_bad_end_pointing(planner):
    """Over the wire: wheel z at -600 rad/s and a slew about +z (which spins it further down) is
    answered slowed (``slowdown`` > 1, the message says so, the wheels within their limit); a bad
    ``end_pointing`` is refused naming the field, and the node keeps serving."""
    req = maneuver_request(rot.IDENTITY, rot.from_axis_angle([0, 0, 1], math.pi / 2), X, [],
                           method="eigenaxis_smooth", wheel_speeds=[0.0, 0.0, -600.0])
    answer = planner.client.plan(req)
    assert answer.success and answer.slowdown > 1.5 and "slowed" in answer.message, answer.message
    assert answer.plan.verification.wheel_speed_ratio <= 1.0
    bad = maneuver_request(rot.IDENTITY, GOAL, X, [], method="time_optimal",
                           end_pointing=PointingMode("ground", latitude=2.0))
    refused = planner.client.plan(bad)
    assert (refused.success, refused.error_code) == (False, ErrorCode.INVALID_POINTING)
    assert "pointing.latitude" in refused.message
    assert planner.client.plan(good_request()).success and planner.suite.alive()["planner"]


@pytest.mark.ros
def test_the_node_answers_an_image_strip_with_a_verified_plan_and_refuses_bad_sites(planner):
    """ImageStrip and ImageTarget on the wire (test_image_requests.py has every field's refusal): a
    NaN latitude and a zero-length strip refused naming the field, a strip across the track 100 s
    ahead answered with the verified plan onto its start, and the node keeps serving."""
    from att_planner.guidance.ground_arrival import site_in_view
    from att_planner.guidance.laws import PointingGeometry
    from att_sim.models import world

    client = planner.client
    assert client.image_strip_client.wait_for_service(timeout_sec=30)
    swift = scen.load("swift_demo")
    lat, lon = (math.degrees(a) for a in site_in_view(PointingGeometry.of(world.Environment.from_scenario(swift)),
                                                        100.0, math.radians(20.0), math.radians(90.0)))
    bad = ImageTarget.Request(latitude_deg=NAN, longitude_deg=lon, dwell_s=10.0, method="graph_smooth")
    bad.sensor_axis.y = bad.along_track_axis.z = 1.0
    refused = client.image_target(bad)
    assert (refused.success, refused.error_code) == (False, ErrorCode.INVALID_SITE)
    assert "latitude_deg = nan" in refused.message, refused.message
    req = ImageStrip.Request(start_latitude_deg=lat, start_longitude_deg=lon, end_latitude_deg=lat,
                             end_longitude_deg=lon, method="graph_smooth", time_budget=20.0)
    req.sensor_axis.y = req.along_track_axis.z = 1.0
    refused = client.image_strip(req)
    assert (refused.success, refused.error_code) == (False, ErrorCode.INVALID_SITE)
    assert "end_latitude_deg, end_longitude_deg" in refused.message, refused.message
    req.by_azimuth, req.azimuth_deg, req.length_m = True, 45.0, 30e3
    answer = client.image_strip(req)
    assert answer.success, answer.message
    ver = answer.plan.verification
    assert ver.final_attitude_error < math.radians(0.05) and ver.final_rate < math.radians(0.01)
    assert answer.image_start == pytest.approx(answer.plan.times[-1]) and answer.image_end > answer.image_start
    assert answer.lowest_elevation_deg >= 58.0 and answer.plan.signature
    assert client.plan(good_request()).success and planner.suite.alive()["planner"]
