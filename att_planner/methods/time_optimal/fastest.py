"""The time-optimal answer is never slower than a verified plan it was given.

The collocation NLP of :mod:`.planner` has many local minima (Melton 2012, 2018): a start in one
homotopy class (the side on which the path passes each zone) converges to that class's optimum, and
the best coarse-mesh optimum need not stay the best after refinement, nor verify. A smooth plan
(minimum time with a C¹ torque, :mod:`.smooth`) may pass the zones in a faster class than every
start of the NLP (``att-bench fastest`` counts such requests on the random keep-out sets of
:mod:`att_planner.reference.random_keepout`). So the planner

- takes the plans of other methods as warm starts (the planner service passes its first plan) and,
  with ``smooth_seed``, the smooth C¹ plan seeded with them (:func:`with_smooth_seed`);
- when its verified answer is slower than a warm start that verifies here (:func:`fastest_verified`,
  the prediction model and the default tolerances), tries further starts within the budget;
- and when it is still slower, answers with that warm start, saying so.

Bang-bang time optimality bounds every smooth plan of the same homotopy class from below, so a
warm start faster than the answer names a class the NLP missed, not a better kind of plan.
"""
from __future__ import annotations

import copy
import time
from dataclasses import replace

from att_msgs_py.types import Plan, Status
from att_planner.problem import ManeuverProblem
from att_planner.verification import measure, predict, rejection

SMOOTH_SEED_SHARE = 0.5     # at most this share of the remaining budget goes to the smooth seed


def with_smooth_seed(problem: ManeuverProblem, warm_starts: tuple, seconds: dict) -> tuple:
    """``warm_starts`` and the smooth C¹ plan of :func:`.smooth.plan_smooth_collocation` (its default
    options) started from them (or, without any, from graph_smooth's plan), with at most
    :data:`SMOOTH_SEED_SHARE` of the time left before ``problem.deadline``; its seconds to
    ``seconds['smooth_seed']``. A failed plan is kept (it still serves as a start when it has a
    trajectory); a moving goal has none (the smooth plans end at rest)."""
    from att_planner.methods.time_optimal.smooth import plan_smooth_collocation  # smooth imports the planner

    if problem.goal_motion is not None:
        return warm_starts
    lap = time.monotonic()
    share = None if problem.deadline is None else lap + SMOOTH_SEED_SHARE * max(0.0, problem.deadline - lap)
    plan = plan_smooth_collocation(replace(problem, deadline=share), warm_starts=warm_starts)
    seconds["smooth_seed"] = time.monotonic() - lap
    return (*warm_starts, plan)


def checked(problem: ManeuverProblem, plan: Plan) -> Plan | None:
    """A copy of ``plan`` with its verification on ``problem`` (prediction model, default tolerances)
    when it is accepted, else None."""
    if not plan.success or len(plan.t) < 2:
        return None
    out = copy.copy(plan)
    out.verification = measure(problem, out, predict(problem, out))
    return out if rejection(out.verification) is None else None


def fastest_verified(problem: ManeuverProblem, warm_starts: tuple, faster_than: float, log: list) -> Plan | None:
    """The fastest of ``warm_starts`` shorter than ``faster_than`` s that verifies on ``problem``
    (:func:`checked`), or None; each plan checked is logged (method, t_f, verified) in ``log``. Plans
    are checked by increasing duration, so no more are integrated than needed."""
    for plan in sorted((p for p in warm_starts if p.success and 1 < len(p.t) and p.duration < faster_than),
                       key=lambda p: p.duration):
        ok = checked(problem, plan)
        log.append({"method": plan.method, "tf": float(plan.duration), "verified": ok is not None})
        if ok is not None:
            return ok
    return None


def warm_start_answer(warm: Plan, method: str, why: str, wall_time: float, stats: dict) -> Plan:
    """``warm`` (verified here) as the planner's answer: status FEASIBLE, the message saying why and
    whose plan it is, ``stats['fastest']['answer']`` naming it."""
    stats["fastest"]["answer"] = f"warm start: {warm.method}"
    return replace(warm, method=method, status=Status.FEASIBLE, wall_time=wall_time, stats=stats,
                   message=f"{why}; returning the verified warm start of {warm.method} (t_f = {warm.duration:.6g} s), "
                           "the fastest verified plan")
