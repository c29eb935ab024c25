"""The constrained rotation axis: λ-rotations (:mod:`.axis_rotations`) that take the sensor round
the keep-out cones.

When the eigenaxis sweeps the sensor through a keep-out cone, the sensor goes around it on the
shortest path around a spherical cap: a great circle tangent to a circle just outside the cone, a
λ-rotation **about the cone axis** so the sensor rides that circle, the tangent great circle to the
target direction, then a roll about the sensor to the final attitude (or, when shorter and clear,
an eigenaxis rotation instead of the last two legs). Every leg is a rest-to-rest λ-rotation; both
ways around each cone are tried and the fastest sequence that clears every cone is kept.
"""
from __future__ import annotations

import time

import numpy as np

from att_msgs_py.types import Plan, Status
from att_planner.cones import min_margin
from att_planner.methods.axis_rotations import (
    AxisLeg,
    eigenaxis_leg,
    goal_attitude,
    leg_profile,
    legs_plan,
    no_torque_limit,
)
from att_planner.problem import ManeuverProblem
from att_sim import rotations as rot

METHOD = "constrained_axis"


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
    u, v = rot.orthonormal_basis(w)              # azimuth ψ measured from u towards v
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
    return float(t[-1]), min_margin(q_dense, problem.sensor_axis, problem.cones)


def plan_constrained_axis(problem: ManeuverProblem, *, ride_margin_deg: float = 0.5) -> Plan:
    """Eigenaxis slew if it clears the cones, else the fastest cone-riding λ-rotation sequence.

    ``ride_margin_deg``: how far outside the cone boundary the sensor rides (deg, ≥ 0).
    """
    start = time.monotonic()
    why = no_torque_limit(problem)
    if why:
        return Plan(method=METHOD, status=Status.FAILED, message=why)
    eig = [eigenaxis_leg(problem.q_initial, goal_attitude(problem))]
    tf, margin = _legs_time(problem, eig)
    if margin >= 0:
        return legs_plan(problem, METHOD, eig, start, "eigenaxis path clears every cone",
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
            return Plan(method=METHOD, status=Status.FAILED, message=msg, stats=stats)
        plan = legs_plan(problem, METHOD, best["legs"], start, msg, stats)
        plan.status = Status.FAILED
        return plan
    best = min(clear, key=lambda c: c["tf"])
    return legs_plan(problem, METHOD, best["legs"], start, f"route: {best['route']}", stats)
