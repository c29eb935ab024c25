"""The planner's service logic without ROS: solve with the requested method, verify, fall back.

:func:`plan_maneuver` runs a validated request's method, integrates the returned torques through
the truth dynamics (:mod:`att_planner.verification`) and accepts the plan only if it meets the
tolerances. A method that fails, raises or runs out of budget without a plan that verifies is
replaced by the smooth eigenaxis slew when that one verifies (status FALLBACK); otherwise the
answer is an error. No unverified plan ever leaves. :func:`plan_schedule_request` does the same
for a schedule (no fallback exists there).
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Cone, Plan, Status, Verification
from att_planner.cones import direction_margins, endpoint_directions
from att_planner.methods import Method
from att_planner.methods.eigenaxis import METHOD as FALLBACK_METHOD
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_planner.service.requests import ValidRequest, ValidSchedule
from att_planner.verification import TOLERANCES, Tolerances, rejection, verify

VERIFY_RESERVE = 0.2        # fraction of the time budget kept for verification and fallback
VERIFY_RESERVE_MAX = 3.0    # s


def verify_reserve(time_budget: float) -> float:
    """Seconds of a request's budget kept back from the solver for verification and fallback."""
    return min(VERIFY_RESERVE * time_budget, VERIFY_RESERVE_MAX)


@dataclass
class PlanOutcome:
    """The answer to a request: an error code, a sentence and the plan (with its verification
    when accepted)."""

    code: ErrorCode
    message: str
    plan: Plan | None

    @property
    def verification(self) -> Verification | None:
        return self.plan.verification if self.plan is not None and self.code == ErrorCode.OK else None


def padded(problem: ManeuverProblem, padding: float) -> ManeuverProblem:
    """The problem with every cone widened by ``padding`` rad (execution margin for the tracking
    controller), but never so much that the start or goal boresight would fall inside it."""
    if padding <= 0 or not problem.cones:
        return problem
    ends = endpoint_directions(problem.q_initial, problem.q_final, problem.sensor_axis, problem.sensor_target)
    room = np.min(direction_margins(np.array(list(ends.values())), problem.cones), axis=0)
    cones = [Cone(c.direction, c.half_angle + min(padding, 0.5 * r), c.name) for c, r in zip(problem.cones, room)]
    return replace(problem, cones=cones)


def run_method(method: Method, problem: ManeuverProblem, options: dict, wait: float | None = None) -> Plan:
    """Call the method in this process; an exception becomes a FAILED plan whose ``stats`` hold it
    (never an exception in the executor). ``wait`` is unused here: an in-process method is trusted
    to honour the deadline."""
    start = time.perf_counter()
    try:
        plan = method.call(problem, **options)
    except Exception as exc:  # any solver failure is reported, the node keeps serving
        plan = Plan(method=method.name, status=Status.FAILED, message=f"{type(exc).__name__}: {exc}",
                    stats={"exception": repr(exc)})
    plan.wall_time = plan.wall_time or time.perf_counter() - start
    return plan


def plan_maneuver(valid: ValidRequest, tol: Tolerances = TOLERANCES, cone_padding: float = 0.0,
                  runner: Callable = run_method) -> PlanOutcome:
    """Plan with cones widened by ``cone_padding`` rad, verify against the requested cones, fall
    back to the eigenaxis slew when that is safe.

    The method gets the request's deadline minus a reserve for verification and fallback
    (:data:`VERIFY_RESERVE` of the budget, at most :data:`VERIFY_RESERVE_MAX` s). ``runner``
    executes it (:func:`run_method` in-process, or :func:`att_planner.service.worker.run_isolated`
    in a child process that is killed if it overruns); ``None`` from the runner means it overran.
    """
    problem = valid.problem
    method_deadline = problem.deadline - verify_reserve(valid.time_budget) if problem.deadline is not None else None
    wait = None if method_deadline is None else max(0.0, method_deadline - time.monotonic())
    plan = runner(valid.method, replace(padded(problem, cone_padding), deadline=method_deadline), valid.options, wait)
    if plan is None:
        plan = Plan(method=valid.method.name, status=Status.BUDGET_EXPIRED,
                    message=f"time budget of {valid.time_budget:g} s expired before {valid.method.name} "
                            "returned a plan")
    reason = plan.message or plan.status
    if plan.success:
        plan.verification = verify(problem, plan)
        reason = rejection(plan.verification, tol)
        if reason is None:
            return PlanOutcome(ErrorCode.OK, plan.message or plan.status, plan)
        reason = f"{valid.method.name} plan rejected by verification: {reason}"
    # fallback: the smooth eigenaxis slew, if it is safe
    if problem.sensor_target is None and valid.method.name != FALLBACK_METHOD:
        fallback = plan_eigenaxis_smooth(problem)
        fallback.verification = verify(problem, fallback)
        if fallback.status != Status.FAILED and rejection(fallback.verification, tol) is None:
            fallback.status = Status.FALLBACK
            fallback.message = f"{reason}; returning the eigenaxis fallback ({fallback.message})"
            return PlanOutcome(ErrorCode.OK, fallback.message, fallback)
    budget_note = " (time budget expired)" if plan.status == Status.BUDGET_EXPIRED else ""
    code = ErrorCode.VERIFICATION_FAILED if "verification" in reason else ErrorCode.SOLVER_FAILED
    if problem.cones and code == ErrorCode.SOLVER_FAILED and "infeasib" in reason.lower():
        code = ErrorCode.INFEASIBLE
    return PlanOutcome(code, f"no verified plan{budget_note}: {reason}", plan)


def plan_schedule_request(valid: ValidSchedule, tol: Tolerances = TOLERANCES, *, runner: Callable) -> PlanOutcome:
    """Plan a validated schedule request within its budget through ``runner(problem, wait)``
    (``None``: overran; a string: the solver died) and accept it only if it verifies."""
    wait = max(0.0, valid.time_budget - verify_reserve(valid.time_budget))
    plan = runner(replace(valid.problem, deadline=time.monotonic() + wait), wait)
    if plan is None or isinstance(plan, str):
        return PlanOutcome(ErrorCode.SOLVER_FAILED,
                           plan or f"time budget of {valid.time_budget:g} s expired without a schedule", None)
    if not plan.success or plan.verification is None:
        code = ErrorCode.VERIFICATION_FAILED if plan.verification else ErrorCode.SOLVER_FAILED
        return PlanOutcome(code, f"no verified schedule: {plan.message}", None)
    why = rejection(plan.verification, tol)
    if why is not None:
        return PlanOutcome(ErrorCode.VERIFICATION_FAILED, f"no verified schedule: {plan.message}; {why}", None)
    return PlanOutcome(ErrorCode.OK, plan.message, plan)
