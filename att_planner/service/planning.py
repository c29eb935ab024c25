"""The planner's service logic without ROS: solve with the requested method, verify, fall back.

:func:`plan_maneuver` runs a validated request's method, integrates the returned torques through
the truth dynamics (:mod:`att_planner.verification`) and accepts the plan only if it meets the
tolerances. A method that fails, raises or runs out of budget without a plan that verifies is
replaced by the smooth eigenaxis slew when that one verifies (status FALLBACK); otherwise the
answer is an error. No unverified plan ever leaves. Zones (issue 13) travel in the problem: the
method plans against their motion (:meth:`ManeuverProblem.zone_sky`), padded like the cones
(:func:`padded`), and every plan, the fallback's too, is verified against the unpadded zones at
their true positions. :func:`plan_schedule_request` does the same
for a schedule (no fallback exists there).

Bounded: a plan of more than :data:`MAX_PLAN_SAMPLES` samples is refused (SIZE_LIMIT) before it is
verified or sent. Every answer comes within the request's budget plus :data:`ANSWER_GRACE`: the
method gets the budget minus a reserve (:func:`verify_reserve`), a child solver is killed soon
after, and a plan is verified only when its verification (and the fallback's, should it be
rejected) still fits, as estimated from the measured cost of an integration step
(:func:`verify_cost`); a plan that does not fit is replaced by the fallback like a failed one.
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Cone, Plan, Status, Verification
from att_msgs_py.validation import MAX_PLAN_SAMPLES
from att_planner import methods
from att_planner.cones import direction_margins, endpoint_directions
from att_planner.methods import Method
from att_planner.methods.eigenaxis import METHOD as FALLBACK_METHOD
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_planner.service.requests import ValidRequest, ValidSchedule
from att_planner.service.sky import lattice
from att_planner.verification import TOLERANCES, VERIFY_STEPS, Tolerances, rejection, verify
from att_sim.ephemeris import de421
from att_sim.epoch import timescale

VERIFY_RESERVE = 0.2        # fraction of the time budget kept for verification and fallback
VERIFY_RESERVE_MIN = 0.25   # s (at most half the budget)
VERIFY_RESERVE_MAX = 3.0    # s
ANSWER_GRACE = 1.0          # s an answer may come after the request's time budget
ANSWER_MARGIN = 0.3         # s of that kept for building, signing and sending the answer
FALLBACK_SAMPLES = 401      # knots of the eigenaxis fallback (its default)
_step_seconds = 2e-4        # running estimate of the wall time of one verification step (s)


def verify_reserve(time_budget: float) -> float:
    """Seconds of a request's budget kept back from the solver for verification and fallback."""
    return min(max(VERIFY_RESERVE * time_budget, min(VERIFY_RESERVE_MIN, 0.5 * time_budget)), VERIFY_RESERVE_MAX)


def verify_cost(samples: int) -> float:
    """Estimated wall time (s) of verifying a plan of ``samples`` knots: the integration takes
    :data:`VERIFY_STEPS` steps plus about one per knot."""
    return (VERIFY_STEPS + samples) * _step_seconds


def timed_verify(problem: ManeuverProblem, plan: Plan) -> Verification:
    """:func:`verify`, keeping the cost estimate of :func:`verify_cost` up to date (it follows a
    slower machine at once, a faster one gradually)."""
    global _step_seconds
    start = time.perf_counter()
    ver = verify(problem, plan)
    per_step = (time.perf_counter() - start) / (VERIFY_STEPS + len(plan.t))
    _step_seconds = max(per_step, 0.8 * _step_seconds + 0.2 * per_step)
    return ver


def prepare(spacecraft) -> None:
    """What the first request would otherwise pay for, done at start: the sky lattice, the DE421
    ephemeris and the time scale of the real sky, the imports of the methods' option checks, and a
    first measure of the verification cost."""
    lattice()
    de421()
    timescale()
    for method in methods.REGISTRY:
        method.validate({})
    problem = ManeuverProblem(spacecraft, np.array([0.0, 0.0, 0.0, 1.0]), np.array([0.0, 0.0, 0.5 ** 0.5, 0.5 ** 0.5]))
    timed_verify(problem, plan_eigenaxis_smooth(problem, samples=FALLBACK_SAMPLES))


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
    """The problem with every cone and keep-out zone widened and every keep-in zone narrowed by
    ``padding`` rad (execution margin for the tracking controller), but never by more than half
    the room the start or goal leaves it (zones as they are at t = 0), so neither end falls inside;
    a cone or zone with an end on its boundary is not padded."""
    if padding <= 0 or not (problem.cones or problem.zones):
        return problem
    cones, zones = problem.cones, problem.zones
    if cones:
        ends = endpoint_directions(problem.q_initial, problem.q_final, problem.sensor_axis, problem.sensor_target)
        room = np.min(direction_margins(np.array(list(ends.values())), cones), axis=0)
        cones = [Cone(c.direction, c.half_angle + min(padding, 0.5 * max(r, 0.0)), c.name) for c, r in zip(cones, room)]
    if zones:
        zone_sky = problem.zone_sky()
        ends = [problem.q_initial] + ([problem.q_final] if problem.sensor_target is None else [])
        room = zone_sky.margins(0.0, np.array(ends), true=True)[:, len(problem.cones):].min(axis=0)
        zones = [replace(z, half_angle=z.half_angle + (-1 if z.keep_in else 1) * min(padding, 0.5 * max(r, 0.0)))
                 for z, r in zip(zones, room)]
    return replace(problem, cones=cones, zones=zones)


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


def too_many_samples(plan: Plan) -> str:
    """Why ``plan`` is too large to verify and send (more than :data:`MAX_PLAN_SAMPLES` samples), or ''."""
    if len(plan.t) <= MAX_PLAN_SAMPLES:
        return ""
    return (f"{plan.method or 'the method'} returned a plan of {len(plan.t)} samples; at most {MAX_PLAN_SAMPLES} "
            "are sent")


def _no_time_to_verify(valid: ValidRequest, plan: Plan, fallback: bool) -> str:
    """Why ``plan`` cannot be verified before the answer is due (its verification, and the
    fallback's when there is one, would not fit), or ''."""
    if valid.problem.deadline is None:
        return ""
    due = valid.problem.deadline + ANSWER_GRACE - ANSWER_MARGIN
    need = verify_cost(len(plan.t)) + (verify_cost(FALLBACK_SAMPLES) if fallback else 0.0)
    if time.monotonic() + need <= due:
        return ""
    return (f"{valid.method.name} returned its plan of {len(plan.t)} samples too late to verify it within the time "
            f"budget of {valid.time_budget:g} s (+{ANSWER_GRACE:g} s)")


def plan_maneuver(valid: ValidRequest, tol: Tolerances = TOLERANCES, cone_padding: float = 0.0,
                  runner: Callable = run_method) -> PlanOutcome:
    """Plan with cones widened by ``cone_padding`` rad, verify against the requested cones, fall
    back to the eigenaxis slew when that is safe.

    The method gets the request's deadline minus a reserve for verification and fallback
    (:func:`verify_reserve`). ``runner`` executes it (:func:`run_method` in-process, or
    :func:`att_planner.service.worker.run_isolated` in a child process that is killed if it
    overruns); ``None`` from the runner means it overran.
    """
    problem = valid.problem
    method_deadline = problem.deadline - verify_reserve(valid.time_budget) if problem.deadline is not None else None
    wait = None if method_deadline is None else max(0.0, method_deadline - time.monotonic())
    plan = runner(valid.method, replace(padded(problem, cone_padding), deadline=method_deadline), valid.options, wait)
    if plan is None:
        plan = Plan(method=valid.method.name, status=Status.BUDGET_EXPIRED,
                    message=f"time budget of {valid.time_budget:g} s expired before {valid.method.name} "
                            "returned a plan")
    oversize = too_many_samples(plan)
    if oversize:
        return PlanOutcome(ErrorCode.SIZE_LIMIT, oversize, None)
    can_fall_back = problem.sensor_target is None and valid.method.name != FALLBACK_METHOD
    reason = plan.message or plan.status
    late = _no_time_to_verify(valid, plan, can_fall_back) if plan.success else ""
    if late:
        reason, plan.status = late, Status.BUDGET_EXPIRED
    elif plan.success:
        plan.verification = timed_verify(problem, plan)
        reason = rejection(plan.verification, tol)
        if reason is None:
            return PlanOutcome(ErrorCode.OK, plan.message or plan.status, plan)
        reason = f"{valid.method.name} plan rejected by verification: {reason}"
    if can_fall_back:           # the smooth eigenaxis slew, if it is safe
        fallback = plan_eigenaxis_smooth(problem, samples=FALLBACK_SAMPLES)
        fallback.verification = timed_verify(problem, fallback)
        if fallback.status != Status.FAILED and rejection(fallback.verification, tol) is None:
            fallback.status = Status.FALLBACK
            fallback.message = f"{reason}; returning the eigenaxis fallback ({fallback.message})"
            return PlanOutcome(ErrorCode.OK, fallback.message, fallback)
    budget_note = " (time budget expired)" if plan.status == Status.BUDGET_EXPIRED else ""
    code = ErrorCode.VERIFICATION_FAILED if "verification" in reason else ErrorCode.SOLVER_FAILED
    if (problem.cones or problem.zones) and code == ErrorCode.SOLVER_FAILED and "infeasib" in reason.lower():
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
    oversize = too_many_samples(plan)
    if oversize:
        return PlanOutcome(ErrorCode.SIZE_LIMIT, oversize, None)
    if not plan.success or plan.verification is None:
        code = ErrorCode.VERIFICATION_FAILED if plan.verification else ErrorCode.SOLVER_FAILED
        return PlanOutcome(code, f"no verified schedule: {plan.message}", None)
    why = rejection(plan.verification, tol)
    if why is not None:
        return PlanOutcome(ErrorCode.VERIFICATION_FAILED, f"no verified schedule: {plan.message}; {why}", None)
    return PlanOutcome(ErrorCode.OK, plan.message, plan)
