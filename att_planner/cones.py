"""Keep-out cone geometry for a body-fixed sensor (inertial directions, body-to-inertial attitude).

The sensor boresight ``r`` (body) points along ``R(q) r`` in inertial axes. Cone ``i`` with unit
axis ``w_i`` and half-angle ``θ_i`` (:class:`att_msgs_py.types.Cone`) is respected when
``rᵀ Rᵀ w_i ≤ cos θ_i``. The *margin* is the angle between boresight and cone axis minus the
half-angle (rad): ≥ 0 means outside the cone.

Boundary ends: a start or goal direction within :data:`BOUNDARY_TOLERANCE` of a boundary
is on it (plannable); only one inside by more is refused (:func:`endpoint_in_cone`). A path that
leaves such an end is necessarily near the boundary while its boresight is near the end, so the
verification asks margin ≥ −tol within :data:`END_RADIUS` of the path's own start and final
boresight, ≥ 0 elsewhere (:func:`att_planner.verification.clearances`), and the planners ramp their
tightening of such a zone up from −tol over the first and last :data:`END_RAMP` of the maneuver
(:func:`end_ramp`). A forced boundary arc (``ManeuverProblem.boundary_cone``) keeps the boresight
on one cone's boundary for the whole maneuver (:func:`boundary_arc_issue`).

The checks of a request's zones (:mod:`att_planner.zones`) are here too:
:func:`zone_issue` gives the code and sentence of the first bad zone, contradiction or violated end.
"""
from __future__ import annotations

import numpy as np

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Cone, Zone
from att_planner.zones import FittedZones, same_axis
from att_sim.models import rotations as rot

BOUNDARY_TOLERANCE = 1e-6   # rad: an end direction this far inside a boundary is on it
END_RADIUS = 0.01           # rad: the neighbourhood of an end direction where margin ≥ −tol suffices
END_RAMP = 0.1              # fraction of the maneuver over which a planner's tightening ramps up at a boundary end
SMOOTH_END_RAMP = 0.25      # the same for smooth plans (Slepian basis: the boresight moves 7e-5 rad by τ = 0.05)
ARC_TOLERANCE = 1e-4        # rad: a forced boundary arc keeps |margin| within this on the dense grid


def boresight(q: np.ndarray, sensor_axis: np.ndarray) -> np.ndarray:
    """Inertial boresight direction(s) for attitude(s) ``q``."""
    return rot.dcm_NB(q) @ np.asarray(sensor_axis, float)


def direction_margins(direction: np.ndarray, cones: list[Cone]) -> np.ndarray:
    """Margins (rad) of inertial direction(s) ``(..., 3)``, shape ``(..., len(cones))``."""
    b = np.asarray(direction, float)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    if not cones:
        return np.zeros(b.shape[:-1] + (0,))
    W = np.stack([c.direction for c in cones])           # (C, 3)
    theta = np.array([c.half_angle for c in cones])       # (C,)
    return np.arccos(np.clip(b @ W.T, -1.0, 1.0)) - theta


def margins(q: np.ndarray, sensor_axis: np.ndarray, cones: list[Cone]) -> np.ndarray:
    """Cone margins (rad) of the boresight at attitude(s) ``q``, shape ``q.shape[:-1] + (len(cones),)``."""
    return direction_margins(boresight(q, sensor_axis), cones)


def min_margin(q: np.ndarray, sensor_axis: np.ndarray, cones: list[Cone]) -> float:
    """Smallest margin over all samples and cones (rad); +inf without cones."""
    m = margins(q, sensor_axis, cones)
    return float(m.min()) if m.size else float("inf")


def endpoint_directions(q_initial, q_final, sensor_axis, sensor_target=None) -> dict[str, np.ndarray]:
    """The sensor directions a maneuver must start and end at, by name."""
    ends = {"start sensor direction": boresight(q_initial, sensor_axis)}
    if sensor_target is None:
        ends["goal sensor direction"] = boresight(q_final, sensor_axis)
    else:
        ends["sensor_target direction"] = np.asarray(sensor_target, float)
    return ends


def endpoint_in_cone(q_initial, q_final, sensor_axis, cones: list[Cone],
                     sensor_target=None) -> tuple[str, Cone, float] | None:
    """``(name of the end, cone, depth in rad)`` of the first end direction inside a cone by more
    than :data:`BOUNDARY_TOLERANCE`, else None (no plan can exist then; one on the boundary is plannable)."""
    for label, direction in endpoint_directions(q_initial, q_final, sensor_axis, sensor_target).items():
        m = direction_margins(direction, cones)
        if m.size and m.min() < -BOUNDARY_TOLERANCE:
            k = int(np.argmin(m))
            return label, cones[k], float(-m[k])
    return None


def end_ramp(tau, length: float = END_RAMP) -> np.ndarray:
    """Weight in [0, 1] of a planner's zone tightening δ at maneuver fractions ``tau`` for a zone
    with an end on its boundary: ``min(1, (min(τ, 1 − τ)/length)⁴)``; the tightening there is
    ``−tol + (δ + tol)·w``, negative for τ < 0.18 length only, where a bang-bang slew of a few
    time units (``END_RAMP``) or a smooth one (``SMOOTH_END_RAMP``) has moved the boresight by less
    than END_RADIUS. Quartic, so that the boresight, which starts from rest, clears it."""
    tau = np.clip(np.asarray(tau, float), 0.0, 1.0)
    return np.minimum(1.0, np.minimum(tau, 1.0 - tau) / length) ** 4


def boundary_end_zones(problem, margin: float) -> np.ndarray:
    """Which zones of ``problem.zone_sky()`` a planner tightened by ``margin`` rad must ramp
    (:func:`end_ramp`): those whose start or goal (semi-free: ``sensor_target``, for the zones of
    ``problem.sensor_axis``) has a margin below ``margin`` at t = 0."""
    zs = problem.zone_sky()
    if not zs.zones:
        return np.zeros(0, bool)
    ends = [zs.margins(0.0, problem.q_initial, true=True)[0]]
    if problem.sensor_target is None:
        ends.append(zs.margins(0.0, problem.q_final, true=True)[0])
    else:
        own = np.array([same_axis(s, problem.sensor_axis) for s in zs.sensor_axes], bool)
        target = np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
        gamma = np.arccos(np.clip(zs.true_axes(0.0) @ target, -1.0, 1.0))
        theta = zs.true_half_angles(0.0)
        ends.append(np.where(own, np.where(zs.keep_in, theta - gamma, gamma - theta), np.inf))
    return np.min(ends, axis=0) < margin


def boundary_arc_issue(problem) -> str:
    """Why the forced boundary arc of ``problem`` (``boundary_cone``: an index into its cones) cannot
    be flown, or '': no such cone, or the start or goal sensor direction (semi-free: the target) not
    on that cone's boundary within :data:`BOUNDARY_TOLERANCE`."""
    index = problem.boundary_cone
    if index is None:
        return ""
    cones = problem.cones
    if not 0 <= index < len(cones):
        names = ", ".join(f"{i}: '{c.name}'" for i, c in enumerate(cones)) or "none"
        return f"option boundary_cone = {index} names no cone of the request (its cones: {names})"
    cone = cones[index]
    for label, direction in endpoint_directions(problem.q_initial, problem.q_final, problem.sensor_axis,
                                                problem.sensor_target).items():
        m = float(direction_margins(direction, [cone])[0])
        if abs(m) > BOUNDARY_TOLERANCE:
            side = "outside" if m > 0 else "inside"
            return (f"option boundary_cone = {index}: the {label} is {np.degrees(abs(m)):.4g} deg {side} the "
                    f"boundary of cone '{cone.name}' (a boundary arc starts and ends on it, within "
                    f"{BOUNDARY_TOLERANCE:g} rad)")
    return ""


def blocked_endpoint(problem) -> str:
    """Why a problem (``ManeuverProblem``) has no plan because an end lies inside a cone (by more
    than :data:`BOUNDARY_TOLERANCE`), its boundary arc cannot be flown (:func:`boundary_arc_issue`),
    or an end violates a zone at t = 0 (:func:`zone_at_end`), or ''."""
    hit = endpoint_in_cone(problem.q_initial, problem.q_final, problem.sensor_axis, problem.cones,
                           problem.sensor_target)
    if hit is None:
        why = boundary_arc_issue(problem) or (zone_at_end(problem) if problem.zones else "")
        return f"infeasible request: {why}" if why else ""
    label, cone, depth = hit
    return (f"infeasible request: the {label} is inside keep-out cone {cone.name or '(unnamed)'} "
            f"({np.degrees(depth):.2f} deg inside its {np.degrees(cone.half_angle):.1f} deg half-angle)")


# ---------------------------------------------------------------------- zones


def invalid_zone(index: int, zone: Zone) -> str:
    """Why ``zone`` (``zones[index]``) cannot be used, or '': the one zone check of the suite,
    :func:`att_msgs_py.validation.zone` (known body, unit axes, half-angle range, a direction only
    for an inertial zone)."""
    try:
        validation.zone(zone, f"zones[{index}]")
    except RequestError as err:
        return err.message
    return ""


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.arccos(np.clip(a @ b / (np.linalg.norm(a) * np.linalg.norm(b)), -1.0, 1.0)))


def contradictory_zones(zone_sky: FittedZones) -> str:
    """Why no boresight satisfies the zones of one sensor at t = 0, or '': a keep-in cone entirely
    inside a keep-out cone (γ + θ_in ≤ θ_out), or two keep-in cones that do not meet (γ > θ_1 + θ_2).
    Only pairs are checked: a keep-in cone covered by several keep-out cones together is not."""
    axes, half = zone_sky.at(0.0, true=True)
    names, keep_in, s = zone_sky.names, zone_sky.keep_in, zone_sky.sensor_axes
    for i in np.flatnonzero(keep_in):
        for j in range(len(names)):
            if j == i or not same_axis(s[i], s[j]):
                continue
            gamma = _angle(axes[i], axes[j])
            if not keep_in[j] and gamma + half[i] <= half[j]:
                return (f"keep-in zone {names[i]} lies entirely inside keep-out zone {names[j]} at t = 0 "
                        f"({np.degrees(gamma):.2f} deg apart, half-angles {np.degrees(half[i]):.2f} and "
                        f"{np.degrees(half[j]):.2f} deg)")
            if keep_in[j] and j > i and gamma > half[i] + half[j]:
                return (f"keep-in zones {names[i]} and {names[j]} of one sensor do not meet at t = 0 "
                        f"({np.degrees(gamma):.2f} deg apart > {np.degrees(half[i] + half[j]):.2f} deg)")
    return ""


GOAL_CHECK_TIMES = 2001      # times over the zones' window at which a goal is judged against moving zones


def zone_at_end(problem, zone_sky: FittedZones | None = None) -> str:
    """Why the start or the goal violates a zone, or '': the start at t = 0; the goal at every
    time of the zones' window (``GOAL_CHECK_TIMES`` times over [0, window]): the arrival time is
    not known before planning, so a goal is refused only when no arrival time in the window clears
    it (a fixed zone: at t = 0); the verification checks the zones at the true arrival time. For a
    semi-free goal only the zones of ``problem.sensor_axis`` are checked, on ``sensor_target`` (the
    roll about it is free)."""
    zs = zone_sky if zone_sky is not None else problem.zone_sky()
    if not zs.zones:
        return ""
    times = np.linspace(0.0, zs.window, GOAL_CHECK_TIMES) if zs.moving else np.zeros(1)
    if problem.sensor_target is None:
        goal = zs.margins(times, problem.q_final, true=True)                    # (K, Z)
        goal_label = "goal attitude"
    else:
        target = np.asarray(problem.sensor_target, float)
        own = np.array([same_axis(s, problem.sensor_axis) for s in zs.sensor_axes], bool)
        angle = np.arccos(np.clip(zs.true_axes(times) @ (target / np.linalg.norm(target)), -1.0, 1.0))
        theta = zs.true_half_angles(times)
        goal = np.where(own, np.where(zs.keep_in, theta - angle, angle - theta), np.inf)
        goal_label = "sensor_target direction"
    ends = [("start attitude", zs.margins(0.0, problem.q_initial, true=True)[0], "at t = 0"),
            (goal_label, goal.max(axis=0), "at t = 0" if not zs.moving else
             f"at every arrival time in [0, {zs.window:.0f}] s (its best)")]
    for label, m, when in ends:
        if m.size and m.min() < -BOUNDARY_TOLERANCE:
            k = int(np.argmin(m))
            kind = "outside keep-in" if zs.keep_in[k] else "inside keep-out"
            return (f"the {label} is {kind} zone {zs.names[k]} {when} ({np.degrees(-m[k]):.2f} deg beyond "
                    f"its {np.degrees(zs.true_half_angles(0.0)[k]):.2f} deg half-angle at t = 0)")
    return ""


def zone_issue(problem) -> tuple[ErrorCode, str] | None:
    """The first reason the zones of ``problem`` make it unplannable, as ``(code, sentence)``, else
    None: INVALID_ZONE (:func:`invalid_zone`, or a moving zone without a sky),
    CONTRADICTORY_ZONES (:func:`contradictory_zones`), ZONE_AT_END (:func:`zone_at_end`). The
    cones (zones of ``sensor_axis``) take part; their own checks stay SENSOR_IN_CONE's."""
    for i, zone in enumerate(problem.zones):
        why = invalid_zone(i, zone)
        if why:
            return ErrorCode.INVALID_ZONE, why
    try:
        zs = problem.zone_sky()
    except ValueError as exc:
        return ErrorCode.INVALID_ZONE, str(exc)
    why = contradictory_zones(zs)
    if why:
        return ErrorCode.CONTRADICTORY_ZONES, why
    why = zone_at_end(problem, zs)
    if why:
        return ErrorCode.ZONE_AT_END, why
    return None


def check_zones(problem) -> None:
    """:func:`zone_issue` as a ``RequestError`` (the planner service's check), or nothing."""
    issue = zone_issue(problem)
    if issue is not None:
        raise RequestError(*issue)
