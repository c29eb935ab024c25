"""The constrained rotation axis: λ-rotations (:mod:`.axis_rotations`) that take the sensor round
the keep-out zones, moving or not.

When the eigenaxis sweeps a sensor through a keep-out zone, that sensor goes around it on the
shortest path around a spherical cap: a great circle tangent to a circle just outside the zone, a
λ-rotation **about the zone axis** so the sensor rides that circle, the tangent great circle to the
target direction, then a roll about the sensor to the final attitude (or, when shorter and clear,
an eigenaxis rotation instead of the last two legs). Every leg is a rest-to-rest λ-rotation; both
ways around each keep-out zone are tried and the fastest sequence that clears every zone is kept.

Zones that move: every candidate is judged with the margins of each dense sample at its physical
time (:func:`.axis_rotations.leg_path`, :meth:`att_planner.zones.FittedZones.margins`), never a
snapshot. The ride is built about the zone as it is at ``t*``, the middle of the ride, on a circle
widened by how far the zone's axis and half-angle move during the ride; ``t*`` and that widening
are found by a few fixed-point iterations (:data:`RIDE_ITERATIONS`) of the construction. When a
zone moves, two-leg detours are tried too (:func:`_detours`: escape straight away from a zone, or
through a tilted half-way attitude): a zone rising over the start is fled rather than ridden round.
Keep-in zones are checked, not steered into. A sequence longer than the zones' window
(:meth:`ManeuverProblem.zone_sky`) is refused, never judged on extrapolated zones.
"""
from __future__ import annotations

import time

import numpy as np

from att_msgs_py.types import Plan, Status
from att_planner.cones import BOUNDARY_TOLERANCE, boundary_arc_issue
from att_planner.methods.axis_rotations import (
    AxisLeg,
    eigenaxis_leg,
    goal_attitude,
    leg_durations,
    leg_path,
    legs_plan,
    no_torque_limit,
)
from att_planner.problem import ManeuverProblem
from att_planner.verification import clearances
from att_planner.zones import FittedZones, same_axis
from att_sim.models import rotations as rot

METHOD = "constrained_axis"
RIDE_ITERATIONS = 4        # fixed-point iterations on the ride time t* and the widening
ESCAPES = (10.0, 20.0, 45.0)           # deg: first legs of the escape detours (moving zones)
TILTS = (10.0, 20.0, 30.0, 45.0)       # deg: tilts of the half-way attitude of the tilted detours


def _polar(b, w, u, v):
    return np.arccos(np.clip(b @ w, -1, 1)), np.arctan2(b @ v, b @ u)


def _point(beta, psi, w, u, v):
    return np.cos(beta) * w + np.sin(beta) * (np.cos(psi) * u + np.sin(psi) * v)


def _great_circle_leg(b_from, b_to, label):
    """The λ-rotation along the great circle from ``b_from`` to ``b_to``; none (angle 0) below
    BOUNDARY_TOLERANCE: a rest-to-rest leg of angle ε costs 2 sqrt(ε/α), 3 ms of TU for 1e-6 rad."""
    axis = np.cross(b_from, b_to)
    n = np.linalg.norm(axis)
    angle = float(np.arctan2(n, b_from @ b_to))
    if angle < BOUNDARY_TOLERANCE:
        return AxisLeg(np.array([0.0, 0.0, 1.0]), 0.0, label)
    return AxisLeg(axis / n, angle, label)


def cone_riding_legs(problem: ManeuverProblem, zone_index: int, side: int, ride_margin: float, finish: str,
                     axis: np.ndarray | None = None, half_angle: float | None = None) -> list[AxisLeg] | None:
    """Legs taking zone ``zone_index``'s sensor (of :meth:`ManeuverProblem.zone_sky`: the cones
    first) around the zone's cone of ``axis`` and ``half_angle`` (default: the zone at t = 0) on
    ``side`` (+1: increasing azimuth about its axis, −1: decreasing) along a circle ``ride_margin``
    outside it.

    ``finish='roll'``: tangent arc to the target direction, then a roll about the sensor;
    ``finish='eigenaxis'``: an eigenaxis rotation from the end of the ride to the goal attitude.
    An end between the boundary and the riding circle joins the circle radially; None when a
    boresight end lies inside the zone (by more than BOUNDARY_TOLERANCE). With ``ride_margin`` 0
    and both ends on the boundary the ride is the boundary arc itself.
    """
    if zone_index < len(problem.cones):          # a cone: no need to build the zones
        cone = problem.cones[zone_index]
        sensor, name = np.asarray(problem.sensor_axis, float), cone.name or str(zone_index)
        w0, theta0 = cone.direction, cone.half_angle
    else:
        zs = problem.zone_sky()
        sensor, name = zs.sensor_axes[zone_index], zs.names[zone_index]
        w0 = zs.true_axes(0.0)[zone_index] if axis is None else None
        theta0 = float(zs.true_half_angles(0.0)[zone_index]) if half_angle is None else None
    w = w0 if axis is None else np.asarray(axis, float) / np.linalg.norm(axis)
    theta = theta0 if half_angle is None else half_angle
    u, v = rot.orthonormal_basis(w)              # azimuth ψ measured from u towards v
    r = sensor / np.linalg.norm(sensor)
    own_sensor = same_axis(sensor, problem.sensor_axis)
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    q_goal = goal_attitude(problem)
    b0, bf = rot.dcm_NB(q0) @ r, rot.dcm_NB(q_goal) @ r
    rho = theta + ride_margin
    beta0, psi0 = _polar(b0, w, u, v)
    betaf, psif = _polar(bf, w, u, v)
    if min(beta0, betaf) < theta - BOUNDARY_TOLERANCE or rho >= np.pi / 2:
        return None
    # Right spherical triangle (w, tangent point, b): cos A = tan ρ / tan β at the cone axis; an end
    # inside the riding circle or on it within BOUNDARY_TOLERANCE joins it radially (A = 0).
    A0, Af = (0.0 if beta - rho <= BOUNDARY_TOLERANCE else np.arccos(np.clip(np.tan(rho) / np.tan(beta), -1, 1))
              for beta in (beta0, betaf))
    psi1 = psi0 + side * A0
    ride = np.mod(side * ((psif - side * Af) - psi1), 2 * np.pi)
    p1 = _point(rho, psi1, w, u, v)
    legs = [_great_circle_leg(b0, p1, f"tangent to {name}"),
            AxisLeg(side * w, float(ride), f"ride {name} boundary")]
    q = q0
    for leg in legs:
        q = rot.multiply(rot.from_axis_angle(leg.axis, leg.angle), q)
    if finish == "eigenaxis":
        return legs + [eigenaxis_leg(q, q_goal, "eigenaxis to goal")]
    b2 = rot.dcm_NB(q) @ r
    legs.append(_great_circle_leg(b2, bf, "tangent to target"))
    q = rot.multiply(rot.from_axis_angle(legs[-1].axis, legs[-1].angle), q)
    if problem.sensor_target is None or not own_sensor:
        roll_q = rot.multiply(q_goal, rot.conjugate(q))            # rotation about bf (inertial)
        if roll_q[3] < 0:
            roll_q = -roll_q
        angle = 2 * np.arctan2(roll_q[:3] @ bf, roll_q[3])
        legs.append(AxisLeg(np.sign(angle) * bf if angle else bf, abs(float(angle)), "roll about sensor"))
    return legs


def _legs_time(problem: ManeuverProblem, legs: list[AxisLeg]) -> tuple[float, float]:
    """(duration, min zone clearance along the path at the physical times
    (:func:`att_planner.verification.clearances`); −inf beyond the zones' window) of a leg
    sequence, without simulation."""
    t, q = leg_path(problem, legs)
    zs = problem.zone_sky()
    if zs.moving and t[-1] > zs.window:
        return float(t[-1]), -np.inf
    m = clearances(problem, t, q, true=False)
    return float(t[-1]), float(m.min()) if m.size else np.inf


def _moving_ride(problem: ManeuverProblem, zs: FittedZones, z: int, side: int, ride_margin: float,
                 finish: str) -> tuple[list[AxisLeg] | None, float, float]:
    """``(legs, t*, widening)``: the riding legs about zone ``z`` as it is at the middle ``t*`` of the
    ride, on a circle widened by the zone's motion during the ride (how far its axis turns from
    ``a(t*)`` plus the growth of its half-angle), found by fixed-point iteration
    (:data:`RIDE_ITERATIONS`)."""
    if zs.zones[z].body == "inertial":
        return cone_riding_legs(problem, z, side, ride_margin, finish), 0.0, 0.0
    t_star, widen, legs = 0.0, 0.0, None
    for _ in range(RIDE_ITERATIONS):
        a_star, th_star = zs.at(min(t_star, zs.window))
        legs = cone_riding_legs(problem, z, side, ride_margin + widen, finish, a_star[z], float(th_star[z]))
        if legs is None:
            return None, t_star, widen
        d = leg_durations(problem, legs)
        if len(d) < 2:
            break
        t_star = min(d[0] + d[1] / 2, zs.window)
        ts = np.linspace(d[0], min(d[0] + d[1], zs.window), 32)
        a, th = (v[:, z] for v in zs.at(ts))
        a_star, th_star = (v[z] for v in zs.at(t_star))
        drift = np.arccos(np.clip(a @ a_star / np.linalg.norm(a, axis=1) / np.linalg.norm(a_star), -1, 1))
        widen = float(np.max(drift + th - th_star))
    return legs, t_star, widen


def _detours(problem: ManeuverProblem, zs: FittedZones) -> list[tuple[str, list[AxisLeg]]]:
    """Two-leg routes for a path that a zone overtakes (moving zones): *escape* — a λ-rotation
    taking a keep-out zone's sensor straight away from the zone's axis (as at t = 0) by
    :data:`ESCAPES`, then the eigenaxis to the goal; *tilt* — two eigenaxis legs through the
    half-way attitude of the eigenaxis slew turned by :data:`TILTS` about either normal of the
    eigenaxis, either way."""
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    q_goal = goal_attitude(problem)
    routes = []
    for z in np.flatnonzero(~zs.keep_in):
        b0 = rot.dcm_NB(q0) @ (zs.sensor_axes[z] / np.linalg.norm(zs.sensor_axes[z]))
        away = np.cross(zs.true_axes(0.0)[z], b0)
        if np.linalg.norm(away) < 1e-9:
            continue
        away /= np.linalg.norm(away)
        for angle in np.deg2rad(ESCAPES):
            q1 = rot.multiply(rot.from_axis_angle(away, angle), q0)
            routes.append((f"escape {zs.names[z]} {np.rad2deg(angle):.0f} deg then eigenaxis",
                           [AxisLeg(away, float(angle), f"away from {zs.names[z]}"), eigenaxis_leg(q1, q_goal)]))
    eig = eigenaxis_leg(q0, q_goal)
    q_half = rot.multiply(rot.from_axis_angle(eig.axis, eig.angle / 2), q0)
    for k, normal in enumerate(rot.orthonormal_basis(eig.axis)):
        for tilt in np.deg2rad(TILTS):
            for sign in (+1, -1):
                q_mid = rot.multiply(rot.from_axis_angle(normal, sign * tilt), q_half)
                routes.append((f"tilt {'+' if sign > 0 else '-'}{np.rad2deg(tilt):.0f} deg about normal {k + 1}",
                               [eigenaxis_leg(q0, q_mid, "tilted eigenaxis"), eigenaxis_leg(q_mid, q_goal)]))
    return routes


def boundary_arc_legs(problem: ManeuverProblem, side: int) -> list[AxisLeg]:
    """The λ-rotation about the axis of the forced boundary arc's cone (``problem.boundary_cone``)
    taking the sensor along its boundary on ``side`` (+1: increasing azimuth), then (a full goal)
    a roll about the sensor: :func:`cone_riding_legs` riding the boundary itself."""
    return cone_riding_legs(problem, problem.boundary_cone, side, 0.0, "roll")


def _boundary_arc(problem: ManeuverProblem, start: float) -> Plan:
    """The faster of the two boundary arcs (:func:`boundary_arc_legs`) that keeps clear of the other zones."""
    candidates = []
    for side in (+1, -1):
        legs = boundary_arc_legs(problem, side)
        tf, margin = _legs_time(problem, legs)
        candidates.append({"route": f"boundary arc {'+' if side > 0 else '-'}", "tf": tf, "min_margin": margin,
                           "legs": legs})
    best = min(candidates, key=lambda c: (c["min_margin"] < 0, c["tf"]))
    stats = {"candidates": [{k: c[k] for k in ("route", "tf", "min_margin")} for c in candidates]}
    return legs_plan(problem, METHOD, best["legs"], start, f"route: {best['route']}", stats)


def plan_constrained_axis(problem: ManeuverProblem, *, ride_margin_deg: float = 0.5) -> Plan:
    """Eigenaxis slew if it clears the zones, else the fastest zone-riding (or, zones moving,
    detour) λ-rotation sequence that clears them; with a forced boundary arc
    (``problem.boundary_cone``) the faster boundary arc (the λ-rotation baseline of Melton's BA cases).

    ``ride_margin_deg``: how far outside the zone boundary the sensor rides (deg, ≥ 0).
    """
    start = time.monotonic()
    why = no_torque_limit(problem) or boundary_arc_issue(problem)
    if why:
        return Plan(method=METHOD, status=Status.FAILED, message=why)
    if problem.boundary_cone is not None:
        return _boundary_arc(problem, start)
    zs = problem.zone_sky()
    eig = [eigenaxis_leg(problem.q_initial, goal_attitude(problem))]
    tf, margin = _legs_time(problem, eig)
    if margin >= 0:
        return legs_plan(problem, METHOD, eig, start, "eigenaxis path clears every zone",
                         {"candidates": [{"route": "eigenaxis", "tf": tf, "min_margin": margin}]})
    candidates = []
    for z in np.flatnonzero(~zs.keep_in):
        for side in (+1, -1):
            for finish in ("roll", "eigenaxis"):
                legs, t_star, widen = _moving_ride(problem, zs, int(z), side, np.deg2rad(ride_margin_deg), finish)
                if legs is None:
                    continue
                tf_c, m_c = _legs_time(problem, legs)
                candidates.append({"route": f"ride {zs.names[z]} {'+' if side > 0 else '-'} then {finish}",
                                   "tf": tf_c, "min_margin": m_c, "ride_time": t_star, "widening": widen,
                                   "legs": legs})
    if zs.moving:
        for route, legs in _detours(problem, zs):
            tf_c, m_c = _legs_time(problem, legs)
            candidates.append({"route": route, "tf": tf_c, "min_margin": m_c, "legs": legs})
    clear = [c for c in candidates if c["min_margin"] >= 0]
    stats = {"candidates": [{k: c[k] for k in ("route", "tf", "min_margin", "ride_time", "widening") if k in c}
                            for c in candidates],
             "zone_window": zs.window}
    if not clear:
        msg = "no zone-riding or detour λ-rotation sequence clears every zone"
        if any(c["tf"] > zs.window for c in candidates) and zs.moving:
            msg += f" (sequences longer than the zones' window of {zs.window:.0f} s are refused)"
        best = max(candidates, key=lambda c: c["min_margin"]) if candidates else None
        if best is None or not np.isfinite(best["min_margin"]):
            return Plan(method=METHOD, status=Status.FAILED, message=msg, stats=stats)
        plan = legs_plan(problem, METHOD, best["legs"], start, msg, stats)
        plan.status = Status.FAILED
        return plan
    best = min(clear, key=lambda c: c["tf"])
    return legs_plan(problem, METHOD, best["legs"], start, f"route: {best['route']}", stats)
