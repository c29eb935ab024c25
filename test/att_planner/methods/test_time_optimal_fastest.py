"""The time-optimal answer is never slower than a verified warm start: with an NLP made to land on
a slow optimum (every refined solution slowed in time by 10 %, the same path flown slower), the
answer is the verified warm start or a further start as fast; an unverified warm start is never
the answer."""
from __future__ import annotations

from dataclasses import replace

import pytest

from att_msgs_py.types import Status
from att_planner import methods
from att_planner.methods.time_optimal import planner
from att_planner.methods.time_optimal.fastest import checked
from att_planner.methods.time_optimal.smooth import plan_smooth_collocation
from att_planner.verification import rejection, verify

SLOWER = 1.10


def slowed(plan, c: float):
    """The same path flown ``c`` times slower from rest: times × c, rates / c, torques / c²."""
    return replace(plan, t=plan.t * c, omega=plan.omega / c, torque=plan.torque / c**2, verification=None)


@pytest.fixture
def slow_nlp(monkeypatch):
    """Every refined, verified NLP answer slowed by :data:`SLOWER` (still verified: the same path
    within the torque limit): a slow local optimum. ``calls`` counts the answers; ``slow_only``
    lists the calls slowed (all when None)."""
    real = planner._Incumbent.verified
    state = {"calls": 0, "slow_only": None}

    def verified(self, extra):
        ok, plan = real(self, extra)
        state["calls"] += 1
        if ok and (state["slow_only"] is None or state["calls"] in state["slow_only"]):
            plan = slowed(plan, SLOWER)
            plan.verification = verify(self.run.problem, plan)
            ok = rejection(plan.verification) is None
        return ok, plan

    monkeypatch.setattr(planner._Incumbent, "verified", verified)
    return state


def test_a_faster_verified_warm_start_is_never_beaten(swift_plan, slow_nlp):
    problem, optimum = swift_plan
    warm = replace(optimum, method="fast_method")
    plan = planner.plan_time_optimal(problem, starts=1, warm_starts=(warm,))
    assert plan.duration <= warm.duration
    assert plan.status == Status.FEASIBLE and plan.method == planner.METHOD
    assert "slower than the warm start of fast_method" in plan.message and "returning the verified" in plan.message
    fastest = plan.stats["fastest"]
    assert fastest["nlp_tf"] == pytest.approx(SLOWER * optimum.duration, rel=0.02)
    assert fastest["answer"] == "warm start: fast_method" and fastest["further_starts"]
    assert rejection(verify(problem, plan)) is None


def test_a_further_start_as_fast_as_the_warm_start_is_the_answer(swift_plan, slow_nlp):
    problem, optimum = swift_plan
    slow_nlp["slow_only"] = {1}                      # only the first answer lands slow
    warm = replace(slowed(optimum, 1.02), method="fast_method")     # verified, 2 % slower than the optimum
    plan = planner.plan_time_optimal(problem, starts=1, warm_starts=(warm,))
    assert plan.duration <= warm.duration and plan.status in (Status.OPTIMAL, Status.FEASIBLE)
    assert plan.stats["fastest"]["answer"].startswith("further start")
    assert "slower than the warm start of fast_method" in plan.message
    assert rejection(verify(problem, plan)) is None


def test_a_faster_warm_start_that_fails_verification_is_not_the_answer(swift_plan, slow_nlp):
    problem, optimum = swift_plan
    too_fast = replace(slowed(optimum, 0.9), method="too_fast")   # torque beyond its limit
    assert checked(problem, too_fast) is None
    plan = planner.plan_time_optimal(problem, starts=1, warm_starts=(too_fast,))
    assert plan.stats["fastest"]["checked"] == [{"method": "too_fast", "tf": too_fast.duration, "verified": False}]
    assert plan.stats["fastest"]["answer"] == "nlp" and plan.duration > too_fast.duration
    assert plan.duration == pytest.approx(SLOWER * optimum.duration, rel=0.02)


def test_without_a_faster_warm_start_nothing_more_is_solved(swift_plan):
    problem, optimum = swift_plan
    slow = slowed(optimum, 1.5)
    plan = planner.plan_time_optimal(problem, starts=1, warm_starts=(slow,))
    assert plan.stats["fastest"] == {"nlp_tf": plan.duration, "checked": [], "further_starts": [], "answer": "nlp"}
    assert "further_starts" not in plan.stats["seconds"]


def test_the_registry_seeds_time_optimal_with_the_smooth_plan(swift_plan):
    problem, _ = swift_plan
    plan = methods.run("time_optimal", problem, starts=1)
    labels = [s["route"] for s in plan.stats["starts"]]
    assert labels[-1] == "warm start: smooth_collocation" and "smooth_seed" in plan.stats["seconds"]
    smooth = plan_smooth_collocation(problem)
    assert rejection(smooth.verification) is None and 0 < plan.duration <= smooth.duration
