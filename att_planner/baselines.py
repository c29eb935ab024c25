"""Fixed-axis bang-bang baselines: the eigenaxis slew and the constrained rotation axis.

A *λ-rotation* turns the body by an angle φ about an axis fixed in inertial space (hence also in the
body). Rest to rest with the largest acceleration α the per-axis limits |T_j| ≤ T̄ allow along the
body axis ``e``, the bang-bang profile (accelerate for half the time, decelerate for the other half)
takes ``t = 2 sqrt(φ / α) = 2 sqrt(φ I_a / T_a)`` with ``I_a = eᵀJe`` and ``T_a = α I_a``.
The torque is ``T = J e φ̈ + φ̇² (e × J e)``; the gyroscopic part vanishes on a principal axis and
is otherwise covered with the peak rate ``φ̇² ≤ α φ``:
``α = T̄ / max_j (|(J e)_j| + φ |(e × J e)_j|)``.

* :func:`plan_eigenaxis` — one λ-rotation about the eigenaxis (Euler axis) of the shortest rotation.
* :func:`plan_constrained_axis` — when the eigenaxis sweeps the sensor through a keep-out cone, the
  sensor goes around it on the shortest path around a spherical cap: a great circle tangent to a
  circle just outside the cone, a λ-rotation **about the cone axis** so the sensor rides that circle,
  the tangent great circle to the target direction, then a roll about the sensor to the final
  attitude (or, when shorter and clear, an eigenaxis rotation instead of the last two legs). Every
  leg is a rest-to-rest λ-rotation; both ways around each cone are tried and the fastest sequence
  that clears every cone is kept.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from att_planner.cones import margins
from att_planner.problem import (STATUS_FAILED, STATUS_FEASIBLE, ManeuverPlan, ManeuverProblem)
from att_planner.verify import verify_profile
from att_sim import rotations as rot

DEFAULT_ATTITUDE_TOL = np.deg2rad(0.5)
DEFAULT_MARGIN_TOL = 0.0


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
    for leg in legs:
        if leg.angle <= 1e-12:
            continue
        e = rot.dcm(q).T @ leg.axis
        alpha = axis_acceleration(J, e, leg.angle, sc.body_torque_max)
        T = 2.0 * np.sqrt(leg.angle / alpha)
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
        q = rot.multiply(_axis_rotation(leg.axis, leg.angle), q)
        qs.append(q)
        ws.append(np.zeros(3))
        durations.append(T)
        t0 += T
    us.append(np.zeros(3))
    torque = np.clip(np.array(us), -sc.body_torque_max, sc.body_torque_max)
    return (np.array(ts), torque, np.array(qs), np.array(ws), durations, np.concatenate(dense))


def verify_plan(problem: ManeuverProblem, t, torque, interpolation: str, q_goal=None, *,
                attitude_tol: float = DEFAULT_ATTITUDE_TOL, rate_tol: float | None = None,
                margin_tol: float = DEFAULT_MARGIN_TOL, dense_steps: int = 200):
    """Integrate a body-torque plan through the truth dynamics; ``(passes, verification dict, traj)``.

    ``q_goal`` defaults to ``problem.q_final``; with a semi-free target the caller passes the
    planned final attitude and the sensor pointing error is checked against ``attitude_tol``.
    ``rate_tol`` defaults to 1e-2 rad/TU. The RK4 step is ``t_f / dense_steps`` (or shorter, one
    step at least per knot interval); cone margins are measured at every step.
    """
    sc = problem.spacecraft
    rate_tol = 1e-2 / time_unit(problem) if rate_tol is None else rate_tol
    q_goal = problem.q_final if q_goal is None else q_goal
    ver, traj = verify_profile(sc, problem.q_initial, q_goal, t, torque, kind="body_torque",
                               interpolation=interpolation, sensor_axis=problem.sensor_axis,
                               cones=problem.cones, dense_step=float(t[-1]) / dense_steps)
    info = ver.as_dict()
    ok = ver.passes(attitude_tol, rate_tol, margin_tol)
    if problem.sensor_target is not None:
        b = rot.dcm(traj.q[-1]) @ np.asarray(problem.sensor_axis, float)
        s = np.asarray(problem.sensor_target, float)
        info["final_sensor_error"] = float(np.arccos(np.clip(b @ s / np.linalg.norm(b) / np.linalg.norm(s), -1, 1)))
        ok = ok and info["final_sensor_error"] <= attitude_tol
    return ok, info, traj


def _semi_free_goal(problem: ManeuverProblem) -> np.ndarray:
    """Attitude reached by the shortest rotation taking the sensor onto ``sensor_target``."""
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    b0 = rot.dcm(q0) @ problem.sensor_axis
    b0 = b0 / np.linalg.norm(b0)
    s = np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
    axis = np.cross(b0, s)
    if np.linalg.norm(axis) < 1e-12:
        axis = np.cross(b0, [1.0, 0.0, 0.0]) if abs(b0[0]) < 0.9 else np.cross(b0, [0.0, 1.0, 0.0])
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


def _finish(problem: ManeuverProblem, method: str, legs: list[AxisLeg], start: float, message: str,
            extra_stats: dict | None = None) -> ManeuverPlan:
    t, torque, q, omega, durations, q_dense = leg_profile(problem, legs)
    goal = goal_attitude(problem) if problem.sensor_target is None else q[-1]
    ok, info, _ = verify_plan(problem, t, torque, "zoh", goal)
    status = STATUS_FEASIBLE if ok else STATUS_FAILED
    if not ok:
        message = (message + "; " if message else "") + (
            f"verification failed (min cone margin {np.rad2deg(info['min_cone_margin']):.2f} deg, "
            f"final error {np.rad2deg(info['final_attitude_error']):.3f} deg)")
    stats = {"tf": float(t[-1]), "legs": [{"label": l.label, "axis": l.axis.tolist(), "angle": float(l.angle),
                                           "duration": float(d)} for l, d in zip([l for l in legs if l.angle > 1e-12], durations)],
             "verification": info}
    stats.update(extra_stats or {})
    return ManeuverPlan(method, t, torque, q, omega, "zoh", status, message, time.monotonic() - start, stats)


def _check_problem(problem: ManeuverProblem) -> str:
    T = problem.spacecraft.body_torque_max
    if not np.isfinite(T) or T <= 0:
        return "the spacecraft has no finite body torque limit (body_torque_max), so no bang-bang plan exists"
    return ""


def plan_eigenaxis(problem: ManeuverProblem, **options) -> ManeuverPlan:
    """Rest-to-rest bang-bang λ-rotation about the eigenaxis (cones are only checked, not avoided)."""
    if options:
        raise ValueError(f"plan_eigenaxis takes no options (got {sorted(options)})")
    start = time.monotonic()
    why = _check_problem(problem)
    if why:
        return ManeuverPlan("eigenaxis", np.zeros(1), np.zeros((1, 3)), np.zeros((1, 4)), np.zeros((1, 3)),
                            status=STATUS_FAILED, message=why)
    leg = eigenaxis_leg(problem.q_initial, goal_attitude(problem))
    return _finish(problem, "eigenaxis", [leg], start, "")


# -- constrained rotation axis -------------------------------------------------------------------

def _cone_frame(w: np.ndarray):
    """Orthonormal (u, v) completing the cone axis w; azimuth ψ measured from u towards v."""
    a = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(w, a)
    u /= np.linalg.norm(u)
    return u, np.cross(w, u)


def _polar(b, w, u, v):
    return np.arccos(np.clip(b @ w, -1, 1)), np.arctan2(b @ v, b @ u)


def _point(beta, psi, w, u, v):
    return np.cos(beta) * w + np.sin(beta) * (np.cos(psi) * u + np.sin(psi) * v)


def _great_circle_leg(b_from, b_to, label):
    axis = np.cross(b_from, b_to)
    n = np.linalg.norm(axis)
    if n < 1e-12:
        return AxisLeg(np.array([0.0, 0.0, 1.0]), 0.0, label)
    return AxisLeg(axis / n, float(np.arctan2(n, b_from @ b_to)), label)


def cone_riding_legs(problem: ManeuverProblem, cone_index: int, side: int, ride_margin: float,
                     finish: str) -> list[AxisLeg] | None:
    """Legs taking the sensor around cone ``cone_index`` on ``side`` (+1: increasing azimuth about
    its axis, −1: decreasing) along a circle ``ride_margin`` outside it.

    ``finish='roll'``: tangent arc to the target direction, then a roll about the sensor;
    ``finish='eigenaxis'``: an eigenaxis rotation from the end of the ride to the goal attitude.
    None when a boresight end lies inside the riding circle.
    """
    cone = problem.cones[cone_index]
    w = cone.direction
    u, v = _cone_frame(w)
    r = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    q_goal = goal_attitude(problem)
    b0, bf = rot.dcm(q0) @ r, rot.dcm(q_goal) @ r
    rho = cone.half_angle + ride_margin
    beta0, psi0 = _polar(b0, w, u, v)
    betaf, psif = _polar(bf, w, u, v)
    if min(beta0, betaf) <= rho or rho >= np.pi / 2:
        return None
    # Right spherical triangle (w, tangent point, b): cos A = tan ρ / tan β at the cone axis.
    A0 = np.arccos(np.clip(np.tan(rho) / np.tan(beta0), -1, 1))
    Af = np.arccos(np.clip(np.tan(rho) / np.tan(betaf), -1, 1))
    psi1 = psi0 + side * A0
    ride = np.mod(side * ((psif - side * Af) - psi1), 2 * np.pi)
    p1 = _point(rho, psi1, w, u, v)
    legs = [_great_circle_leg(b0, p1, f"tangent to {cone.name or cone_index}"),
            AxisLeg(side * w, float(ride), f"ride {cone.name or cone_index} boundary")]
    q = q0
    for leg in legs:
        q = rot.multiply(rot.from_axis_angle(leg.axis, leg.angle), q)
    if finish == "eigenaxis":
        return legs + [eigenaxis_leg(q, q_goal, "eigenaxis to goal")]
    b2 = rot.dcm(q) @ r
    legs.append(_great_circle_leg(b2, bf, "tangent to target"))
    q = rot.multiply(rot.from_axis_angle(legs[-1].axis, legs[-1].angle), q)
    if problem.sensor_target is None:
        roll_q = rot.multiply(q_goal, rot.conjugate(q))            # rotation about bf (inertial)
        if roll_q[3] < 0:
            roll_q = -roll_q
        angle = 2 * np.arctan2(roll_q[:3] @ bf, roll_q[3])
        legs.append(AxisLeg(np.sign(angle) * bf if angle else bf, abs(float(angle)), "roll about sensor"))
    return legs


def _legs_time(problem: ManeuverProblem, legs: list[AxisLeg]) -> tuple[float, float]:
    """(duration, min cone margin along the path) of a leg sequence, without simulation."""
    t, _, _, _, _, q_dense = leg_profile(problem, legs, pieces_per_half=1)
    m = margins(q_dense, problem.sensor_axis, problem.cones)
    return float(t[-1]), float(m.min()) if m.size else np.inf


def plan_constrained_axis(problem: ManeuverProblem, *, ride_margin_deg: float = 0.5) -> ManeuverPlan:
    """Eigenaxis slew if it clears the cones, else the fastest cone-riding λ-rotation sequence.

    ``ride_margin_deg``: how far outside the cone boundary the sensor rides (deg, ≥ 0).
    """
    if not ride_margin_deg >= 0:
        raise ValueError("ride_margin_deg must be a non-negative angle in degrees")
    start = time.monotonic()
    why = _check_problem(problem)
    if why:
        return ManeuverPlan("constrained_axis", np.zeros(1), np.zeros((1, 3)), np.zeros((1, 4)),
                            np.zeros((1, 3)), status=STATUS_FAILED, message=why)
    eig = [eigenaxis_leg(problem.q_initial, goal_attitude(problem))]
    tf, margin = _legs_time(problem, eig)
    if margin >= 0:
        return _finish(problem, "constrained_axis", eig, start, "eigenaxis path clears every cone",
                       {"candidates": [{"route": "eigenaxis", "tf": tf, "min_margin": margin}]})
    candidates = []
    for c in range(len(problem.cones)):
        for side in (+1, -1):
            for finish in ("roll", "eigenaxis"):
                legs = cone_riding_legs(problem, c, side, np.deg2rad(ride_margin_deg), finish)
                if legs is None:
                    continue
                tf_c, m_c = _legs_time(problem, legs)
                name = problem.cones[c].name or str(c)
                candidates.append({"route": f"ride {name} {'+' if side > 0 else '-'} then {finish}",
                                   "tf": tf_c, "min_margin": m_c, "legs": legs})
    clear = [c for c in candidates if c["min_margin"] >= 0]
    stats = {"candidates": [{k: c[k] for k in ("route", "tf", "min_margin")} for c in candidates]}
    if not clear:
        msg = "no cone-riding λ-rotation sequence clears every cone"
        best = max(candidates, key=lambda c: c["min_margin"]) if candidates else None
        if best is None:
            return ManeuverPlan("constrained_axis", np.zeros(1), np.zeros((1, 3)), np.zeros((1, 4)),
                                np.zeros((1, 3)), status=STATUS_FAILED, message=msg, stats=stats)
        plan = _finish(problem, "constrained_axis", best["legs"], start, msg, stats)
        plan.status = STATUS_FAILED
        return plan
    best = min(clear, key=lambda c: c["tf"])
    return _finish(problem, "constrained_axis", best["legs"], start, f"route: {best['route']}", stats)
