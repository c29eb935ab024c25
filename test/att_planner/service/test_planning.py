"""The planner service: its stages (the first plan, the method seeded with it, the fallback), solver
faults, budget expiry and fallbacks, semi-free goals judged on the integrated boresight."""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Stage, Status
from att_planner.methods import Method
from att_planner.service.planning import plan_maneuver, run_method
from att_planner.service.worker import run_isolated, warm_up
from att_planner.verification import TOLERANCES
from att_sim.models import rotations as rot
from helpers.maneuver_requests import EARTH, request, validate


@pytest.fixture(scope="module", autouse=True)
def fork_server():
    warm_up()          # as the planner node does at start-up


def misbehaving(function: str, cheap: bool = False) -> Method:
    return Method(function, "helpers.misbehaving_methods", function, "test", cheap=cheap)


@pytest.mark.parametrize("function, status", [("plan_ignores_deadline", Status.BUDGET_EXPIRED),
                                              ("plan_crashes", Status.FALLBACK), ("plan_raises", Status.FALLBACK)])
def test_a_faulty_solver_is_answered_with_the_verified_first_plan_within_the_budget(function, status):
    """The first stage's plan (graph_smooth) stands in for a method that overruns (BUDGET_EXPIRED:
    the best plan when the budget ran out), crashes or raises (FALLBACK)."""
    valid = validate(request(time_budget=3.0))
    valid = replace(valid, method=misbehaving(function))
    start = time.monotonic()
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_isolated)
    elapsed = time.monotonic() - start
    assert elapsed < 3.0 + 1.5, f"budget of 3 s overrun: {elapsed:.2f} s"
    assert outcome.code == ErrorCode.OK and outcome.plan.status == status and outcome.stage == Stage.FIRST
    assert outcome.plan.method == "graph_smooth" and "returning the first plan" in outcome.message
    assert [s.name for s in outcome.stages] == [Stage.FIRST, Stage.METHOD]
    assert outcome.stages[0].verified and not outcome.stages[1].verified
    assert outcome.verification.min_cone_margin > 0
    assert outcome.verification.final_attitude_error < math.radians(1)


@pytest.mark.parametrize("function", ["plan_ignores_deadline", "plan_crashes", "plan_raises"])
def test_faulty_cheap_solver_gives_a_verified_eigenaxis_fallback_within_the_budget(function):
    """A method run at once (cheap: no first stage) that fails is replaced by the eigenaxis slew."""
    valid = validate(request(cones=[EARTH], time_budget=3.0))     # eigenaxis clears the Earth cone
    valid = replace(valid, method=misbehaving(function, cheap=True))
    start = time.monotonic()
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_isolated)
    elapsed = time.monotonic() - start
    assert elapsed < 3.0 + 1.5, f"budget of 3 s overrun: {elapsed:.2f} s"
    assert outcome.code == ErrorCode.OK and outcome.plan.status == Status.FALLBACK
    assert outcome.stage == Stage.FALLBACK and [s.name for s in outcome.stages] == [Stage.METHOD, Stage.FALLBACK]
    assert outcome.verification.min_cone_margin > 0
    assert outcome.verification.final_attitude_error < math.radians(1)


def test_no_fallback_when_the_eigenaxis_enters_a_cone():
    valid = replace(validate(request(time_budget=2.0)), method=misbehaving("plan_raises", cheap=True))
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_method)
    assert outcome.code == ErrorCode.SOLVER_FAILED and "solver exploded" in outcome.message
    assert outcome.verification is None and outcome.stage == ""
    assert [(s.name, s.verified) for s in outcome.stages] == [(Stage.METHOD, False), (Stage.FALLBACK, False)]


def test_budget_expiry_is_reported_as_such():
    valid = replace(validate(request(cones=[], time_budget=1.0)), method=misbehaving("plan_ignores_deadline"))
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_isolated)
    assert outcome.plan.status == Status.BUDGET_EXPIRED and "time budget" in outcome.message


def test_a_quick_answer_is_the_verified_first_plan():
    """A 50 ms budget leaves the requested method no time: the first plan, verified, is the answer
    (through the Sun and Earth cones of the Swift maneuver, which the eigenaxis enters)."""
    valid = validate(request(method="smooth_collocation", time_budget=0.05))
    start = time.monotonic()
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_method)
    assert time.monotonic() - start < 0.05 + 1.0
    assert outcome.code == ErrorCode.OK and outcome.stage == Stage.FIRST
    assert outcome.plan.method == "graph_smooth" and outcome.plan.status == Status.BUDGET_EXPIRED
    first, method = outcome.stages
    assert first.verified and first.duration == outcome.plan.duration and first.seconds > 0
    assert method.method == "smooth_collocation" and method.status == "" and "not run" in method.message
    assert outcome.verification.min_cone_margin > 0


def test_the_method_seeded_with_the_first_plan_improves_on_it():
    valid = validate(request(method="smooth_collocation", time_budget=20.0))
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_method)
    assert outcome.code == ErrorCode.OK and outcome.stage == Stage.METHOD
    first, method = outcome.stages
    assert first.verified and method.verified and method.method == outcome.plan.method == "smooth_collocation"
    assert outcome.plan.duration == method.duration < 0.8 * first.duration
    assert outcome.verification.min_cone_margin > 0


def test_semi_free_plan_is_judged_on_the_integrated_boresight():
    target = np.array([0.0, 1.0, 0.0])         # sensor x_b must end along inertial y; roll free
    valid = validate(request(cones=[EARTH], semi_free=True, sensor_target=target, method="time_optimal",
                             time_budget=30.0))
    outcome = plan_maneuver(valid, TOLERANCES, runner=run_method)
    assert outcome.code == ErrorCode.OK, outcome.message
    assert outcome.verification.final_attitude_error < math.radians(0.5)      # boresight error here
    reached = rot.dcm_NB(outcome.plan.q[-1]) @ np.array([1.0, 0, 0])
    assert reached @ target > math.cos(math.radians(0.5))


def test_the_first_plan_falls_back_on_the_unpadded_zones():
    """leo_observatory: the Earth limb rises over the start; padded by 2 deg it overtakes every
    rest-to-rest leg, so the first plan is searched among the zones as requested (verified against them)."""
    from att_planner.methods import get
    from att_planner.methods.graph_smooth import plan_graph_smooth
    from att_planner.service.planning import padded
    from att_planner.service.requests import ValidRequest
    from att_planner.tools.bench.sky import case_problem

    _, problem = case_problem("leo_observatory")
    assert not plan_graph_smooth(padded(problem, math.radians(2.0))).success
    valid = ValidRequest(replace(problem, deadline=time.monotonic() + 0.05), get("smooth_collocation"), {}, "x", 0.05)
    outcome = plan_maneuver(valid, TOLERANCES, cone_padding=math.radians(2.0), runner=run_method)
    assert outcome.code == ErrorCode.OK and outcome.stage == Stage.FIRST and outcome.plan.method == "graph_smooth"
    assert outcome.verification.min_cone_margin >= 0
