"""Warm starts of the time-optimal planner: cheap, diverse routes turned into bang-bang guesses.

Routes are λ-rotation sequences (:mod:`att_planner.methods.axis_rotations`) — eigenaxis both ways
round, the eigenaxis midpoint tilted, the cone-riding routes of
:mod:`att_planner.methods.constrained_axis` — or other methods' plans.

Zones that move (:mod:`att_planner.zones`): a route's margin is measured against every zone at the
physical time the route passes each attitude (its bang-bang timing), and a moving keep-out zone is
ridden as the cone it is when the sensor passes it: frozen at the time of the eigenaxis route's
closest approach, then once more at the time of the riding route's own closest approach. Inertial
zones are constant, so among keep-out cones alone every route is the frozen one.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from att_msgs_py.types import Plan
from att_planner.methods.axis_rotations import AxisLeg, axis_acceleration, eigenaxis_leg, goal_attitude
from att_planner.methods.constrained_axis import boundary_arc_legs, cone_riding_legs
from att_planner.methods.time_optimal import collocation as col
from att_planner.methods.time_optimal.model import BOUND_MARGIN, Scaling
from att_planner.problem import ManeuverProblem
from att_planner.verification import clearances
from att_sim.models import rotations as rot


@dataclass
class Route:
    """A cheap route used as a warm start: a sequence of λ-rotations or another method's plan."""

    label: str
    legs: list | None = None
    plan: Plan | None = None
    tf_estimate: float = np.inf       # TU
    min_margin: float = np.inf        # rad, along the route


def zone_margin(problem: ManeuverProblem, t: np.ndarray, q: np.ndarray) -> float:
    """Smallest margin (rad) of attitudes ``q`` (K, 4) at times ``t`` (K,) s over every zone of the
    problem (:meth:`att_planner.zones.FittedZones.margins`, the fitted motion; a time past the zones'
    window counts as its end, for a guess only); +inf without zones."""
    zones = problem.zone_sky()
    m = zones.margins(np.minimum(t, zones.window), q)
    return float(m.min()) if m.size else np.inf


def _peak_rate(problem: ManeuverProblem, scaling: Scaling, e_body: np.ndarray) -> float:
    """Largest path rate (rad per TU) about body axis ``e`` within the problem's body-rate and
    wheel-momentum bounds (tightened like the NLP's, :data:`~.model.BOUND_MARGIN`); inf without
    (a spacecraft without wheels holds no wheel momentum)."""
    limit = np.inf
    if np.isfinite(problem.rate_max):
        limit = problem.rate_max * scaling.tu * (1 - BOUND_MARGIN) / np.abs(e_body).max()
    if np.isfinite(problem.wheel_momentum_max) and problem.spacecraft.n_wheels:
        per_rate = np.abs(problem.spacecraft.wheel_axes_pinv @ scaling.Jn @ e_body).max() * scaling.J0 / scaling.tu
        limit = min(limit, problem.wheel_momentum_max * (1 - BOUND_MARGIN) / per_rate)
    return limit


def _leg_route_functions(problem: ManeuverProblem, scaling: Scaling, legs):
    """Continuous motion along a leg sequence: the path angle s(t) accelerates, coasts at the peak
    rate the rate and momentum bounds allow (when they bind) and brakes, with the smallest per-leg
    axis acceleration and peak rate. Returns (tf, state(t), control(t)) in normalised units."""
    legs = [leg for leg in legs if leg.angle > 1e-9] or [AxisLeg(np.array([0.0, 0.0, 1.0]), 1e-6)]
    q = rot.normalize(np.asarray(problem.q_initial, float))
    starts, axes_body, cum = [], [], [0.0]
    total = sum(leg.angle for leg in legs)
    alpha, peak = np.inf, np.inf
    for leg in legs:
        e = rot.dcm_BN(q) @ leg.axis
        alpha = min(alpha, axis_acceleration(scaling.Jn, e, total, 1.0))
        peak = min(peak, _peak_rate(problem, scaling, e))
        starts.append(q)
        axes_body.append(e)
        q = rot.multiply(rot.from_axis_angle(leg.axis, leg.angle), q)
        cum.append(cum[-1] + leg.angle)
    t_acc = t_brake = np.sqrt(total / alpha)                 # end of the acceleration, start of the braking
    if peak < alpha * t_acc:                                 # the bounds bind: coast at the peak rate
        t_acc = peak / alpha
        t_brake = t_acc + (total - alpha * t_acc**2) / peak
    v = alpha * t_acc
    tf = t_brake + t_acc
    cum = np.array(cum)

    def law(t):
        t = np.clip(t, 0.0, tf)
        first, coast = t <= t_acc, t <= t_brake
        s = np.where(first, 0.5 * alpha * t**2,
                     np.where(coast, 0.5 * alpha * t_acc**2 + v * (t - t_acc), total - 0.5 * alpha * (tf - t) ** 2))
        sd = np.where(first, alpha * t, np.where(coast, v, alpha * (tf - t)))
        sdd = np.where(first, alpha, np.where(coast, 0.0, -alpha))
        k = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(legs) - 1)
        return s, sd, sdd, k

    axes = np.array([leg.axis for leg in legs])
    starts = np.array(starts)
    axes_body = np.array(axes_body)

    def state(t):
        s, sd, _, k = law(np.asarray(t, float))
        q = rot.multiply(rot.from_axis_angle(axes[k], s - cum[k]), starts[k])
        return np.concatenate([q, axes_body[k] * sd[:, None]], axis=1)

    def control(t):
        _, sd, sdd, k = law(np.asarray(t, float))
        E = axes_body[k]
        JE = E @ scaling.Jn.T
        u = JE * sdd[:, None] + sd[:, None] ** 2 * np.cross(E, JE)
        return np.clip(u, -1.0, 1.0)

    return tf, state, control


def _plan_route_functions(plan: Plan, scaling: Scaling):
    """Warm start from another method's plan (its reference states and torques, normalised)."""
    tn = np.asarray(plan.t, float) / scaling.tu
    tf = float(tn[-1])

    def state(t):
        q = np.stack([np.interp(t, tn, plan.q[:, j]) for j in range(4)], axis=-1)
        w = np.stack([np.interp(t, tn, plan.omega[:, j]) for j in range(3)], axis=-1) * scaling.tu
        return np.concatenate([rot.normalize(q), w], axis=-1)

    def control(t):
        u = np.stack([np.interp(t, tn, plan.torque[:, j]) for j in range(3)], axis=-1)
        return np.clip(u / scaling.torque_max, -1.0, 1.0)

    return tf, state, control


def route_guess(problem, scaling, route: Route, phase: col.Phase) -> col.PhaseGuess:
    if route.plan is not None:
        tf, state, control = _plan_route_functions(route.plan, scaling)
    else:
        tf, state, control = _leg_route_functions(problem, scaling, route.legs)
    return col.guess_from_functions(phase, tf, state, control)


def candidate_routes(problem: ManeuverProblem, scaling: Scaling, tilt_deg: float = 45.0,
                     ride_margin_deg: float = 2.0) -> list[Route]:
    """Cheap, diverse routes: eigenaxis both ways, the eigenaxis midpoint tilted about two axes
    perpendicular to it (±), every cone-riding λ-rotation sequence and, for a forced boundary arc,
    the λ-rotations along it (:func:`~att_planner.methods.constrained_axis.boundary_arc_legs`).
    Each gets its bang-bang duration estimate and its smallest zone clearance.

    With a semi-free target whose ``q_final`` also points the sensor at it, the routes to
    ``q_final`` are added (labelled "full goal"): every fully specified plan is feasible for the
    semi-free problem, so they seed the semi-free search with the fully specified optima."""
    routes = _goal_routes(problem, scaling, tilt_deg, ride_margin_deg)
    if problem.boundary_cone is not None:
        for side in (+1, -1):
            routes.append(Route(f"boundary arc {'+' if side > 0 else '-'}", boundary_arc_legs(problem, side)))
            _estimate(problem, scaling, routes[-1])
    if problem.sensor_target is not None:
        r = np.asarray(problem.sensor_axis, float)
        b = rot.dcm_NB(rot.normalize(np.asarray(problem.q_final, float))) @ r
        s = np.asarray(problem.sensor_target, float)
        if b @ s / np.linalg.norm(b) / np.linalg.norm(s) > np.cos(np.deg2rad(0.5)):
            full = replace(problem, sensor_target=None)
            for rt in _goal_routes(full, scaling, tilt_deg, ride_margin_deg):
                rt.label += " (full goal)"
                routes.append(rt)
    return routes


def _goal_routes(problem: ManeuverProblem, scaling: Scaling, tilt_deg: float,
                 ride_margin_deg: float) -> list[Route]:
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    q_goal = goal_attitude(problem)
    eig = eigenaxis_leg(q0, q_goal)
    routes = [Route("eigenaxis", [eig])]
    if eig.angle < np.pi - 1e-3:
        routes.append(Route("eigenaxis long way", [AxisLeg(-eig.axis, 2 * np.pi - eig.angle)]))
    a = eig.axis
    n1, n2 = rot.orthonormal_basis(a)
    q_half = rot.multiply(rot.from_axis_angle(a, eig.angle / 2), q0)
    for name, n in (("n1", n1), ("n2", n2)):
        for sign in (+1, -1):
            q_mid = rot.multiply(rot.from_axis_angle(n, sign * np.deg2rad(tilt_deg)), q_half)
            routes.append(Route(f"tilted {'+' if sign > 0 else '-'}{name}",
                                 [eigenaxis_leg(q0, q_mid), eigenaxis_leg(q_mid, q_goal)]))
    for z, name, cone in _ride_cones(problem, scaling, routes[0], ride_margin_deg):
        for side in (+1, -1):
            for finish in ("eigenaxis", "roll"):
                legs = _ride(problem, z, cone, side, ride_margin_deg, finish)
                if legs is not None:
                    routes.append(Route(f"ride {name} {'+' if side > 0 else '-'} {finish}", legs))
    for rt in routes:
        _estimate(problem, scaling, rt)
    return routes


def _estimate(problem: ManeuverProblem, scaling: Scaling, route: Route, samples: int = 400) -> np.ndarray:
    """Set the route's bang-bang duration (TU) and its smallest zone clearance along it (every zone
    at the time the route passes, :func:`att_planner.verification.clearances`); returns the
    clearances (samples, Z)."""
    tf, state, _ = _leg_route_functions(problem, scaling, route.legs)
    t = np.linspace(0.0, tf, samples)
    m = clearances(problem, np.minimum(t * scaling.tu, problem.zone_sky().window), state(t)[:, :4], true=False)
    route.tf_estimate = tf
    route.min_margin = float(m.min()) if m.size else np.inf
    return m


def _snapshot(problem: ManeuverProblem, scaling: Scaling, route: Route, z: int) -> tuple:
    """``(axis, half-angle)`` of zone ``z`` when ``route`` comes closest to it (its own timing)."""
    zones = problem.zone_sky()
    m = _estimate(problem, scaling, route)
    t = min(np.linspace(0.0, route.tf_estimate, len(m))[int(np.argmin(m[:, z]))] * scaling.tu, zones.window)
    return zones.axes(t)[z], float(zones.half_angles(t)[z])


def _ride_cones(problem: ManeuverProblem, scaling: Scaling, eigenaxis: Route, ride_margin_deg: float):
    """``(z, name, cone)`` for every keep-out zone, ``cone`` the ``(axis, half-angle)`` it is when
    the sensor passes it (module docstring), None for a zone that does not move (ridden as it is).
    Keep-in zones are not ridden."""
    zones = problem.zone_sky()
    for z, zone in enumerate(zones.zones):
        if zone.keep_in:
            continue
        cone = None
        if zone.body != "inertial":
            cone = _snapshot(problem, scaling, eigenaxis, z)
            legs = _ride(problem, z, cone, +1, ride_margin_deg, "eigenaxis")
            if legs is not None:
                cone = _snapshot(problem, scaling, Route("ride", legs), z)
        yield z, zone.name or str(z), cone


def _ride(problem: ManeuverProblem, z: int, cone, side: int, ride_margin_deg: float, finish: str):
    """:func:`~att_planner.methods.constrained_axis.cone_riding_legs` of zone ``z`` (its own
    sensor) around ``cone`` (``(axis, half-angle)``, None: the zone as it is)."""
    axis, half_angle = (None, None) if cone is None else cone
    return cone_riding_legs(problem, z, side, np.deg2rad(ride_margin_deg), finish, axis, half_angle)


def select_routes(routes: list[Route], count: int) -> list[Route]:
    """``count`` routes: those clearing the cones by increasing duration, then the least violating."""
    clear = sorted([r for r in routes if r.min_margin >= 0], key=lambda r: r.tf_estimate)
    blocked = sorted([r for r in routes if r.min_margin < 0], key=lambda r: -r.min_margin)
    return (clear + blocked)[:count]
