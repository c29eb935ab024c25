"""The planner's service logic without ROS: a first plan, the requested method, verify, fall back.

:func:`plan_maneuver` answers in stages (anytime planning): the constructive first plan
(:data:`FIRST_METHOD`, tens of milliseconds), then the requested method seeded with it as long as
the budget allows, then, if neither verified, the smooth eigenaxis slew. Each plan is integrated
through the prediction model (:mod:`att_planner.verification`) and accepted only if it meets the
tolerances; the method's accepted plan is returned, else the first plan (status BUDGET_EXPIRED
when the budget left the method no time or ran out in it, FALLBACK when the method failed), else
the eigenaxis slew with status FALLBACK when only it verifies; otherwise the answer is an error. No unverified
plan ever leaves, and the outcome reports every stage and its time. Zones travel in the
problem: the method plans against their motion (:meth:`ManeuverProblem.zone_sky`), padded like the
cones (:func:`padded`), and every plan, the fallback's too, is verified against the unpadded zones
at their true positions. :func:`plan_schedule_request` does the same for a schedule (no fallback
exists there).

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
from dataclasses import dataclass, field, replace

import numpy as np

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Cone, Plan, Stage, StageReport, Status, Verification
from att_msgs_py.validation import MAX_PLAN_SAMPLES
from att_planner import methods
from att_planner.cones import direction_margins, endpoint_directions
from att_planner.methods import Method
from att_planner.methods.eigenaxis import METHOD as FALLBACK_METHOD
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_planner.service.requests import ValidRequest, ValidSchedule
from att_planner.service.sky import lattice
from att_planner.service.wheels import slow_for_wheels
from att_planner.verification import TOLERANCES, VERIFY_STEPS, Tolerances, rejection, verify
from att_sim.models.ephemeris import de421
from att_sim.models.epoch import timescale

VERIFY_RESERVE = 0.1        # fraction of the time budget kept for verification and fallback
VERIFY_RESERVE_MIN = 0.1    # s (at most half the budget)
VERIFY_RESERVE_MAX = 3.0    # s
ANSWER_GRACE = 1.0          # s an answer may come after the request's time budget
ANSWER_MARGIN = 0.3         # s of that kept for building, signing and sending the answer
FALLBACK_SAMPLES = 401      # knots of the eigenaxis fallback (its default)
FIRST_METHOD = "graph_smooth"   # the constructive first plan of every request for a method that is not cheap
MIN_METHOD_SECONDS = 0.05   # s of its deadline the requested method needs at least, after the first plan
WHEEL_SPEED = "wheel speed"     # how rejection() names a wheel beyond its speed limit
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
    ephemeris and the time scale of the real sky, the imports of the methods' option checks, the
    compiled integrator, a first plan and a first measure of the verification cost."""
    lattice()
    de421()
    timescale()
    for method in methods.REGISTRY:
        method.validate({})
    problem = ManeuverProblem(spacecraft, np.array([0.0, 0.0, 0.0, 1.0]), np.array([0.0, 0.0, 0.5 ** 0.5, 0.5 ** 0.5]))
    timed_verify(problem, plan_eigenaxis_smooth(problem, samples=FALLBACK_SAMPLES))
    timed_verify(problem, run_method(methods.get(FIRST_METHOD), problem, {}))


@dataclass
class PlanOutcome:
    """The answer to a request: an error code, a sentence and the plan (with its verification
    when accepted)."""

    code: ErrorCode
    message: str
    plan: Plan | None
    stage: Stage | str = ""                                   # the stage whose plan is returned
    stages: list[StageReport] = field(default_factory=list)   # every stage, in order

    @property
    def slowdown(self) -> float:
        """How many times slower than its method planned it the plan flies (1: as planned; :mod:`.wheels`)."""
        accepted = self.plan is not None and self.code == ErrorCode.OK
        return float(self.plan.stats.get("slowdown", 1.0)) if accepted else 1.0

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
    return (f"{plan.method or 'the method'} returned its plan of {len(plan.t)} samples too late to verify it within "
            f"the time budget of {valid.time_budget:g} s (+{ANSWER_GRACE:g} s)")


@dataclass
class _Stage:
    """A stage's plan, its report, why the plan cannot be returned ('' when it verified) and whether
    that is its size (:func:`too_many_samples`)."""

    plan: Plan
    report: StageReport
    reason: str = ""
    oversize: bool = False


def _run_stage(name: Stage, method: Method, problem: ManeuverProblem, options: dict, runner: Callable,
               wait: float | None, valid: ValidRequest, tol: Tolerances, fallback: bool) -> _Stage:
    """Run ``method`` through ``runner`` and verify its plan against the unpadded problem when that
    still fits the budget (:func:`_no_time_to_verify`, ``fallback``: with the fallback's)."""
    start = time.perf_counter()
    plan = runner(method, problem, options, wait)
    if plan is None:
        plan = Plan(method=method.name, status=Status.BUDGET_EXPIRED,
                    message=f"time budget of {valid.time_budget:g} s expired before {method.name} returned a plan")
    reason = plan.message or str(plan.status)
    oversize = too_many_samples(plan) if plan.success else ""
    if oversize:
        reason = oversize
    elif plan.success:
        reason = _no_time_to_verify(valid, plan, fallback)
        if reason:
            plan.status = Status.BUDGET_EXPIRED
        else:
            plan.verification = timed_verify(valid.problem, plan)
            why = rejection(plan.verification, tol)
            if why is not None and why.startswith(WHEEL_SPEED):
                plan, why = _slowed_for_wheels(valid.problem, plan, why, tol)
            reason = "" if why is None else f"{method.name} plan rejected by verification: {why}"
    report = StageReport(name, method.name, time.perf_counter() - start, str(plan.status), not reason,
                         plan.duration if len(plan.t) else float("nan"), reason or plan.message)
    return _Stage(plan, report, reason, bool(oversize))


def _slowed_for_wheels(problem: ManeuverProblem, plan: Plan, why: str, tol: Tolerances) -> tuple[Plan, str | None]:
    """``plan`` slowed in time to keep its wheels within their speed limit (:mod:`.wheels`) and verified
    again, with why it is still not acceptable (None: it is); the plan as it was when it cannot be slowed."""
    slowed, why_not = slow_for_wheels(problem, plan)
    if slowed is None:
        return plan, f"{why}; not slowed: {why_not}"
    slowed.verification = timed_verify(problem, slowed)
    again = rejection(slowed.verification, tol)
    if again is not None:
        return plan, f"{why}; slowed {slowed.stats['slowdown']:.3f} times it is rejected too: {again}"
    before, after = plan.verification.wheel_speed_ratio, slowed.verification.wheel_speed_ratio
    slowed.message = (f"{plan.message}; slowed {slowed.stats['slowdown']:.3f} times (t_f {plan.duration:.6g} -> "
                      f"{slowed.duration:.6g} s) to keep the wheels within their speed limit ({before:.3f} -> "
                      f"{after:.3f} of it)")
    return slowed, None


def _first_plan_answer(first: _Stage, method: _Stage | None, valid: ValidRequest) -> tuple[Status, str]:
    """Status and message of the first plan returned instead of the method's: BUDGET_EXPIRED when the
    budget left no time for the method (or ran out in it), FALLBACK when the method failed or its plan
    was rejected."""
    note = f"returning the first plan ({first.plan.message})"
    if method is None:
        return Status.BUDGET_EXPIRED, (f"time budget of {valid.time_budget:g} s: no time left for {valid.method.name} "
                                       f"after the first plan; {note}")
    status = Status.BUDGET_EXPIRED if method.plan.status == Status.BUDGET_EXPIRED else Status.FALLBACK
    return status, f"{method.reason}; {note}"


def plan_maneuver(valid: ValidRequest, tol: Tolerances = TOLERANCES, cone_padding: float = 0.0,
                  runner: Callable = run_method) -> PlanOutcome:
    """Plan in stages with zones padded by ``cone_padding`` rad, verify against the requested zones,
    answer with the method's verified plan, else the first plan, else the eigenaxis fallback when that
    is safe.

    1. *first*: :data:`FIRST_METHOD`'s constructive plan, in-process (not for a cheap method, which
       is answered at once): the quick answer, and the seed of the method. When it finds no plan
       among the padded zones, it tries the zones as requested.
    2. *method*: the requested method, seeded with the first plan (``warm_starts``, for a method
       that takes them), when at least :data:`MIN_METHOD_SECONDS` are left of its deadline: the
       request's deadline minus a reserve for verification and fallback (:func:`verify_reserve`).
       ``runner`` executes it (:func:`run_method` in-process, or
       :func:`att_planner.service.worker.run_isolated` in a child process that is killed if it
       overruns); ``None`` from the runner means it overran.
    3. *fallback*: the smooth eigenaxis slew, when no stage's plan verified and it is safe.

    Every stage is reported (:class:`StageReport`) with its wall time, and the outcome names the
    stage whose plan it returns. The plan carries the problem's epoch (the instant of its t = 0).
    """
    outcome = _plan_in_stages(valid, tol, cone_padding, runner)
    if outcome.plan is not None:
        outcome.plan.epoch = valid.problem.epoch
    return outcome


def _plan_in_stages(valid: ValidRequest, tol: Tolerances, cone_padding: float, runner: Callable) -> PlanOutcome:
    """:func:`plan_maneuver`'s stages."""
    problem = valid.problem
    planned = padded(problem, cone_padding)
    rest_to_rest = problem.goal_motion is None          # a moving goal: the eigenaxis fallback cannot end on it
    can_fall_back = problem.sensor_target is None and valid.method.name != FALLBACK_METHOD and rest_to_rest
    done: list[_Stage] = []
    first = None
    if not valid.method.cheap:
        first = _run_stage(Stage.FIRST, methods.get(FIRST_METHOD), planned, {}, run_method, None, valid, tol, False)
        if not first.report.verified and planned is not problem:   # the padding may close a way the zones leave
            first = _run_stage(Stage.FIRST, methods.get(FIRST_METHOD), problem, {}, run_method, None, valid, tol,
                               False)
        done.append(first)
        first = first if first.report.verified else None
    method_deadline = problem.deadline - verify_reserve(valid.time_budget) if problem.deadline is not None else None
    wait = None if method_deadline is None else max(0.0, method_deadline - time.monotonic())
    method = None
    if first is None or wait is None or wait >= MIN_METHOD_SECONDS:
        options = dict(valid.options)
        if first is not None and valid.method.seeded:
            options["warm_starts"] = (first.plan,)
        method = _run_stage(Stage.METHOD, valid.method, replace(planned, deadline=method_deadline), options, runner,
                            wait, valid, tol, can_fall_back and first is None)
        done.append(method)
        if first is None and method.oversize:
            return PlanOutcome(ErrorCode.SIZE_LIMIT, method.reason, None, stages=[s.report for s in done])
    else:
        done.append(_Stage(Plan(method=valid.method.name), StageReport(
            Stage.METHOD, valid.method.name, 0.0, message=f"not run: {wait:.3f} s left of its deadline after the "
                                                           f"first plan (at least {MIN_METHOD_SECONDS:g} s needed)")))
    reports = [s.report for s in done]
    if method is not None and method.report.verified:
        return PlanOutcome(ErrorCode.OK, method.plan.message or method.plan.status, method.plan, Stage.METHOD, reports)
    if first is not None:
        first.plan.status, first.plan.message = _first_plan_answer(first, method, valid)
        return PlanOutcome(ErrorCode.OK, first.plan.message, first.plan, Stage.FIRST, reports)
    plan, reason = method.plan, method.reason
    if can_fall_back:           # the smooth eigenaxis slew, if it is safe
        start = time.perf_counter()
        fallback = plan_eigenaxis_smooth(problem, samples=FALLBACK_SAMPLES)
        fallback.verification = timed_verify(problem, fallback)
        safe = fallback.status != Status.FAILED and rejection(fallback.verification, tol) is None
        reports.append(StageReport(Stage.FALLBACK, FALLBACK_METHOD, time.perf_counter() - start, str(fallback.status),
                                   safe, fallback.duration, fallback.message))
        if safe:
            fallback.status = Status.FALLBACK
            fallback.message = f"{reason}; returning the eigenaxis fallback ({fallback.message})"
            return PlanOutcome(ErrorCode.OK, fallback.message, fallback, Stage.FALLBACK, reports)
    budget_note = " (time budget expired)" if plan.status == Status.BUDGET_EXPIRED else ""
    code = ErrorCode.VERIFICATION_FAILED if "verification" in reason else ErrorCode.SOLVER_FAILED
    saturating = [s.reason for s in done if f"verification: {WHEEL_SPEED}" in s.reason]
    if saturating:
        code, reason = ErrorCode.WHEEL_SATURATION, saturating[0]
    if (problem.cones or problem.zones) and code == ErrorCode.SOLVER_FAILED and "infeasib" in reason.lower():
        code = ErrorCode.INFEASIBLE
    return PlanOutcome(code, f"no verified plan{budget_note}: {reason}", plan, stages=reports)


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
