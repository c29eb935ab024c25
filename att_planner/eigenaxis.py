"""Smooth eigenaxis rest-to-rest slew: the always-available baseline and safe fallback.

Rotation by φ about the fixed body axis e of ``q_i* ⊗ q_f`` with the quintic (minimum-jerk)
angle profile θ(t) = φ p(t/T), p(s) = 10s³ − 15s⁴ + 6s⁵: rate is C¹... zero with zero
acceleration at both ends, so the torque starts and ends at zero and is continuous. Body torque
(ω = θ̇ e)::

    τ(t) = J e θ̈ + θ̇² e × J e = (φ/T²) [J e p''(s) + φ p'(s)² e × J e]

The duration T is the smallest that keeps every axis within T̄:
``T² = φ max_{s,j} |(J e p'' + φ p'² e × J e)_j| / T̄``. Cones are not considered by the profile;
verification reports whether the path enters one.
"""
from __future__ import annotations

import time

import numpy as np

from att_planner.problem import STATUS_FAILED, STATUS_OPTIMAL, ManeuverPlan, ManeuverProblem
from att_planner.cones import margins
from att_sim import rotations as rot

METHOD = "eigenaxis_smooth"


def _profile(s):
    return 10 * s**3 - 15 * s**4 + 6 * s**5, 30 * s**2 - 60 * s**3 + 30 * s**4, 60 * s - 180 * s**2 + 120 * s**3


def plan_eigenaxis_smooth(problem: ManeuverProblem, samples: int = 401) -> ManeuverPlan:
    """Eigenaxis slew with the quintic profile, sampled at ``samples`` knots (linear interpolation)."""
    start = time.perf_counter()
    if not 11 <= samples <= 100_000:
        raise ValueError(f"option samples={samples} is outside [11, 100000]")
    J, tmax = problem.spacecraft.inertia, problem.spacecraft.body_torque_max
    axis, phi = rot.to_axis_angle(rot.multiply(rot.conjugate(problem.q_initial), problem.q_final))
    s = np.linspace(0.0, 1.0, samples)
    p, dp, ddp = _profile(s)
    if phi < 1e-12:
        t = np.linspace(0.0, 1.0, samples)
        return ManeuverPlan(METHOD, t, np.zeros((samples, 3)), np.tile(problem.q_initial, (samples, 1)),
                            np.zeros((samples, 3)), "linear", STATUS_OPTIMAL, "already at the goal attitude",
                            time.perf_counter() - start)
    shape = J @ axis * ddp[:, None] + phi * dp[:, None] ** 2 * np.cross(axis, J @ axis)
    duration = np.sqrt(phi * np.abs(shape).max() / tmax)
    t = s * duration
    torque = phi / duration**2 * shape
    q = rot.multiply(problem.q_initial, rot.from_axis_angle(np.tile(axis, (samples, 1)), phi * p))
    omega = (phi * dp / duration)[:, None] * axis
    worst = margins(q, problem.sensor_axis, problem.cones).min() if problem.cones else np.inf
    status, message = STATUS_OPTIMAL, f"eigenaxis slew of {np.degrees(phi):.2f} deg about body {np.round(axis, 4).tolist()}"
    if worst < 0:
        status = STATUS_FAILED
        message += f"; the path enters a keep-out cone by {np.degrees(-worst):.2f} deg"
    return ManeuverPlan(METHOD, t, torque, q, omega, "linear", status, message, time.perf_counter() - start,
                        {"angle": float(phi), "axis": axis.tolist()})
