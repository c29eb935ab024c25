"""The constructive first plan onto a moving goal: a spin about the goal's final rate axis entered
from rest, the offset from it removed about a fixed axis.

A slew that ends on a pointing law (:class:`att_planner.problem.MovingGoal`: ``t ↦ (q_g, ω_g)``)
must start at rest on ``q_0`` and end at ``t = T`` on ``q_T = q_g(T)`` at the body rate
``ω_T = ω_g(T)``. The plan flies the frame ``F(t) = q_T ⊗ exp(W(t) ω_T)`` (``W ω_T`` a rotation
vector: the goal's final attitude turned back about its final rate axis), ``W' = s(t/T)``,
``W(T) = 0``, so F starts at rest and ends on the goal at its rate; and turns the body relative to
F by ``q_BF(t) = exp(½ (1 − s(t/T)) φ e)`` about the fixed axis ``e`` of the start's offset
``q_F(0)* ⊗ q_0 = exp(½ φ e)``. ``s`` is the quintic ``10σ³ − 15σ⁴ + 6σ⁵`` (its rate and
acceleration zero at both ends). With ``ω_F = W' ω_T`` (F axes)::

    q_BN = q_F ⊗ q_BF,    ω_B = [BF] ω_F − ṡ φ e,
    ω̇_B = [BF] W'' ω_T + ṡ φ e × [BF] ω_F − s̈ φ e,
    τ = J ω̇_B + ω_B × J ω_B,

so ``q(0) = q_0``, ``ω(0) = 0``, ``τ(0) = 0`` and ``q(T) = q_g(T)``, ``ω(T) = ω_g(T)`` exactly,
whatever T (the goal is asked once per T: only its end matters). T is found by doubling from the
rest-to-rest bound until the torque stays within the per-axis bound T̄ (and the rate,
wheel-momentum and wheel-speed bounds) at every knot, then by bisection to
:data:`DURATION_TOLERANCE` (the upper end always fits), within the goal's window. The zones are
not steered round: the verification judges them. The knots hold the torque (linear
interpolation) and the exact attitude and rate.
"""
from __future__ import annotations

import time

import numpy as np

from att_msgs_py.types import Interpolation, Plan, Status
from att_planner.problem import ManeuverProblem
from att_planner.verification import body_plan_wheel_speeds
from att_sim.models import rotations as rot

METHOD = "onto_moving_goal"
KNOTS = 1201                   # knots of the plan (linear torque between them)
DURATION_TOLERANCE = 1e-3      # relative: the bisection on T stops within this
BOUND_MARGIN = 1e-3            # relative room kept below the torque, rate and momentum bounds


def profile(problem: ManeuverProblem, duration: float, knots: int = KNOTS):
    """The construction (module docstring) sampled.

    Parameters
    ----------
    problem : ManeuverProblem
        Its start, spacecraft and moving goal.
    duration : float
        T (s).
    knots : int, optional
        Samples over [0, T].

    Returns
    -------
    t, q, omega, torque : ndarray
        Times (s), attitudes [x, y, z, w], body rates (rad/s) and body torques (N m), one row per knot.
    """
    T = float(duration)
    q_T, omega_T = problem.goal_motion(T)
    sigma = np.linspace(0.0, 1.0, knots)
    s = 10 * sigma**3 - 15 * sigma**4 + 6 * sigma**5
    s1 = (30 * sigma**2 - 60 * sigma**3 + 30 * sigma**4) / T
    s2 = (60 * sigma - 180 * sigma**2 + 120 * sigma**3) / T**2
    W = T * (sigma**4 * (2.5 - 3 * sigma + sigma**2) - 0.5)     # ∫ s dt, zero at T
    spin = np.asarray(omega_T, float)
    q_F = rot.multiply(np.asarray(q_T, float), rot.exp_map(W[:, None] * spin))
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    e, phi = rot.to_axis_angle(rot.multiply(rot.conjugate(q_F[0]), q0))
    q_BF = rot.from_axis_angle(np.tile(e, (knots, 1)), (1.0 - s) * phi)
    dcm_BF = np.transpose(rot.dcm_NB(q_BF), (0, 2, 1))                  # F components to B
    frame_B = np.einsum("kij,j->ki", dcm_BF, spin) * s[:, None]
    omega = frame_B - (s1 * phi)[:, None] * e
    omega_dot = (np.einsum("kij,j->ki", dcm_BF, spin) * s1[:, None]
                 + (s1 * phi)[:, None] * rot.cross(np.tile(e, (knots, 1)), frame_B) - (s2 * phi)[:, None] * e)
    J = problem.spacecraft.inertia
    torque = omega_dot @ J.T + rot.cross(omega, omega @ J.T)
    return sigma * T, rot.multiply(q_F, q_BF), omega, torque


def bound_ratio(problem: ManeuverProblem, omega: np.ndarray, torque: np.ndarray, q: np.ndarray) -> float:
    """The largest ratio of the torque, body rate, wheel momentum and wheel speed (relative to the body,
    :func:`att_planner.verification.body_plan_wheel_speeds`) to their bounds (with the margin)."""
    sc = problem.spacecraft
    ratios = [np.abs(torque).max() / (sc.body_torque_max * (1 - BOUND_MARGIN))]
    if sc.n_wheels and np.isfinite(sc.wheel_speed_max):
        stored, slew = body_plan_wheel_speeds(problem, q, omega)
        ratios.append(np.abs(stored + slew).max() / (sc.wheel_speed_max * (1 - BOUND_MARGIN)))
    if np.isfinite(problem.rate_max):
        ratios.append(np.abs(omega).max() / (problem.rate_max * (1 - BOUND_MARGIN)))
    if np.isfinite(problem.wheel_momentum_max) and sc.n_wheels:
        h = omega @ (sc.wheel_axes_pinv @ sc.inertia).T
        ratios.append(np.abs(h).max() / (problem.wheel_momentum_max * (1 - BOUND_MARGIN)))
    return float(max(ratios))


def plan_onto_moving_goal(problem: ManeuverProblem, knots: int = KNOTS) -> Plan:
    """The first plan onto the problem's moving goal (module docstring).

    Parameters
    ----------
    problem : ManeuverProblem
        With ``goal_motion`` set; its torque, rate, wheel-momentum and wheel-speed bounds are kept.
    knots : int, optional
        Knots of the plan (linear torque between them).

    Returns
    -------
    Plan
        FEASIBLE: the shortest duration within the bounds (to :data:`DURATION_TOLERANCE`); FAILED
        without a moving goal, or when no duration within the goal's window keeps the bounds.
    """
    start = time.perf_counter()
    goal = problem.goal_motion
    if goal is None:
        return Plan(method=METHOD, status=Status.FAILED, message="the problem has no moving goal",
                    wall_time=time.perf_counter() - start)
    coarse = max(65, knots // 8)

    def fits(T: float) -> bool:
        _, q, omega, torque = profile(problem, T, coarse)
        return bound_ratio(problem, omega, torque, q) <= 1.0

    low, high = 0.0, max(problem.slew_time_bound(), 1.0)
    while not fits(high):
        low, high = high, 2.0 * high
        if high > goal.window:
            high = goal.window
            if not fits(high):
                return Plan(method=METHOD, status=Status.FAILED, wall_time=time.perf_counter() - start,
                            message=f"no slew onto the moving goal within its window of {goal.window:.0f} s keeps "
                                    "the torque, rate and momentum bounds")
            break
    while high - low > DURATION_TOLERANCE * high:
        middle = 0.5 * (low + high)
        low, high = (low, middle) if fits(middle) else (middle, high)
    t, q, omega, torque = profile(problem, high, knots)
    if bound_ratio(problem, omega, torque, q) > 1.0:      # between the coarse knots: slightly longer
        for _ in range(20):
            high *= 1.0 + DURATION_TOLERANCE
            t, q, omega, torque = profile(problem, high, knots)
            if bound_ratio(problem, omega, torque, q) <= 1.0:
                break
    return Plan(t=t, torque=np.clip(torque, -problem.spacecraft.body_torque_max, problem.spacecraft.body_torque_max),
                q=q, omega=omega, interpolation=Interpolation.LINEAR, method=METHOD, status=Status.FEASIBLE,
                message=f"onto the moving goal, spun up about its final rate axis, t_f = {high:.4g} s",
                wall_time=time.perf_counter() - start, stats={"tf": float(high)})
