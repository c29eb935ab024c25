"""Request validation (30+ distinct bad requests), time budgets, solver faults, fallbacks."""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_planner import methods
from att_planner.methods import Method
from att_planner.planner import Tolerances, plan_maneuver, run_method
from att_planner.problem import STATUS_FALLBACK
from att_planner.requests import MAX_CONES, ManeuverRequest, validate_maneuver
from att_planner.worker import run_isolated, warm_up
from att_sim import rotations as rot

NAN, INF = float("nan"), float("inf")
GOAL = rot.from_axis_angle([0, 0, 1], math.radians(135))
SUN = ([0.5, 0.866, 0.0], math.radians(47), "sun")
EARTH = ([0.0, 0.0, -1.0], math.radians(33), "earth")


def request(**fields) -> ManeuverRequest:
    base = dict(frame_id="eci", q_initial=rot.IDENTITY, q_final=GOAL, sensor_axis=np.array([1.0, 0, 0]),
                cones=[SUN, EARTH], method="eigenaxis_smooth")
    base.update(fields)
    return ManeuverRequest(**base)


def validate(req, **kw):
    args = dict(frame_id="eci", default_spacecraft="swift_demo", default_method="eigenaxis_smooth",
                default_budget=5.0, methods=methods.available())
    args.update(kw)
    return validate_maneuver(req, **args)


BAD_REQUESTS = {
    # attitudes
    "nan initial": (dict(q_initial=[NAN, 0, 0, 1]), ErrorCode.INVALID_ATTITUDE, "initial_attitude"),
    "inf final": (dict(q_final=[0, 0, INF, 1]), ErrorCode.INVALID_ATTITUDE, "final_attitude"),
    "zero quaternion": (dict(q_initial=[0, 0, 0, 0]), ErrorCode.INVALID_ATTITUDE, "zero quaternion"),
    "norm 2": (dict(q_final=[0, 0, 0, 2.0]), ErrorCode.INVALID_ATTITUDE, "norm 2"),
    "norm 0.99": (dict(q_initial=[0, 0, 0, 0.99]), ErrorCode.INVALID_ATTITUDE, "tolerance"),
    "wrong frame": (dict(frame_id="map"), ErrorCode.INVALID_FRAME, "'map'"),
    "body frame": (dict(frame_id="body"), ErrorCode.INVALID_FRAME, "inertial frame"),
    # sensor axis and cones
    "zero sensor": (dict(sensor_axis=[0, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "zero vector"),
    "nan sensor": (dict(sensor_axis=[NAN, 1, 0]), ErrorCode.INVALID_SENSOR_AXIS, "NaN"),
    "long sensor": (dict(sensor_axis=[2, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "unit vector"),
    "zero cone": (dict(cones=[([0, 0, 0], 0.5, "c")]), ErrorCode.INVALID_CONE, "cones[0]"),
    "nan cone": (dict(cones=[([NAN, 0, 1], 0.5, "c")]), ErrorCode.INVALID_CONE, "NaN"),
    "cone not unit": (dict(cones=[([0, 0, 3], 0.5, "c")]), ErrorCode.INVALID_CONE, "unit vector"),
    "half-angle 0": (dict(cones=[([0, 0, 1], 0.0, "c")]), ErrorCode.INVALID_CONE, "half_angle"),
    "half-angle negative": (dict(cones=[([0, 0, 1], -0.2, "c")]), ErrorCode.INVALID_CONE, "half_angle"),
    "half-angle 90": (dict(cones=[([0, 0, 1], math.pi / 2, "c")]), ErrorCode.INVALID_CONE, "half_angle"),
    "half-angle nan": (dict(cones=[([0, 0, 1], NAN, "c")]), ErrorCode.INVALID_CONE, "half_angle"),
    "start in cone": (dict(sensor_axis=[0.5, 0.866, 0]), ErrorCode.SENSOR_IN_CONE, "start sensor direction is inside cone 'sun'"),
    "goal in cone": (dict(q_final=rot.from_axis_angle([0, 0, 1], math.radians(60))), ErrorCode.SENSOR_IN_CONE,
                     "goal sensor direction is inside cone 'sun'"),
    "too many cones": (dict(cones=[([0, 0, 1], 0.1, "c")] * (MAX_CONES + 1)), ErrorCode.SIZE_LIMIT, "at most"),
    "thousands of cones": (dict(cones=[([0, 0, 1], 0.1, "c")] * 5000), ErrorCode.SIZE_LIMIT, "5000 cones"),
    "semi-free target nan": (dict(semi_free=True, sensor_target=[NAN, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS,
                             "sensor_target"),
    "semi-free target in cone": (dict(semi_free=True, sensor_target=[0.5, 0.866, 0]), ErrorCode.SENSOR_IN_CONE,
                                 "sensor_target"),
    # spacecraft
    "unknown spacecraft": (dict(spacecraft="no_such_craft"), ErrorCode.UNKNOWN_SPACECRAFT, "no_such_craft"),
    "path traversal name": (dict(spacecraft="../../etc/passwd"), ErrorCode.UNKNOWN_SPACECRAFT, "configuration name"),
    # method and options
    "unknown method": (dict(method="teleport"), ErrorCode.UNKNOWN_METHOD, "teleport"),
    "unknown option": (dict(option_names=["warp"], option_values=[1.0]), ErrorCode.INVALID_OPTION, "warp"),
    "option out of range": (dict(option_names=["samples"], option_values=[5.0]), ErrorCode.INVALID_OPTION, "outside"),
    "option absurd size": (dict(option_names=["samples"], option_values=[1e9]), ErrorCode.INVALID_OPTION, "outside"),
    "option not integer": (dict(option_names=["samples"], option_values=[100.5]), ErrorCode.INVALID_OPTION, "integer"),
    "option nan": (dict(option_names=["samples"], option_values=[NAN]), ErrorCode.INVALID_OPTION, "outside"),
    "option lists differ": (dict(option_names=["samples", "x"], option_values=[100.0]), ErrorCode.INVALID_OPTION,
                            "option_values"),
    "millions of options": (dict(option_names=["samples"] * 1_000_000, option_values=[100.0] * 1_000_000),
                            ErrorCode.SIZE_LIMIT, "at most"),
    # budget
    "negative budget": (dict(time_budget=-1.0), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
    "nan budget": (dict(time_budget=NAN), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
    "huge budget": (dict(time_budget=1e6), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
}


@pytest.mark.parametrize("name", sorted(BAD_REQUESTS))
def test_bad_request_is_rejected_with_code_and_sentence(name):
    fields, code, words = BAD_REQUESTS[name]
    with pytest.raises(RequestError) as err:
        validate(request(**fields))
    assert err.value.code == code
    assert words in err.value.message


def test_there_are_more_than_thirty_distinct_bad_requests():
    assert len(BAD_REQUESTS) >= 30


def test_bad_spacecraft_configs_are_rejected(tmp_path, monkeypatch):
    monkeypatch.setenv("ATT_CONFIG_PATH", str(tmp_path))
    cases = {
        "not_spd": ("inertia: [1, 0, 0, 0, -1, 0, 0, 0, 1]", "positive definite"),
        "asymmetric": ("inertia: [1, 0.5, 0, 0, 1, 0, 0, 0, 1]", "symmetric"),
        "triangle": ("inertia: [1, 1, 5]", "triangle inequality"),
        "zero_torque": ("inertia: [1, 1, 1]\n      torque_max: 0.0", "torque_max"),
        "neg_wheel": ("inertia: [1, 1, 1]\n      torque_max: 1.0\n      wheel_torque_max: -1", "wheel_torque_max"),
    }
    for name, (body, words) in cases.items():
        (tmp_path / f"{name}.yaml").write_text(f"/**:\n  ros__parameters:\n    spacecraft:\n      {body}\n")
        with pytest.raises(RequestError) as err:
            validate(request(spacecraft=name))
        assert err.value.code == ErrorCode.INVALID_SPACECRAFT and words in err.value.message, name


def test_near_unit_quaternion_is_normalised_within_tolerance():
    valid = validate(request(q_initial=[0, 0, 0, 1.0005], cones=[]))
    assert np.linalg.norm(valid.problem.q_initial) == pytest.approx(1.0, abs=1e-15)


@pytest.fixture(scope="module", autouse=True)
def fork_server():
    warm_up()          # as the planner node does at start-up


def misbehaving(function: str) -> Method:
    return Method(function, "misbehaving_methods", function, "test")


@pytest.mark.parametrize("function", ["plan_ignores_deadline", "plan_crashes", "plan_raises"])
def test_faulty_solver_gives_a_verified_fallback_within_the_budget(function):
    valid = validate(request(cones=[EARTH], time_budget=3.0))     # eigenaxis clears the Earth cone
    valid = replace(valid, method=misbehaving(function))
    start = time.monotonic()
    outcome = plan_maneuver(valid, Tolerances(), runner=run_isolated)
    elapsed = time.monotonic() - start
    assert elapsed < 3.0 + 1.5, f"budget of 3 s overrun: {elapsed:.2f} s"
    assert outcome.code == ErrorCode.OK and outcome.plan.status == STATUS_FALLBACK
    assert outcome.verification.min_cone_margin > 0
    assert outcome.verification.final_attitude_error < math.radians(1)


def test_no_fallback_when_the_eigenaxis_enters_a_cone():
    valid = replace(validate(request(time_budget=2.0)), method=misbehaving("plan_raises"))
    outcome = plan_maneuver(valid, Tolerances(), runner=run_method)
    assert outcome.code == ErrorCode.SOLVER_FAILED and "solver exploded" in outcome.message
    assert outcome.verification is None


def test_budget_expiry_is_reported_as_such():
    valid = replace(validate(request(cones=[], time_budget=1.0)), method=misbehaving("plan_ignores_deadline"))
    outcome = plan_maneuver(valid, Tolerances(), runner=run_isolated)
    assert outcome.plan.status == STATUS_FALLBACK and "time budget" in outcome.message


def test_semi_free_plan_is_judged_on_the_integrated_boresight():
    target = np.array([0.0, 1.0, 0.0])         # sensor x_b must end along inertial y; roll free
    valid = validate(request(cones=[EARTH], semi_free=True, sensor_target=target, method="time_optimal",
                             time_budget=30.0))
    outcome = plan_maneuver(valid, Tolerances(), runner=run_method)
    assert outcome.code == ErrorCode.OK, outcome.message
    assert outcome.verification.final_attitude_error < math.radians(0.5)      # boresight error here
    reached = rot.dcm(outcome.plan.q[-1]) @ np.array([1.0, 0, 0])
    assert reached @ target > math.cos(math.radians(0.5))
