"""Validation of maneuver and schedule requests, before any numerics run (no ROS).

:func:`validate_maneuver` and :func:`validate_schedule` turn the raw fields of a ``PlanManeuver``
or ``PlanSchedule`` request into a :class:`~att_planner.problem.ManeuverProblem`, or raise
:class:`RequestError` with a code and a sentence naming the field and the reason. Documented
tolerances and caps are the constants below (README, "Errors and limits"); method options are
checked by the registry (:mod:`att_planner.methods`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Cone
from att_planner import methods
from att_planner.cones import endpoint_in_cone
from att_planner.methods import Method
from att_planner.problem import ManeuverProblem
from att_sim import scenario as scen
from att_sim.dynamics import Spacecraft

UNIT_TOLERANCE = 1e-3          # |‖q‖ − 1| (and unit vectors) accepted and normalised below this
MAX_CONES = 16
MAX_OPTIONS = 16
MAX_TIME_BUDGET = 600.0        # s
MAX_NAME_LENGTH = 128
MAX_TARGETS = 20               # schedule targets (the order search is exponential in their number)


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


@dataclass
class ValidRequest:
    problem: ManeuverProblem
    method: Method
    options: dict
    spacecraft: str
    time_budget: float


def unit_quaternion(q, name: str) -> np.ndarray:
    q = np.asarray(q, float)
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise RequestError(ErrorCode.INVALID_ATTITUDE, f"{name} has NaN or Inf components")
    n = np.linalg.norm(q)
    if n == 0.0:
        raise RequestError(ErrorCode.INVALID_ATTITUDE, f"{name} is the zero quaternion")
    if abs(n - 1.0) > UNIT_TOLERANCE:
        raise RequestError(ErrorCode.INVALID_ATTITUDE,
                           f"{name} has norm {n:.6g}; a unit quaternion is required (tolerance {UNIT_TOLERANCE})")
    return q / n


def unit_vector(v, name: str, code: ErrorCode) -> np.ndarray:
    v = np.asarray(v, float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise RequestError(code, f"{name} has NaN or Inf components")
    n = np.linalg.norm(v)
    if n == 0.0:
        raise RequestError(code, f"{name} is the zero vector")
    if abs(n - 1.0) > UNIT_TOLERANCE:
        raise RequestError(code, f"{name} has norm {n:.6g}; a unit vector is required (tolerance {UNIT_TOLERANCE})")
    return v / n


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
    """The request's option lists as the method's validated options (:meth:`Method.validate`)."""
    if len(names) != len(values):
        raise RequestError(ErrorCode.INVALID_OPTION,
                           f"option_names has {len(names)} entries but option_values has {len(values)}")
    if len(names) > MAX_OPTIONS:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"{len(names)} options given; at most {MAX_OPTIONS} are accepted")
    return method.validate(dict(zip(names, values)))


def check_frame(request_frame: str, frame_id: str) -> None:
    """The request's header frame is empty (meaning ours) or the planner's inertial frame."""
    if request_frame not in ("", frame_id):
        raise RequestError(ErrorCode.INVALID_FRAME,
                           f"header.frame_id '{request_frame[:MAX_NAME_LENGTH]}' is not the planner's inertial "
                           f"frame '{frame_id}'")


def validate_maneuver(req: ManeuverRequest, *, frame_id: str, default_spacecraft: str, default_method: str,
                      default_budget: float) -> ValidRequest:
    """Check every field of a maneuver request; return the problem or raise RequestError."""
    check_frame(req.frame_id, frame_id)
    q0 = unit_quaternion(req.q_initial, "initial_attitude")
    qf = unit_quaternion(req.q_final, "final_attitude")
    r = unit_vector(req.sensor_axis, "sensor_axis", ErrorCode.INVALID_SENSOR_AXIS)
    if len(req.cones) > MAX_CONES:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"{len(req.cones)} cones given; at most {MAX_CONES} are accepted")
    cones = []
    for i, (direction, half_angle, name) in enumerate(req.cones):
        label = f"cones[{i}] ('{name[:MAX_NAME_LENGTH]}')"
        d = unit_vector(direction, f"{label}.direction", ErrorCode.INVALID_CONE)
        if not (math.isfinite(half_angle) and 0.0 < half_angle < math.pi / 2):
            raise RequestError(ErrorCode.INVALID_CONE,
                               f"{label}.half_angle = {half_angle} rad is outside (0, pi/2)")
        cones.append(Cone(d, float(half_angle), name or f"cone{i}"))
    sensor_target = None
    if req.semi_free:
        sensor_target = unit_vector(req.sensor_target, "sensor_target", ErrorCode.INVALID_SENSOR_AXIS)
    hit = endpoint_in_cone(q0, qf, r, cones, sensor_target)
    if hit is not None:
        label, cone, depth = hit
        raise RequestError(ErrorCode.SENSOR_IN_CONE,
                           f"the {label} is inside cone '{cone.name}' by {np.degrees(depth):.3f} deg")
    name = req.spacecraft or default_spacecraft
    sc = load_spacecraft(name)
    method = methods.get(req.method or default_method)
    options, limits = method.split(check_options(method, list(req.option_names), [float(v) for v in req.option_values]))
    budget = check_budget(float(req.time_budget), default_budget)
    problem = ManeuverProblem(sc, q0, qf, r, cones, deadline=time.monotonic() + budget, sensor_target=sensor_target,
                              **limits)
    return ValidRequest(problem, method, options, name, budget)


@dataclass
class ValidSchedule:
    problem: ManeuverProblem         # targets, start, end, rate bound; no deadline (the service sets it)
    spacecraft: str                  # its configuration name
    time_budget: float


def load_spacecraft(name: str) -> Spacecraft:
    if len(name) > MAX_NAME_LENGTH or not all(ch.isalnum() or ch in "_-" for ch in name):
        raise RequestError(ErrorCode.UNKNOWN_SPACECRAFT,
                           "spacecraft must be a configuration name (letters, digits, '_' and '-')")
    try:
        sc = scen.load(name).spacecraft
    except KeyError as exc:
        raise RequestError(ErrorCode.UNKNOWN_SPACECRAFT, str(exc.args[0])) from None
    except (ValueError, TypeError) as exc:
        raise RequestError(ErrorCode.INVALID_SPACECRAFT, f"spacecraft '{name}': {exc}") from None
    check_spacecraft(sc, name)
    return sc


def check_budget(budget: float, default: float) -> float:
    if not math.isfinite(budget) or budget < 0 or budget > MAX_TIME_BUDGET:
        raise RequestError(ErrorCode.INVALID_TIME_BUDGET,
                           f"time_budget = {budget} s is outside [0, {MAX_TIME_BUDGET}] (0: the default)")
    return budget or default


def validate_schedule(names: list, targets: list, q_start, q_end, spacecraft: str, time_budget: float, *,
                      frame_id: str, request_frame: str, default_spacecraft: str, default_budget: float,
                      rate_max: float = math.inf) -> ValidSchedule:
    """Check a PlanSchedule request: names match targets, unit quaternions, a wheeled spacecraft.
    ``q_end`` None: end where the schedule started. ``rate_max``: the planner's body-rate bound."""
    check_frame(request_frame, frame_id)
    if len(targets) > MAX_TARGETS or len(names) > MAX_TARGETS:
        raise RequestError(ErrorCode.SIZE_LIMIT,
                           f"{max(len(targets), len(names))} targets given; at most {MAX_TARGETS}")
    if not targets:
        raise RequestError(ErrorCode.INVALID_ATTITUDE, "targets is empty")
    if len(names) != len(targets):
        raise RequestError(ErrorCode.INVALID_ATTITUDE, f"{len(names)} target_names for {len(targets)} targets")
    if len(set(names)) != len(names) or any(not n or len(n) > MAX_NAME_LENGTH for n in names):
        raise RequestError(ErrorCode.INVALID_ATTITUDE, "target_names must be distinct, non-empty and short")
    checked = {n: unit_quaternion(q, f"targets[{i}] ('{n}')") for i, (n, q) in enumerate(zip(names, targets))}
    q0 = unit_quaternion(q_start, "start_attitude")
    q1 = q0 if q_end is None else unit_quaternion(q_end, "end_attitude")
    name = spacecraft or default_spacecraft
    sc = load_spacecraft(name)
    if sc.n_wheels < 3 or not (np.isfinite(sc.wheel_torque_max) and np.isfinite(sc.wheel_speed_max)):
        raise RequestError(ErrorCode.INVALID_SPACECRAFT,
                           f"spacecraft '{name}' needs three or more reaction wheels with finite torque and "
                           "speed limits")
    problem = ManeuverProblem(sc, q0, q1, targets=checked, rate_max=rate_max)
    return ValidSchedule(problem, name, check_budget(float(time_budget), default_budget))
