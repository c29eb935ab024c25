"""The planner's service logic without ROS: solve with the requested method, verify, fall back.

:func:`plan_maneuver` runs a validated request's method, integrates the returned torques through
the truth dynamics (:mod:`att_planner.verify`) and accepts the plan only if it meets the
tolerances. A method that fails, raises or runs out of budget without a plan that verifies is
replaced by the smooth eigenaxis slew when that one verifies (status ``fallback``); otherwise the
answer is an error. No unverified plan ever leaves.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from att_msgs_py.errors import ErrorCode
from att_planner import eigenaxis
from att_planner.cones import Cone, boresight, direction_margins
from att_planner.problem import STATUS_BUDGET, STATUS_FAILED, STATUS_FALLBACK, ManeuverPlan, ManeuverProblem
from att_planner.methods import Method
from att_planner.requests import ValidRequest
from att_planner.verify import Verification, verify_profile
from att_sim import rotations as rot


VERIFY_RESERVE = 0.2        # fraction of the time budget kept for verification and fallback
VERIFY_RESERVE_MAX = 3.0    # s


def verify_reserve(time_budget: float) -> float:
    """Seconds of a request's budget kept back from the solver for verification and fallback."""
    return min(VERIFY_RESERVE * time_budget, VERIFY_RESERVE_MAX)


@dataclass(frozen=True)
class Tolerances:
    """Acceptance of a plan after integration through the dynamics."""

    attitude: float = math.radians(1.0)     # rad, final attitude error
    rate: float = 1e-3                      # rad/s, final body-rate norm
    cone_margin: float = math.radians(0.1)  # rad of cone penetration tolerated on the dense grid
    torque_ratio: float = 1.0 + 1e-6


@dataclass
class PlanOutcome:
    code: ErrorCode
    message: str
    plan: ManeuverPlan | None
    verification: Verification | None


VERIFY_SAMPLES = 2000       # RK4 steps over the maneuver (at least one per control sample)


def verify(problem: ManeuverProblem, plan: ManeuverPlan) -> Verification:
    """Integrate the plan's torques from the request's start; figures against the request."""
    ver, traj = verify_profile(problem.spacecraft, problem.q_initial, problem.q_final, plan.t, plan.torque,
                               interpolation=plan.interpolation, sensor_axis=problem.sensor_axis,
                               cones=problem.cones, torque_limit=problem.spacecraft.body_torque_max,
                               dense_step=max(plan.duration, 1e-9) / VERIFY_SAMPLES)
    if problem.sensor_target is not None:
        # semi-free goal: judge where the integrated boresight ends, not the full attitude
        reached = rot.dcm(traj.q[-1]) @ problem.sensor_axis
        ver.final_attitude_error = float(np.arccos(np.clip(reached @ problem.sensor_target, -1, 1)))
    return ver


def rejection(ver: Verification, tol: Tolerances) -> str | None:
    """Why a verified plan is not acceptable, or None."""
    if ver.final_attitude_error > tol.attitude:
        return f"final attitude error {math.degrees(ver.final_attitude_error):.3f} deg > {math.degrees(tol.attitude):.3f} deg"
    if ver.final_rate > tol.rate:
        return f"final rate {ver.final_rate:.3g} rad/s > {tol.rate:.3g} rad/s"
    if ver.min_cone_margin < -tol.cone_margin:
        return f"enters a keep-out cone by {math.degrees(-ver.min_cone_margin):.3f} deg"
    if ver.torque_ratio > tol.torque_ratio:
        return f"torque {ver.torque_ratio:.4f} x the limit"
    return None


def padded(problem: ManeuverProblem, padding: float) -> ManeuverProblem:
    """The problem with every cone widened by ``padding`` rad (execution margin for the tracking
    controller), but never so much that the start or goal boresight would fall inside it."""
    if padding <= 0 or not problem.cones:
        return problem
    ends = [problem.q_initial] + ([problem.q_final] if problem.sensor_target is None else [])
    directions = [boresight(q, problem.sensor_axis) for q in ends]
    if problem.sensor_target is not None:
        directions.append(problem.sensor_target)
    room = np.min(direction_margins(np.array(directions), problem.cones), axis=0)
    cones = [Cone(c.direction, c.half_angle + min(padding, 0.5 * r), c.name) for c, r in zip(problem.cones, room)]
    return replace(problem, cones=cones)


def failed_plan(method: str, message: str) -> ManeuverPlan:
    return ManeuverPlan(method, np.zeros(1), np.zeros((1, 3)), np.zeros((1, 4)), np.zeros((1, 3)),
                        status=STATUS_FAILED, message=message)


def run_method(method: Method, problem: ManeuverProblem, options: dict, wait: float | None = None) -> ManeuverPlan:
    """Call the method in this process; exceptions become a failed plan (never an exception in the
    executor). ``wait`` is unused here: an in-process method is trusted to honour the deadline."""
    start = time.perf_counter()
    try:
        plan = method.load()(problem, **method.fixed, **options)
    except Exception as exc:  # noqa: BLE001 - any solver failure is reported, the node keeps serving
        plan = failed_plan(method.name, f"{type(exc).__name__}: {exc}")
    plan.solve_seconds = plan.solve_seconds or time.perf_counter() - start
    return plan


def plan_maneuver(valid: ValidRequest, tol: Tolerances = Tolerances(), cone_padding: float = 0.0,
                  runner: Callable = run_method) -> PlanOutcome:
    """Plan with cones widened by ``cone_padding`` rad, verify against the requested cones, fall
    back to the eigenaxis slew when that is safe.

    The method gets the request's deadline minus a reserve for verification and fallback
    (:data:`VERIFY_RESERVE` of the budget, at most :data:`VERIFY_RESERVE_MAX` s). ``runner``
    executes it (:func:`run_method` in-process, or :func:`att_planner.worker.run_isolated` in a
    child process that is killed if it overruns); ``None`` from the runner means it overran.
    """
    problem = valid.problem
    method_deadline = problem.deadline - verify_reserve(valid.time_budget) if problem.deadline is not None else None
    wait = None if method_deadline is None else max(0.0, method_deadline - time.monotonic())
    plan = runner(valid.method, replace(padded(problem, cone_padding), deadline=method_deadline), valid.options, wait)
    if plan is None:
        plan = failed_plan(valid.method.name, f"time budget of {valid.time_budget:g} s expired before "
                                              f"{valid.method.name} returned a plan")
        plan.status = STATUS_BUDGET
    reason = plan.message or plan.status
    if plan.status != STATUS_FAILED and len(plan.t) >= 2:
        ver = verify(problem, plan)
        reason = rejection(ver, tol)
        if reason is None:
            return PlanOutcome(ErrorCode.OK, plan.message or plan.status, plan, ver)
        reason = f"{valid.method.name} plan rejected by verification: {reason}"
    # fallback: the smooth eigenaxis slew, if it is safe
    if problem.sensor_target is None and valid.method.name != eigenaxis.METHOD:
        fallback = eigenaxis.plan_eigenaxis_smooth(problem)
        ver = verify(problem, fallback)
        if fallback.status != STATUS_FAILED and rejection(ver, tol) is None:
            fallback = replace(fallback, status=STATUS_FALLBACK,
                               message=f"{reason}; returning the eigenaxis fallback ({fallback.message})")
            return PlanOutcome(ErrorCode.OK, fallback.message, fallback, ver)
    budget_note = " (time budget expired)" if plan.status == STATUS_BUDGET else ""
    code = ErrorCode.VERIFICATION_FAILED if "verification" in reason else ErrorCode.SOLVER_FAILED
    if problem.cones and code == ErrorCode.SOLVER_FAILED and "infeasib" in reason.lower():
        code = ErrorCode.INFEASIBLE
    return PlanOutcome(code, f"no verified plan{budget_note}: {reason}", plan, None)


def schedule_plan(result) -> ManeuverPlan:
    """A :class:`~att_planner.schedule.ScheduleResult` as a plan whose controls are wheel torques."""
    return ManeuverPlan("schedule", result.t, result.wheel_torque, result.q, result.omega, result.interpolation,
                        result.status, result.message, result.solve_seconds, result.stats)


def schedule_verification(result) -> Verification:
    """The schedule's truth verification in the plan's verification figures (no cones)."""
    v = result.verification
    return Verification(final_attitude_error=v.final_attitude_error, final_rate=v.final_rate,
                        min_cone_margin=float("inf"), cone_margins=[], torque_ratio=v.torque_ratio,
                        wheel_speed_ratio=v.wheel_speed_ratio, rate_max=float("nan"),
                        duration=float(result.tf), dense_samples=0)
