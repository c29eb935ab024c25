"""Eigenaxis slews: the smooth quintic slew (always available, the planner's safe fallback) and
the bang-bang λ-rotation about the eigenaxis. Both ignore the cones and zones (they do not steer
round them, moving or not); the smooth slew reports a path that enters one (every zone at its true
position at each sample's time, judged like the verification: :func:`att_planner.verification.clearances`),
the bang-bang plan is verified (:mod:`.axis_rotations`), which checks every zone the same way.

Smooth: rotation by φ about the fixed body axis e of ``q_i* ⊗ q_f`` with the quintic (minimum-jerk)
angle profile θ(t) = φ p(t/T), p(s) = 10s³ − 15s⁴ + 6s⁵: the rate is C¹, zero with zero
acceleration at both ends, so the torque starts and ends at zero and is continuous. Body torque
(ω = θ̇ e)::

    τ(t) = J e θ̈ + θ̇² e × J e = (φ/T²) [J e p''(s) + φ p'(s)² e × J e]

The duration T is the smallest that keeps every axis within T̄:
``T² = φ max_{s,j} |(J e p'' + φ p'² e × J e)_j| / T̄``, or longer when the problem bounds the body
rate (``φ p'_max |e_j| / T ≤ ω̄``, p'_max = 15/8) or the wheel momentum (``φ p'_max |(G⁺ J e)_i| / T ≤ h̄``).
"""
from __future__ import annotations

import time

import numpy as np

from att_msgs_py.types import Interpolation, Plan, Status
from att_planner.methods.axis_rotations import eigenaxis_leg, goal_attitude, legs_plan, no_torque_limit
from att_planner.problem import ManeuverProblem
from att_planner.verification import clearances
from att_sim.models import rotations as rot

METHOD = "eigenaxis_smooth"


def _profile(s):
    return 10 * s**3 - 15 * s**4 + 6 * s**5, 30 * s**2 - 60 * s**3 + 30 * s**4, 60 * s - 180 * s**2 + 120 * s**3


BOUND_MARGIN = 1e-3     # relative room kept below the problem's rate and momentum bounds


def _rate_limited_duration(problem: ManeuverProblem, axis: np.ndarray, peak_angle_rate: float) -> float:
    """Shortest duration whose peak rate ``peak_angle_rate / T`` about body ``axis`` keeps the
    problem's per-axis body-rate bound and the wheels' momentum bound (0 when there are none)."""
    duration = 0.0
    if np.isfinite(problem.rate_max):
        duration = peak_angle_rate * np.abs(axis).max() / (problem.rate_max * (1 - BOUND_MARGIN))
    sc = problem.spacecraft
    if np.isfinite(problem.wheel_momentum_max) and sc.n_wheels:
        per_rate = np.abs(sc.wheel_axes_pinv @ sc.inertia @ axis).max()
        duration = max(duration, peak_angle_rate * per_rate / (problem.wheel_momentum_max * (1 - BOUND_MARGIN)))
    return duration


def plan_eigenaxis_smooth(problem: ManeuverProblem, samples: int = 401) -> Plan:
    """Eigenaxis slew with the quintic profile, sampled at ``samples`` knots (linear interpolation);
    slowed down when the problem bounds the body rate or the wheel momentum."""
    start = time.perf_counter()
    J, tmax = problem.spacecraft.inertia, problem.spacecraft.body_torque_max
    axis, phi = rot.to_axis_angle(rot.multiply(rot.conjugate(problem.q_initial), problem.q_final))
    s = np.linspace(0.0, 1.0, samples)
    p, dp, ddp = _profile(s)
    if phi < 1e-12:
        return Plan(t=np.linspace(0.0, 1.0, samples), torque=np.zeros((samples, 3)),
                    q=np.tile(problem.q_initial, (samples, 1)), omega=np.zeros((samples, 3)),
                    interpolation=Interpolation.LINEAR, method=METHOD, status=Status.OPTIMAL,
                    message="already at the goal attitude", wall_time=time.perf_counter() - start)
    shape = J @ axis * ddp[:, None] + phi * dp[:, None] ** 2 * np.cross(axis, J @ axis)
    duration = max(np.sqrt(phi * np.abs(shape).max() / tmax), _rate_limited_duration(problem, axis, phi * dp.max()))
    q = rot.multiply(problem.q_initial, rot.from_axis_angle(np.tile(axis, (samples, 1)), phi * p))
    zones = problem.zone_sky()
    m = clearances(problem, s * duration, q)
    status = Status.OPTIMAL
    message = f"eigenaxis slew of {np.degrees(phi):.2f} deg about body {np.round(axis, 4).tolist()}"
    if m.size and m.min() < 0:
        status = Status.FAILED
        z = int(np.argmin(m.min(axis=0)))
        kind = "leaves keep-in" if zones.keep_in[z] else "enters keep-out"
        what = "cone" if z < len(problem.cones) else "zone"
        message += f"; the path {kind} {what} {zones.names[z]} by {np.degrees(-m.min()):.2f} deg"
    return Plan(t=s * duration, torque=phi / duration**2 * shape, q=q, omega=(phi * dp / duration)[:, None] * axis,
                interpolation=Interpolation.LINEAR, method=METHOD, status=status, message=message,
                wall_time=time.perf_counter() - start, stats={"angle": float(phi), "axis": axis.tolist()})


def plan_eigenaxis(problem: ManeuverProblem) -> Plan:
    """Rest-to-rest bang-bang λ-rotation about the eigenaxis (zones are only checked, not avoided)."""
    start = time.monotonic()
    why = no_torque_limit(problem)
    if why:
        return Plan(method="eigenaxis", status=Status.FAILED, message=why)
    return legs_plan(problem, "eigenaxis", [eigenaxis_leg(problem.q_initial, goal_attitude(problem))], start, "")
