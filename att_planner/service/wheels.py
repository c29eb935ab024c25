"""Plans that respect the wheels: a plan whose wheels would pass their speed limit is
slowed in time, or refused.

The wheels that fly a body-torque plan hold the momentum the body gives up
(:func:`att_planner.verification.wheel_speeds_along`): along the path, each wheel's speed relative
to the body is ``S_k + D_k`` — ``S_k`` what the momentum stored at the start becomes as the body
turns (``Ω₀ + G⁺(R_kᵀ H_N − G I_w Ω₀) / I_w``), ``D_k`` the slew's own share
(``−(G⁺ J ω_k) / I_w − Gᵀ ω_k``). Flying the same path ``c`` times slower (``t → c t``, ``ω → ω / c``,
body torque → torque / c², exact for the rigid body from rest to rest) keeps ``S_k`` and divides
``D_k`` by ``c``; the smallest ``c`` with every ``|S_k + D_k / c| ≤ limit`` is linear in ``1 / c``
per sample and wheel (:func:`smallest_slowdown`). When ``S_k`` alone passes the limit, the stored
momentum saturates a wheel on this path at any speed and the plan is refused
(:data:`~att_msgs_py.errors.ErrorCode.WHEEL_SATURATION`).
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import ControlKind, Plan
from att_planner.problem import ManeuverProblem
from att_planner.verification import body_plan_wheel_speeds, predict

MAX_SLOWDOWN = 20.0         # a plan is slowed at most this many times
LIMIT_MARGIN = 1e-3         # the slowed plan aims this fraction inside the limit (the dense grid moves)


def smallest_slowdown(static: np.ndarray, slew: np.ndarray, limit: float) -> float:
    """The smallest ``c ≥ 1`` with ``|static + slew / c| ≤ limit`` everywhere (inf: none)."""
    if np.any(np.abs(static) > limit):
        return math.inf
    # static + slew x within [-limit, limit] for x = 1/c in (0, 1]: x <= (limit - static)/slew where slew > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = np.where(slew > 0, (limit - static) / slew, np.where(slew < 0, (-limit - static) / slew, np.inf))
    x = min(1.0, float(bound.min())) if bound.size else 1.0
    return 1.0 / x if x > 0 else math.inf


def time_scaled(plan: Plan, c: float) -> Plan:
    """``plan`` flown ``c`` times slower along the same path (body torques / c²)."""
    return Plan(t=plan.t * c, torque=plan.torque / c ** 2, q=plan.q.copy(), omega=plan.omega / c,
                control_kind=plan.control_kind, interpolation=plan.interpolation, method=plan.method,
                status=plan.status, message=plan.message, nit=plan.nit, nfev=plan.nfev, wall_time=plan.wall_time,
                stats={**plan.stats, "slowdown": c * plan.stats.get("slowdown", 1.0)})


def slow_for_wheels(problem: ManeuverProblem, plan: Plan) -> tuple[Plan | None, str]:
    """``plan`` slowed just enough to keep every wheel within its speed limit, or (None, why not)."""
    sc = problem.spacecraft
    if plan.control_kind != ControlKind.BODY_TORQUE:
        return None, "a wheel-torque plan is not slowed (its wheels' gyroscopic torque does not scale)"
    if problem.goal_motion is not None:
        return None, "a plan that ends on a moving goal is not slowed (it would miss the goal)"
    traj = predict(problem, plan)
    stored, slew = body_plan_wheel_speeds(problem, traj.q_BN, traj.omega_BN_B)
    c = smallest_slowdown(stored, slew, sc.wheel_speed_max * (1.0 - LIMIT_MARGIN))
    if not math.isfinite(c):
        k, i = np.unravel_index(int(np.argmax(np.abs(stored))), stored.shape)
        return None, (f"the momentum stored in the wheels saturates wheel {i + 1} on this path at any speed "
                      f"({abs(stored[k, i]):.1f} rad/s > {sc.wheel_speed_max:g} rad/s at t = {traj.t[k]:.1f} s)")
    if c > MAX_SLOWDOWN:
        return None, f"it would have to fly {c:.1f} times slower (at most {MAX_SLOWDOWN:g})"
    return time_scaled(plan, c), ""
