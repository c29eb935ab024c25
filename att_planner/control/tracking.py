"""Plan tracking law of the controller (no ROS): feedforward plan torque + quaternion PD feedback.

Reference at time t from the plan samples (:func:`plan_reference`): rate and torque by the plan's
interpolation; attitude by cubic Hermite interpolation of the rotation vector φ from knot k,
``q_ref = q_k ⊗ exp(φ)``, matching both knots' attitudes and rates (φ̇ = J_r⁻¹(φ) ω; Barfoot,
*State Estimation for Robotics*, 2017, §7.1.5). A constant-torque arc about a fixed axis (φ
quadratic in t) is reproduced exactly, so a bang-bang plan of three knots is tracked as flown;
a slerp between such knots would run ahead of the spacecraft by up to 10° (135° slew, 336 s).
Body torque demand::

    τ = τ_ff(t) − K_p · 2 sign(e_w) e_v − K_d (ω − ω_ref)      with e = q_ref* ⊗ q

(a quaternion PD in body axes; Wie, *Space Vehicle Dynamics and Control*, §7.3). The demand is
realised by reaction wheels: the body receives ``−G u − ω × G h_w`` so
``u = −G⁺ (τ + ω × G I_w Ω)`` (pseudo-inverse for any number of wheels), scaled down as a whole
to the limit when a wheel would exceed it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import Interpolation, Plan
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft


@dataclass
class Reference:
    q: np.ndarray
    omega: np.ndarray
    torque: np.ndarray


def rotation_vector_rate(phi, omega) -> np.ndarray:
    """dφ/dt of the rotation ``exp(φ)`` turning at body rate ``omega``: ``J_r⁻¹(φ) ω`` =
    ω + ½ φ × ω + (1/θ²)(1 − (θ/2) cot(θ/2)) φ × (φ × ω), θ = |φ| (< 2π)."""
    phi, omega = np.asarray(phi, float), np.asarray(omega, float)
    theta = math.sqrt(phi @ phi)
    c = (1.0 - 0.5 * theta / math.tan(0.5 * theta)) / theta**2 if theta > 1e-4 else 1.0 / 12.0 + theta**2 / 720.0
    turn = rot.cross(phi, omega)
    return omega + 0.5 * turn + c * rot.cross(phi, turn)


def plan_reference(plan: Plan, t: float) -> Reference:
    """The reference of ``plan`` at ``t`` s from its start (clamped to the plan; after the end:
    final attitude, zero rate and torque); the attitude is the Hermite interpolant of the module
    docstring."""
    t_knots, q, omega, torque = plan.t, plan.q, plan.omega, plan.torque
    if t >= t_knots[-1]:
        return Reference(q[-1], np.zeros(3), np.zeros(3))
    t = max(t, t_knots[0])
    k = min(max(int(np.searchsorted(t_knots, t, side="right")) - 1, 0), len(t_knots) - 2)
    s = (t - t_knots[k]) / (t_knots[k + 1] - t_knots[k])
    h = t_knots[k + 1] - t_knots[k]
    axis, angle = rot.to_axis_angle(rot.multiply(rot.conjugate(q[k]), q[k + 1]))
    phi1 = axis * angle
    phi = ((s**3 - 2 * s**2 + s) * h * omega[k] + (3 * s**2 - 2 * s**3) * phi1
           + (s**3 - s**2) * h * rotation_vector_rate(phi1, omega[k + 1]))
    q_ref = rot.multiply(q[k], rot.exp_map(phi))
    w_ref = (1 - s) * omega[k] + s * omega[k + 1]
    tau = torque[k] if plan.interpolation == Interpolation.ZOH else (1 - s) * torque[k] + s * torque[k + 1]
    return Reference(q_ref, w_ref, tau)


class ReferenceMemo:
    """:func:`plan_reference` remembering its latest answer: controllers flying one plan object
    from one start (lockstep Monte Carlo runs) share one and compute each instant's reference once."""

    def __init__(self):
        self.plan, self.t, self.reference = None, math.nan, None

    def __call__(self, plan: Plan, t: float) -> Reference:
        if plan is not self.plan or t != self.t:
            self.plan, self.t, self.reference = plan, t, plan_reference(plan, t)
        return self.reference


def tracking_torque(q, omega, ref: Reference, kp: float, kd: float) -> np.ndarray:
    """The PD demand of the module docstring (rows of attitudes, rates and references: each row's)."""
    e = rot.error_vector(q, ref.q)     # sign chosen so that e_w >= 0 (shortest way back)
    return ref.torque - kp * 2.0 * e - kd * (np.asarray(omega) - ref.omega)


def wheel_torques(sc: Spacecraft, body_torque, omega, wheel_speed, extra=None) -> np.ndarray:
    """Motor torques u that put ``body_torque`` on the body (gyroscopic wheel term compensated),
    distributed by the pseudo-inverse (least norm, any number of wheels) and, when a wheel would
    exceed its limit, scaled down as a whole (the torque keeps its direction, rather than being
    bent by clipping one wheel); ``extra`` (N m per wheel: the drive friction expected at the
    measured speeds, null-space torques) is added after, and clipped."""
    h_w = sc.wheel_axes @ (sc.wheel_inertia * np.asarray(wheel_speed, float))
    demand = np.asarray(body_torque, float) + rot.cross(omega, h_w)
    u = -sc.wheel_axes_pinv @ demand
    peak = float(np.abs(u).max()) if u.size else 0.0
    if peak > sc.wheel_torque_max:
        u = u * (sc.wheel_torque_max / peak)
    if extra is not None:
        u = u + extra
    return np.minimum(np.maximum(u, -sc.wheel_torque_max), sc.wheel_torque_max)


def matvec_rows(A: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``A @ v`` of each row ``v`` (stacked: each row gets the bits of ``A @ v`` alone)."""
    return np.matmul(A, rows[:, :, None])[:, :, 0]


def wheel_torques_of_runs(sc: Spacecraft, body_torque, omega, wheel_speed, extra) -> np.ndarray:
    """:func:`wheel_torques` of each row (runs × 3 torques and rates, runs × wheels speeds and
    extras), row by row the same operations: each row gets the bits it gets alone."""
    h_w = matvec_rows(sc.wheel_axes, sc.wheel_inertia * wheel_speed)
    u = matvec_rows(-sc.wheel_axes_pinv, body_torque + rot.cross(omega, h_w))
    peak = np.abs(u).max(axis=1)
    for i in np.flatnonzero(peak > sc.wheel_torque_max).tolist():
        u[i] = u[i] * (sc.wheel_torque_max / peak[i])
    return np.minimum(np.maximum(u + extra, -sc.wheel_torque_max), sc.wheel_torque_max)
