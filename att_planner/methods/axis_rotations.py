"""λ-rotations: rest-to-rest bang-bang turns about axes fixed in inertial space (hence in the body).

Shared by the eigenaxis slew (:mod:`.eigenaxis`), the constrained rotation axis
(:mod:`.constrained_axis`) and the warm-start routes of the time-optimal planner.

Rest to rest with the largest acceleration α the per-axis limits |T_j| ≤ T̄ allow along the
body axis ``e``, the bang-bang profile (accelerate for half the time, decelerate for the other half)
takes ``t = 2 sqrt(φ / α) = 2 sqrt(φ I_a / T_a)`` with ``I_a = eᵀJe`` and ``T_a = α I_a``.
The torque is ``T = J e φ̈ + φ̇² (e × J e)``; the gyroscopic part vanishes on a principal axis and
is otherwise covered with the peak rate ``φ̇² ≤ α φ``:
``α = T̄ / max_j (|(J e)_j| + φ |(e × J e)_j|)``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import Plan, Status
from att_planner.problem import ManeuverProblem
from att_planner.verification import rejection, verify
from att_sim.models import rotations as rot


@dataclass
class AxisLeg:
    """A rest-to-rest λ-rotation by ``angle`` ≥ 0 about the inertial unit ``axis``."""

    axis: np.ndarray
    angle: float
    label: str = ""


def time_unit(problem: ManeuverProblem) -> float:
    """``sqrt(J0 / T̄)`` with J0 the largest principal inertia: the natural time scale (1 TU)."""
    J0 = float(np.linalg.eigvalsh(problem.spacecraft.inertia).max())
    return float(np.sqrt(J0 / problem.spacecraft.body_torque_max))


def axis_acceleration(inertia: np.ndarray, e_body: np.ndarray, angle: float, torque_max: float) -> float:
    """Largest angular acceleration along body axis ``e`` within |T_j| ≤ T̄ (module docstring)."""
    Je = inertia @ e_body
    gyro = np.cross(e_body, Je)
    return float(torque_max / np.max(np.abs(Je) + angle * np.abs(gyro)))


def _axis_rotation(axis: np.ndarray, angle) -> np.ndarray:
    return rot.from_axis_angle(np.broadcast_to(axis, np.shape(angle) + (3,)), angle)


def leg_profile(problem: ManeuverProblem, legs: list[AxisLeg], pieces_per_half: int | None = None):
    """ZOH body-torque profile of a sequence of λ-rotations starting at ``problem.q_initial``.

    Returns ``(t, torque, q, omega, durations, q_dense)``: knots, torque per knot (held to the next),
    reference attitude and body rate at the knots, the leg durations and a dense attitude path
    (for cone checks). With a gyroscopic term each half is split into ``pieces_per_half`` pieces
    holding the mean torque of the piece (default 32; 1 when the axis is principal).
    """
    sc = problem.spacecraft
    J = sc.inertia
    q = rot.normalize(np.asarray(problem.q_initial, float))
    ts, us, qs, ws, durations, dense = [0.0], [], [q], [np.zeros(3)], [], [q[None]]
    t0 = 0.0
    for leg, q, e, alpha, T in _kinematics(problem, legs):
        gyro = np.cross(e, J @ e)
        n = pieces_per_half or (1 if np.linalg.norm(gyro) < 1e-12 * np.linalg.norm(J) else 32)
        half = T / 2
        edges = np.linspace(0.0, half, n + 1)
        # mean of (α s)² over a piece [a, b] of the acceleration half (mirror image when braking)
        mean_rate_sq = alpha**2 * (edges[1:] ** 3 - edges[:-1] ** 3) / (3 * np.diff(edges))
        acc = [J @ e * alpha + m * gyro for m in mean_rate_sq]
        dec = [-J @ e * alpha + m * gyro for m in mean_rate_sq[::-1]]
        local = np.concatenate([edges[:-1], half + edges[:-1]])
        phi = np.where(local <= half, 0.5 * alpha * local**2, leg.angle - 0.5 * alpha * (T - local) ** 2)
        rate = np.where(local <= half, alpha * local, alpha * (T - local))
        q_knots = rot.multiply(_axis_rotation(leg.axis, phi), q)
        us += acc + dec
        ts += list(t0 + local[1:]) + [t0 + T]
        qs += list(q_knots[1:])
        ws += list(rate[1:, None] * e)
        dense.append(rot.multiply(_axis_rotation(leg.axis, leg.angle * np.linspace(0.0, 1.0, 200)), q))
        qs.append(rot.multiply(_axis_rotation(leg.axis, leg.angle), q))
        ws.append(np.zeros(3))
        durations.append(T)
        t0 += T
    us.append(np.zeros(3))
    torque = np.clip(np.array(us), -sc.body_torque_max, sc.body_torque_max)
    return (np.array(ts), torque, np.array(qs), np.array(ws), durations, np.concatenate(dense))


def leg_path(problem: ManeuverProblem, legs: list[AxisLeg]) -> tuple[np.ndarray, np.ndarray]:
    """``(t_dense, q_dense)``: the dense attitude path of :func:`leg_profile` (200 samples per leg,
    even in angle) with the physical time of each sample, for zones that move: on a leg the angle
    is ``½ α τ²`` up to half-way, then ``φ − ½ α (T − τ)²``."""
    ts, qs = [np.zeros(1)], [rot.normalize(np.asarray(problem.q_initial, float))[None]]
    t0 = 0.0
    for leg, q, _, alpha, T in _kinematics(problem, legs):
        swept = leg.angle * np.linspace(0.0, 1.0, 200)
        qs.append(rot.multiply(_axis_rotation(leg.axis, swept), q))
        ts.append(t0 + np.where(swept <= leg.angle / 2, np.sqrt(2 * swept / alpha),
                                T - np.sqrt(2 * np.maximum(leg.angle - swept, 0.0) / alpha)))
        t0 += T
    return np.concatenate(ts), np.concatenate(qs)


def leg_durations(problem: ManeuverProblem, legs: list[AxisLeg]) -> list[float]:
    """Duration (s) of each leg of non-zero angle: ``2 sqrt(φ / α)`` (module docstring)."""
    return [T for *_, T in _kinematics(problem, legs)]


def _kinematics(problem: ManeuverProblem, legs: list[AxisLeg]):
    """``(leg, q at its start, body axis e, α, duration)`` of each leg of non-zero angle, in turn."""
    sc = problem.spacecraft
    q = rot.normalize(np.asarray(problem.q_initial, float))
    for leg in legs:
        if leg.angle <= 1e-12:
            continue
        e = rot.dcm_BN(q) @ leg.axis
        alpha = axis_acceleration(sc.inertia, e, leg.angle, sc.body_torque_max)
        yield leg, q, e, alpha, 2.0 * np.sqrt(leg.angle / alpha)
        q = rot.multiply(_axis_rotation(leg.axis, leg.angle), q)


def _semi_free_goal(problem: ManeuverProblem) -> np.ndarray:
    """Attitude reached by the shortest rotation taking the sensor onto ``sensor_target``."""
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    b0 = rot.dcm_NB(q0) @ problem.sensor_axis
    b0 = b0 / np.linalg.norm(b0)
    s = np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
    axis = np.cross(b0, s)
    if np.linalg.norm(axis) < 1e-12:
        axis = rot.orthonormal_basis(b0)[0]          # on the antipode: any axis normal to b0
    angle = np.arccos(np.clip(b0 @ s, -1.0, 1.0))
    return rot.multiply(rot.from_axis_angle(axis, angle), q0)


def goal_attitude(problem: ManeuverProblem) -> np.ndarray:
    """The fully specified goal, or for a semi-free target the eigenaxis-nearest attitude."""
    if problem.sensor_target is not None:
        return _semi_free_goal(problem)
    return rot.normalize(np.asarray(problem.q_final, float))


def eigenaxis_leg(q_from: np.ndarray, q_to: np.ndarray, label: str = "eigenaxis") -> AxisLeg:
    """The shortest λ-rotation from ``q_from`` to ``q_to`` (inertial axis, angle in [0, π])."""
    q_rel = rot.multiply(q_to, rot.conjugate(q_from))          # inertial frame rotation
    axis, angle = rot.to_axis_angle(q_rel)
    return AxisLeg(axis, angle, label)


def no_torque_limit(problem: ManeuverProblem) -> str:
    """Why no bang-bang plan exists (no finite, positive body torque limit), or ''."""
    T = problem.spacecraft.body_torque_max
    if not np.isfinite(T) or T <= 0:
        return "the spacecraft has no finite body torque limit (body_torque_max), so no bang-bang plan exists"
    return ""


def legs_plan(problem: ManeuverProblem, method: str, legs: list[AxisLeg], start: float, message: str,
              extra_stats: dict | None = None) -> Plan:
    """The ZOH plan of a leg sequence, verified (:func:`att_planner.verification.verify`): status
    FEASIBLE, or FAILED with the reason when it does not pass."""
    t, torque, q, omega, durations, _ = leg_profile(problem, legs)
    plan = Plan(t=t, torque=torque, q=q, omega=omega, method=method)
    plan.verification = verify(problem, plan)
    why = rejection(plan.verification)
    plan.status = Status.FEASIBLE if why is None else Status.FAILED
    if why is not None:
        message = (message + "; " if message else "") + (
            f"verification failed: {why} (min cone margin {np.rad2deg(plan.verification.min_cone_margin):.2f} deg, "
            f"final error {np.rad2deg(plan.verification.final_attitude_error):.3f} deg)")
    plan.message = message
    flown = [leg for leg in legs if leg.angle > 1e-12]
    plan.stats = {"tf": float(t[-1]),
                  "legs": [{"label": leg.label, "axis": leg.axis.tolist(), "angle": float(leg.angle),
                            "duration": float(d)} for leg, d in zip(flown, durations)]}
    plan.stats.update(extra_stats or {})
    plan.wall_time = time.monotonic() - start
    return plan
