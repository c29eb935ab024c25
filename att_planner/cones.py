"""Keep-out cones for a body-fixed sensor (inertial directions, body-to-inertial attitude).

The sensor boresight ``r`` (body) points along ``R(q) r`` in inertial axes. Cone ``i`` with unit
axis ``w_i`` and half-angle ``θ_i`` is respected when ``rᵀ Rᵀ w_i ≤ cos θ_i``. The *margin* is the
angle between boresight and cone axis minus the half-angle (rad): ≥ 0 means outside the cone.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from att_sim import rotations as rot


@dataclass(frozen=True)
class Cone:
    direction: np.ndarray   # (3,) inertial unit vector
    half_angle: float       # rad, in (0, π/2)
    name: str = ""

    def __post_init__(self):
        d = np.asarray(self.direction, dtype=float)
        object.__setattr__(self, "direction", d / np.linalg.norm(d))


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
