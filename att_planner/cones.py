"""Keep-out cone geometry for a body-fixed sensor (inertial directions, body-to-inertial attitude).

The sensor boresight ``r`` (body) points along ``R(q) r`` in inertial axes. Cone ``i`` with unit
axis ``w_i`` and half-angle ``θ_i`` (:class:`att_msgs_py.types.Cone`) is respected when
``rᵀ Rᵀ w_i ≤ cos θ_i``. The *margin* is the angle between boresight and cone axis minus the
half-angle (rad): ≥ 0 means outside the cone.
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import Cone
from att_sim import rotations as rot


def boresight(q: np.ndarray, sensor_axis: np.ndarray) -> np.ndarray:
    """Inertial boresight direction(s) for attitude(s) ``q``."""
    return rot.dcm(q) @ np.asarray(sensor_axis, float)


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
    """``(name of the end, cone, depth in rad)`` of the first end direction inside a cone, else
    None: no plan can exist then."""
    for label, direction in endpoint_directions(q_initial, q_final, sensor_axis, sensor_target).items():
        m = direction_margins(direction, cones)
        if m.size and m.min() < 0:
            k = int(np.argmin(m))
            return label, cones[k], float(-m[k])
    return None


def blocked_endpoint(problem) -> str:
    """Why a problem (``ManeuverProblem``) has no plan because an end lies inside a cone, or ''."""
    hit = endpoint_in_cone(problem.q_initial, problem.q_final, problem.sensor_axis, problem.cones,
                           problem.sensor_target)
    if hit is None:
        return ""
    label, cone, depth = hit
    return (f"infeasible request: the {label} is inside keep-out cone {cone.name or '(unnamed)'} "
            f"({np.degrees(depth):.2f} deg inside its {np.degrees(cone.half_angle):.1f} deg half-angle)")
