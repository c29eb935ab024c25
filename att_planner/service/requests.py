"""Validation of maneuver and schedule requests, before any numerics run (no ROS).

:func:`validate_maneuver` and :func:`validate_schedule` turn the raw fields of a ``PlanManeuver``
or ``PlanSchedule`` request into a :class:`~att_planner.problem.ManeuverProblem`, or raise
:class:`RequestError` with a code and a sentence naming the field and the reason. Documented
tolerances and caps are the constants below (docs/limits.md); method options are
checked by the registry (:mod:`att_planner.methods`). Field checks are the shared ones of
:mod:`att_msgs_py.validation` (``unit_quaternion`` and ``unit_vector`` are re-exported here): every
string is free of control characters (INVALID_TEXT) and at most ``MAX_NAME_LENGTH`` characters
(SIZE_LIMIT). Cones and zones that close the sky between the start and goal sensor directions are
refused as INFEASIBLE before any solving (:mod:`att_planner.service.sky`). The real sky (epoch,
orbit, zones) is checked by :mod:`att_planner.service.real_sky`, then the zones against
each other and the ends (:func:`att_planner.cones.check_zones`: CONTRADICTORY_ZONES, ZONE_AT_END).
A request without epoch, TLE and zones is checked and planned against its inertial cones alone.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.errors import ErrorCode, RequestError, clip
from att_msgs_py.limits import MAX_CONES, MAX_OPTIONS, MAX_TARGETS
from att_msgs_py.types import Cone, PointingMode
from att_msgs_py.validation import MAX_NAME_LENGTH, finite_array, text, unit_quaternion, unit_vector
from att_planner import methods
from att_planner.cones import BOUNDARY_TOLERANCE, boundary_arc_issue, check_zones, endpoint_in_cone
from att_planner.fdir.envelope import planning_spacecraft
from att_planner.methods import END_POINTING_METHODS, Method
from att_planner.problem import ManeuverProblem, MovingGoal
from att_planner.service.moving_goal import goal_law
from att_planner.service.real_sky import RequestGeometry, check_orbit_window, resolve_sky
from att_planner.service.sky import closed_sky
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.dynamics import Spacecraft

MAX_TIME_BUDGET = 600.0        # s
MAX_DWELL = 86_400.0           # s: a schedule target's observation, at most a day
MAX_WINDOW = 7 * 86_400.0      # s: a schedule target's window opens within a week of the start
SAME_TARGET = 1e-6             # rad: schedule targets closer than this are one attitude (q and -q too)


@dataclass
class ManeuverRequest:
    """Plain fields of a PlanManeuver request (as numpy), as the node received them."""

    frame_id: str
    q_initial: np.ndarray
    q_final: np.ndarray
    sensor_axis: np.ndarray
    cones: list                      # [(direction (3,), half_angle, name)]
    method: str = ""
    time_budget: float = 0.0
    spacecraft: str = ""
    option_names: list = field(default_factory=list)
    option_values: list = field(default_factory=list)
    semi_free: bool = False
    sensor_target: np.ndarray = field(default_factory=lambda: np.zeros(3))
    epoch: tuple = (0, 0)            # (sec, nanosec) as sent; zero: the scenario's epoch
    zones: list = field(default_factory=list)      # att_msgs_py.types.Zone, as sent
    tle_line1: str = ""
    tle_line2: str = ""
    wheel_speeds: list = field(default_factory=list)   # rad/s relative to the body at the start; empty: stopped
    end_pointing: PointingMode | None = None           # end on this mode's attitude and rate (kind ''/None: at rest)
    healthy_wheels: list = field(default_factory=list)  # the wheels the plan may use (empty: every one)
    # a goal the service builds (not from the wire): (scenario, epoch) ↦ (law t ↦ (q, ω), kind); a strip's start
    end_goal: Callable | None = None


@dataclass
class ValidRequest:
    problem: ManeuverProblem
    method: Method
    options: dict
    spacecraft: str
    time_budget: float
    spacecraft_digest: str = ""      # of the configuration named (the problem's model may be its healthy wheels')


def check_spacecraft(sc: Spacecraft, name: str) -> None:
    J = sc.inertia
    if not np.all(np.isfinite(J)) or not np.allclose(J, J.T, rtol=1e-9, atol=1e-12):
        raise RequestError(ErrorCode.INVALID_SPACECRAFT, f"spacecraft '{name}': inertia is not symmetric")
    eig = np.linalg.eigvalsh(J)
    if eig.min() <= 0:
        raise RequestError(ErrorCode.INVALID_SPACECRAFT, f"spacecraft '{name}': inertia is not positive definite")
    a, b, c = eig
    if a + b < c * (1 - 1e-9):
        raise RequestError(ErrorCode.INVALID_SPACECRAFT,
                           f"spacecraft '{name}': principal inertias {eig.tolist()} violate the triangle inequality")
    if not (sc.body_torque_max > 0 and math.isfinite(sc.body_torque_max)):
        raise RequestError(ErrorCode.INVALID_SPACECRAFT, f"spacecraft '{name}': torque_max must be positive and finite")
    for field_name in ("wheel_torque_max", "wheel_speed_max", "dipole_max"):
        if not getattr(sc, field_name) > 0:
            raise RequestError(ErrorCode.INVALID_SPACECRAFT, f"spacecraft '{name}': {field_name} must be positive")


def check_options(method: Method, names, values) -> dict:
    """The request's option lists as the method's validated options (:meth:`Method.validate`):
    names are text, each given once; values finite and in range (the registry)."""
    if len(names) != len(values):
        raise RequestError(ErrorCode.INVALID_OPTION,
                           f"option_names has {len(names)} entries but option_values has {len(values)}")
    if len(names) > MAX_OPTIONS:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"{len(names)} options given; at most {MAX_OPTIONS} are accepted")
    seen = {}
    for i, name in enumerate(names):
        text(name, f"option_names[{i}]")
        if not name:
            raise RequestError(ErrorCode.INVALID_OPTION, f"option_names[{i}] is empty")
        if name in seen:
            raise RequestError(ErrorCode.INVALID_OPTION,
                               f"option_names[{i}] repeats option '{name}' (first at option_names[{seen[name]}]); "
                               "each option may be given once")
        seen[name] = i
    return method.validate(dict(zip(names, [float(v) for v in values])))


def check_frame(request_frame: str, frame_id: str) -> None:
    """The request's header frame is empty (meaning ours) or the planner's inertial frame."""
    text(request_frame, "header.frame_id")
    if request_frame not in ("", frame_id):
        raise RequestError(ErrorCode.INVALID_FRAME,
                           f"header.frame_id '{request_frame}' is not the planner's inertial frame '{frame_id}'")


def check_cones(raw: list) -> list[Cone]:
    """At most :data:`MAX_CONES` cones, each with a unit direction, a half-angle in (0, pi/2) and a
    text name."""
    if len(raw) > MAX_CONES:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"{len(raw)} cones given; at most {MAX_CONES} are accepted")
    cones = []
    for i, (direction, half_angle, name) in enumerate(raw):
        text(name, f"cones[{i}].name")
        label = f"cones[{i}] ('{name}')"
        d = unit_vector(direction, f"{label}.direction", ErrorCode.INVALID_CONE)
        if not (math.isfinite(half_angle) and 0.0 < half_angle < math.pi / 2):
            raise RequestError(ErrorCode.INVALID_CONE,
                               f"{label}.half_angle = {half_angle} rad is outside (0, pi/2)")
        cones.append(Cone(d, float(half_angle), name or f"cone{i}"))
    return cones


def zone_window(problem: ManeuverProblem, legs: int = 1) -> float:
    """The zone window (s) of ``problem`` (:meth:`ManeuverProblem.default_window`), times
    ``legs`` for a schedule, with its observations and its last window's close: the span its orbit
    must last."""
    closes = [b for _, b in problem.target_windows.values() if math.isfinite(b)]
    return problem.default_window() * legs + sum(problem.target_dwell.values()) + max(closes, default=0.0)


def check_sky(problem: ManeuverProblem, real: RequestGeometry, legs: int = 1) -> None:
    """The orbit lasts the window (ORBIT_TOO_LOW), then the zones' own checks
    (:func:`att_planner.cones.check_zones`)."""
    if real.sky is not None:
        check_orbit_window(real.sky, zone_window(problem, legs))
    if problem.zones:
        check_zones(problem)


def check_reachable(problem: ManeuverProblem) -> None:
    """Neither end inside a cone by more than BOUNDARY_TOLERANCE (SENSOR_IN_CONE; on the boundary is
    plannable), a forced boundary arc that can be flown (INVALID_OPTION), and the cones and zones do
    not close the sky between the ends for any sensor (INFEASIBLE)."""
    q0, qf, r, cones, sensor_target = (problem.q_initial, problem.q_final, problem.sensor_axis, problem.cones,
                                       problem.sensor_target)
    hit = endpoint_in_cone(q0, qf, r, cones, sensor_target)
    if hit is not None:
        label, cone, depth = hit
        raise RequestError(ErrorCode.SENSOR_IN_CONE,
                           f"the {label} is inside cone '{cone.name}' by {np.degrees(depth):.3g} deg "
                           f"(more than the boundary tolerance of {BOUNDARY_TOLERANCE:g} rad)")
    why = boundary_arc_issue(problem)
    if why:
        raise RequestError(ErrorCode.INVALID_OPTION, why)
    if not cones and not problem.zones:
        return
    zone_sky = problem.zone_sky()
    axis = closed_sky(zone_sky, q0, qf, r, sensor_target)
    if axis is None:
        return
    goal = "goal" if sensor_target is None else "sensor_target"
    if not problem.zones:
        raise RequestError(ErrorCode.INFEASIBLE,
                           f"cones: the {len(cones)} keep-out cones close the sky between the start and {goal} "
                           "sensor directions; no sensor path avoids them")
    members = np.flatnonzero(np.all(np.isclose(zone_sky.sensor_axes, axis, atol=1e-12), axis=1))
    raise RequestError(ErrorCode.INFEASIBLE,
                       f"zones: the {len(members)} zones and cones of sensor axis {np.round(axis, 4).tolist()} "
                       f"({', '.join(zone_sky.names[i] for i in members[:6])}) close the sky between its start and "
                       f"{goal} directions over the {zone_sky.window:.0f} s zone window; no path avoids them")


def validate_maneuver(req: ManeuverRequest, *, frame_id: str, default_spacecraft: str, default_method: str,
                      default_budget: float) -> ValidRequest:
    """Check every field of a maneuver request; return the problem or raise RequestError. The
    budget counts from the call."""
    received = time.monotonic()
    check_frame(req.frame_id, frame_id)
    text(req.method, "method")
    text(req.spacecraft, "spacecraft")
    q0 = unit_quaternion(req.q_initial, "initial_attitude")
    qf = unit_quaternion(req.q_final, "final_attitude")
    r = unit_vector(req.sensor_axis, "sensor_axis", ErrorCode.INVALID_SENSOR_AXIS)
    cones = check_cones(list(req.cones))
    sensor_target = None
    if req.semi_free:
        sensor_target = unit_vector(req.sensor_target, "sensor_target", ErrorCode.INVALID_SENSOR_AXIS)
    name = req.spacecraft or default_spacecraft
    scenario = load_scenario(name)
    method = methods.get(req.method or default_method)
    options, limits = method.split(check_options(method, list(req.option_names), list(req.option_values)))
    budget = check_budget(float(req.time_budget), default_budget)
    real = resolve_sky(*req.epoch, req.zones, req.tle_line1, req.tle_line2, scenario)
    healthy = check_healthy_wheels(req.healthy_wheels, scenario.spacecraft)
    speeds = check_wheel_speeds(req.wheel_speeds, scenario.spacecraft)
    sc = scenario.spacecraft
    if healthy is not None:
        sc = planning_spacecraft(sc, healthy)
        speeds = None if speeds is None else speeds[healthy]
    problem = ManeuverProblem(sc, q0, qf, r, cones, sensor_target=sensor_target, zones=real.zones,
                              epoch=real.epoch, sky=real.sky if real.moving else None, wheel_speeds=speeds, **limits)
    if req.end_pointing is not None and req.end_pointing.kind:
        _end_on_pointing(problem, req, method, scenario)
    elif req.end_goal is not None:
        law, kind = req.end_goal(scenario, problem.epoch)
        _end_on_goal(problem, law, kind, method)
    check_sky(problem, real)
    check_reachable(problem)
    problem.deadline = received + budget          # set last: the zone sky built by the checks stays cached
    return ValidRequest(problem, method, options, name, budget, scenario.spacecraft.digest)


@dataclass
class ValidSchedule:
    problem: ManeuverProblem         # targets, start, end, rate bound; no deadline (the service sets it)
    spacecraft: str                  # its configuration name
    time_budget: float


def load_spacecraft(name: str) -> Spacecraft:
    return load_scenario(name).spacecraft


def load_scenario(name: str) -> scen.Scenario:
    """The scenario of a spacecraft configuration name, its spacecraft checked."""
    if len(name) > MAX_NAME_LENGTH or not all(ch.isalnum() or ch in "_-" for ch in name):
        raise RequestError(ErrorCode.UNKNOWN_SPACECRAFT,
                           f"spacecraft '{name[:MAX_NAME_LENGTH]}' must be a configuration name (letters, digits, "
                           "'_' and '-')")
    try:
        scen.find(name)
    except KeyError as exc:
        raise RequestError(ErrorCode.UNKNOWN_SPACECRAFT, f"spacecraft: {exc.args[0]}") from None
    try:
        scenario = scen.load(name)
    except Exception as exc:  # any configuration that does not load is refused, the node keeps serving
        why = exc.message if isinstance(exc, RequestError) else f"{type(exc).__name__}: {exc}"
        raise RequestError(ErrorCode.INVALID_SPACECRAFT, f"spacecraft '{name}': its configuration does not load ({why})"
                           ) from None
    check_spacecraft(scenario.spacecraft, name)
    return scenario


def _end_on_pointing(problem: ManeuverProblem, req: ManeuverRequest, method: Method, scenario: scen.Scenario) -> None:
    """Make ``problem``'s goal the moving one of ``req.end_pointing`` (:mod:`.moving_goal`)."""
    _check_end_method(method)
    if req.semi_free:
        raise RequestError(ErrorCode.INVALID_OPTION, "end_pointing and semi_free exclude each other")
    _end_on_goal(problem, goal_law(req.end_pointing, scenario, problem.epoch, problem.q_initial),
                 req.end_pointing.kind, method)


def _check_end_method(method: Method) -> None:
    if method.name not in END_POINTING_METHODS:
        raise RequestError(ErrorCode.INVALID_OPTION,
                           f"end_pointing: a slew that ends on a pointing mode is planned by "
                           f"{', '.join(END_POINTING_METHODS)}; {method.name} plans rest-to-rest (execute it with "
                           "point_after: the controller blends)")


def _end_on_goal(problem: ManeuverProblem, law: Callable, kind: str, method: Method) -> None:
    """Make ``problem``'s goal the moving ``law`` (``t ↦ (q, ω)``); its ``q_final`` the law's attitude
    after the eigenaxis slew time to where the law is at the start."""
    _check_end_method(method)
    window = problem.zone_sky().window
    try:
        problem.q_final = law(0.0)[0]
        problem.q_final = law(problem.slew_time_bound())[0]
        problem.goal_motion = MovingGoal(law, window, kind)
    except ValueError as err:        # the mode has no attitude somewhere in the window the plan may end in
        raise RequestError(ErrorCode.INVALID_POINTING,
                           f"end_pointing ({clip(kind, 40)}): {err} within {window:.0f} s "
                           "of the start, where the slew may end") from None


def check_wheel_speeds(speeds, sc: Spacecraft) -> np.ndarray | None:
    """The wheels' speeds at the start: none (stopped), or one finite speed per wheel within its limit."""
    if len(speeds) == 0:
        return None
    if len(speeds) != sc.n_wheels:
        raise RequestError(ErrorCode.INVALID_WHEEL_SPEEDS,
                           f"wheel_speeds has {len(speeds)} values; the spacecraft has {sc.n_wheels} wheels "
                           "(or give none)")
    out = finite_array(speeds, "wheel_speeds", ErrorCode.INVALID_WHEEL_SPEEDS)
    over = np.flatnonzero(np.abs(out) > sc.wheel_speed_max)
    if over.size:
        raise RequestError(ErrorCode.INVALID_WHEEL_SPEEDS,
                           f"wheel_speeds[{over[0]}] = {out[over[0]]:g} rad/s is beyond the wheels' limit of "
                           f"{sc.wheel_speed_max:g} rad/s")
    return out


def check_healthy_wheels(healthy, sc: Spacecraft) -> np.ndarray | None:
    """The wheels a plan may use: none given (every one), or one flag per wheel whose true ones span
    the body (the plan is then made for their envelope, :func:`att_planner.fdir.envelope.planning_spacecraft`)."""
    if len(healthy) == 0:
        return None
    if len(healthy) != sc.n_wheels:
        raise RequestError(ErrorCode.INVALID_WHEEL_SET,
                           f"healthy_wheels: expected {sc.n_wheels} values (one per wheel of the spacecraft) or "
                           f"none; found {len(healthy)}")
    mask = np.array([bool(h) for h in healthy], bool)
    if not mask.any() or np.linalg.matrix_rank(sc.wheel_axes[:, mask]) < 3:
        raise RequestError(ErrorCode.INVALID_WHEEL_SET,
                           f"healthy_wheels: expected healthy wheels whose axes span the body; found "
                           f"{mask.tolist()}, on which the attitude cannot be controlled")
    return mask


def check_budget(budget: float, default: float) -> float:
    if not math.isfinite(budget) or budget < 0 or budget > MAX_TIME_BUDGET:
        raise RequestError(ErrorCode.INVALID_TIME_BUDGET,
                           f"time_budget = {budget} s is outside [0, {MAX_TIME_BUDGET}] (0: the default)")
    return budget or default


def check_targets(names: list, targets: list) -> dict:
    """Schedule targets: as many text names as quaternions, names distinct and non-empty, unit
    quaternions, no attitude twice (within :data:`SAME_TARGET`; q and -q are one attitude)."""
    if len(targets) > MAX_TARGETS or len(names) > MAX_TARGETS:
        raise RequestError(ErrorCode.SIZE_LIMIT,
                           f"{max(len(targets), len(names))} targets given; at most {MAX_TARGETS}")
    if not targets:
        raise RequestError(ErrorCode.INVALID_ATTITUDE, "targets is empty")
    if len(names) != len(targets):
        raise RequestError(ErrorCode.INVALID_ATTITUDE, f"{len(names)} target_names for {len(targets)} targets")
    for i, n in enumerate(names):
        text(n, f"target_names[{i}]")
        if not n or n in names[:i]:
            raise RequestError(ErrorCode.INVALID_ATTITUDE,
                               f"target_names[{i}] is {'empty' if not n else f'a repeat of {n!r}'}; names must be "
                               "distinct and non-empty")
    qs = [unit_quaternion(q, f"targets[{i}] ('{n}')") for i, (n, q) in enumerate(zip(names, targets))]
    for j in range(len(qs)):
        for i in range(j):
            if rot.angle_between(qs[i], qs[j]) < SAME_TARGET:
                raise RequestError(ErrorCode.INVALID_ATTITUDE,
                                   f"targets[{i}] ('{names[i]}') and targets[{j}] ('{names[j]}') are the same "
                                   "attitude (q and -q are one attitude); each target must be distinct")
    return dict(zip(names, qs))


def check_targets_clear(problem: ManeuverProblem) -> None:
    """No schedule target violates a fixed (inertial) zone by more than BOUNDARY_TOLERANCE
    (ZONE_AT_END): it could never be passed.
    A moving zone may clear a target before it is reached: planning and verification judge those."""
    zone_sky = problem.zone_sky()
    fixed = np.array([z.body == "inertial" for z in zone_sky.zones], bool)
    if not fixed.any():
        return
    for i, (target, q) in enumerate(problem.targets.items()):
        m = np.where(fixed, zone_sky.margins(0.0, q, true=True)[0], np.inf)
        k = int(np.argmin(m))
        if m[k] < -BOUNDARY_TOLERANCE:
            kind = "outside keep-in" if zone_sky.keep_in[k] else "inside keep-out"
            raise RequestError(ErrorCode.ZONE_AT_END,
                               f"targets[{i}] ('{target}') is {kind} zone {zone_sky.names[k]} by "
                               f"{np.degrees(-m[k]):.2f} deg; it can never be passed")


def check_observations(names: list, dwell: list, opens: list, closes: list) -> tuple[dict, dict]:
    """A schedule's observations (``dwell_times``, ``window_opens``, ``window_closes``): each none or
    one value per target; dwells finite in [0, MAX_DWELL]; windows both or neither, opens finite ≥ 0,
    closes after opens by at least the dwell (.inf: never closes). ``(dwell, windows)`` by name."""
    fields = {"dwell_times": dwell, "window_opens": opens, "window_closes": closes}
    for field_name, values in fields.items():
        if len(values) not in (0, len(names)):
            raise RequestError(ErrorCode.INVALID_OBSERVATION,
                               f"{field_name} has {len(values)} values for {len(names)} targets (give one per "
                               "target, or none)")
    if bool(opens) != bool(closes):
        raise RequestError(ErrorCode.INVALID_OBSERVATION, "window_opens and window_closes go together: give both "
                                                          "or neither")
    for i, d in enumerate(dwell):
        if not (math.isfinite(d) and 0.0 <= d <= MAX_DWELL):
            raise RequestError(ErrorCode.INVALID_OBSERVATION,
                               f"dwell_times[{i}] ('{names[i]}') = {d!r} s is outside [0, {MAX_DWELL:g}] s")
    for i, (a, b) in enumerate(zip(opens, closes)):
        if not (math.isfinite(a) and 0.0 <= a <= MAX_WINDOW):
            raise RequestError(ErrorCode.INVALID_OBSERVATION,
                               f"window_opens[{i}] ('{names[i]}') = {a!r} s is outside [0, {MAX_WINDOW:g}] s")
        need = a + (dwell[i] if dwell else 0.0)
        if math.isnan(b) or b < need or b == -math.inf:
            raise RequestError(ErrorCode.INVALID_OBSERVATION,
                               f"window_closes[{i}] ('{names[i]}') = {b!r} s leaves no time to observe it (it "
                               f"opens at {a:g} s{f' and needs {dwell[i]:g} s' if dwell else ''})")
    return ({n: float(d) for n, d in zip(names, dwell) if d > 0},
            {n: (float(a), float(b)) for n, a, b in zip(names, opens, closes)})


def validate_schedule(names: list, targets: list, q_start, q_end, spacecraft: str, time_budget: float, *,
                      frame_id: str, request_frame: str, default_spacecraft: str, default_budget: float,
                      rate_max: float = math.inf, epoch: tuple = (0, 0), zones: list = (),
                      tle: tuple = ("", ""), observations: tuple = ((), (), ())) -> ValidSchedule:
    """Check a PlanSchedule request: names match targets, unit quaternions, a wheeled spacecraft,
    the real sky as for a maneuver (``epoch`` (sec, nanosec), ``zones``, ``tle`` lines; the orbit
    must last a window per leg), the observations (``(dwell_times, window_opens, window_closes)``,
    :func:`check_observations`). ``q_end`` None: end where the schedule started. ``rate_max``: the
    planner's body-rate bound."""
    check_frame(request_frame, frame_id)
    text(spacecraft, "spacecraft")
    checked = check_targets(list(names), list(targets))
    dwell, windows = check_observations(list(names), *(list(v) for v in observations))
    q0 = unit_quaternion(q_start, "start_attitude")
    q1 = q0 if q_end is None else unit_quaternion(q_end, "end_attitude")
    name = spacecraft or default_spacecraft
    scenario = load_scenario(name)
    sc = scenario.spacecraft
    if sc.n_wheels < 3 or not (np.isfinite(sc.wheel_torque_max) and np.isfinite(sc.wheel_speed_max)):
        raise RequestError(ErrorCode.INVALID_SPACECRAFT,
                           f"spacecraft '{name}' needs three or more reaction wheels with finite torque and "
                           "speed limits")
    budget = check_budget(float(time_budget), default_budget)
    real = resolve_sky(*epoch, list(zones), *tle, scenario)
    problem = ManeuverProblem(sc, q0, q1, targets=checked, rate_max=rate_max, zones=real.zones, epoch=real.epoch,
                              sky=real.sky if real.moving else None, target_dwell=dwell, target_windows=windows)
    if real.zones or real.sky is not None:
        check_sky(problem, real, legs=len(checked) + 1)
        check_targets_clear(problem)
    return ValidSchedule(problem, name, budget)
