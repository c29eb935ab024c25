"""Through the planner service, the time-optimal answer is never slower than the verified first plan
or the verified smooth plan of the same request, on random keep-out sets
(:mod:`att_planner.reference.random_keepout`) planned as the node plans them (its default cone
padding), every answer re-verified on the unpadded problem."""
from __future__ import annotations

import math
import time
from dataclasses import replace
from functools import cache

import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Stage
from att_planner import methods
from att_planner.reference.random_keepout import keepout_set
from att_planner.service.planner_parameters import PLANNER
from att_planner.service.planning import plan_maneuver, run_method
from att_planner.service.requests import ValidRequest
from att_planner.verification import rejection, verify

BUDGET_S = 20.0
COARSE = {"intervals": 4, "max_intervals": 4}
COARSE_ONE_START = {"starts": 1, "intervals": 6, "max_intervals": 6, "refine_rounds": 0}
# (seed, time_optimal's options, how the answer comes). Without the warm-start check the service
# answers the coarse requests of sets 0 and 37 with its first plan (7.35 and 7.63 TU: the method's
# plan fails verification) while the smooth plan flies 3.77 and 3.34 TU.
CASES = [(37, {}, "nlp"), (0, COARSE, "further start"), (37, COARSE, "warm start: smooth_collocation"),
         (37, COARSE_ONE_START, "further start")]


def answer(problem, method: str, options: dict):
    valid = ValidRequest(replace(problem, deadline=time.monotonic() + BUDGET_S), methods.get(method),
                         methods.get(method).validate(options), "swift", BUDGET_S)
    outcome = plan_maneuver(valid, cone_padding=math.radians(PLANNER["cone_padding_deg"].default), runner=run_method)
    assert outcome.code == ErrorCode.OK, outcome.message
    assert rejection(verify(problem, outcome.plan)) is None, (method, outcome.message)
    return outcome


@cache
def smooth_answer(seed: int):
    return answer(keepout_set(seed), "smooth_collocation", {})


@pytest.mark.parametrize("seed, options, source", CASES)
def test_time_optimal_is_never_slower_than_the_verified_first_or_smooth_plan(seed, options, source):
    problem = keepout_set(seed)
    smooth = smooth_answer(seed)
    fastest = answer(problem, "time_optimal", options)
    assert smooth.stage == Stage.METHOD and fastest.stage == Stage.METHOD, fastest.message
    first = fastest.stages[0]
    assert first.name == Stage.FIRST and first.verified
    assert fastest.plan.duration <= min(smooth.plan.duration, first.duration), (seed, fastest.message)
    assert fastest.plan.stats["fastest"]["answer"].startswith(source), fastest.plan.stats["fastest"]
    if source != "nlp":
        assert "slower than the warm start" in fastest.message or "fails truth verification" in fastest.message
