"""The planner service: solver faults, budget expiry and fallbacks, semi-free goals judged on the
integrated boresight."""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Status
from att_planner.methods import Method
from att_planner.service.planning import plan_maneuver, run_method
from att_planner.service.worker import run_isolated, warm_up
from att_planner.verification import TOLERANCES
from att_sim import rotations as rot
from helpers.maneuver_requests import EARTH, request, validate


@pytest.fixture(scope="module", autouse=True)
def fork_server():
    warm_up()          # as the planner node does at start-up


def misbehaving(function: str) -> Method:
    return Method(function, "helpers.misbehaving_methods", function, "test")


@pytest.mark.parametrize("function", ["plan_ignores_deadline", "plan_crashes", "plan_raises"])
def test_faulty_solver_gives_a_verified_fallback_within_the_budget(function):
    valid = validate(request(cones=[EARTH], time_budget=3.0))     # eigenaxis clears the Earth cone
    valid = replace(valid, method=misbehaving(function))
    start = time.monotonic()
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_isolated)
    elapsed = time.monotonic() - start
    assert elapsed < 3.0 + 1.5, f"budget of 3 s overrun: {elapsed:.2f} s"
    assert outcome.code == ErrorCode.OK and outcome.plan.status == Status.FALLBACK
    assert outcome.verification.min_cone_margin > 0
    assert outcome.verification.final_attitude_error < math.radians(1)


def test_no_fallback_when_the_eigenaxis_enters_a_cone():
    valid = replace(validate(request(time_budget=2.0)), method=misbehaving("plan_raises"))
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_method)
    assert outcome.code == ErrorCode.SOLVER_FAILED and "solver exploded" in outcome.message
    assert outcome.verification is None


def test_budget_expiry_is_reported_as_such():
    valid = replace(validate(request(cones=[], time_budget=1.0)), method=misbehaving("plan_ignores_deadline"))
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_isolated)
    assert outcome.plan.status == Status.FALLBACK and "time budget" in outcome.message


def test_semi_free_plan_is_judged_on_the_integrated_boresight():
    target = np.array([0.0, 1.0, 0.0])         # sensor x_b must end along inertial y; roll free
    valid = validate(request(cones=[EARTH], semi_free=True, sensor_target=target, method="time_optimal",
                             time_budget=30.0))
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_method)
    assert outcome.code == ErrorCode.OK, outcome.message
    assert outcome.verification.final_attitude_error < math.radians(0.5)      # boresight error here
    reached = rot.dcm(outcome.plan.q[-1]) @ np.array([1.0, 0, 0])
    assert reached @ target > math.cos(math.radians(0.5))
