"""Plan tracking law of the controller (no ROS, pure): the plan's feedforward plus the PD law.

Reference at time t from the plan samples (:func:`plan_reference`): rate and torque by the plan's
interpolation; attitude by cubic Hermite interpolation of the rotation vector φ from knot k,
``q_RN = q_k ⊗ exp(φ)``, matching both knots' attitudes and rates (φ̇ = J_r⁻¹(φ) ω; Barfoot,
*State Estimation for Robotics*, 2017, §7.1.5). A constant-torque arc about a fixed axis (φ
quadratic in t) is reproduced exactly, so a bang-bang plan of three knots is tracked as flown;
a slerp between such knots would run ahead of the spacecraft by up to 10° (135° slew, 336 s).
A plan's rates and torques are those of the body as planned: the reference frame R's, in R's axes.
Body torque demand (:mod:`.pd`)::

    τ_B = [BR] τ_R − K_p 2 sign(q_BR,w) q_BR,v − K_d (ω_BN_B − [BR] ω_RN_R)      q_BR = q_RN* ⊗ q_BN

The rate error is the body's rate relative to R (Schaub & Junkins, *Analytical Mechanics of Space
Systems*, §8.3); the plan's torque is rotated into body axes like its rate. Its realisation by the
reaction wheels is :func:`att_planner.control.wheels.wheel_torques`.
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import Interpolation, Plan
from att_planner.control import pd
from att_planner.guidance import Reference
from att_sim.models import rotations as rot


def rotation_vector_rate(phi, omega_RN_R) -> np.ndarray:
    """dφ/dt of the rotation ``exp(φ)`` of a frame R turning at ``omega_RN_R`` (its own axes):
    ``J_r⁻¹(φ) ω`` = ω + ½ φ × ω + (1/θ²)(1 − (θ/2) cot(θ/2)) φ × (φ × ω), θ = |φ| (< 2π)."""
    phi, omega = np.asarray(phi, float), np.asarray(omega_RN_R, float)
    theta = math.sqrt(phi @ phi)
    c = (1.0 - 0.5 * theta / math.tan(0.5 * theta)) / theta**2 if theta > 1e-4 else 1.0 / 12.0 + theta**2 / 720.0
    turn = rot.cross(phi, omega)
    return omega + 0.5 * turn + c * rot.cross(phi, turn)


def plan_reference(plan: Plan, t: float, hold: float = 0.0) -> Reference:
    """The reference of ``plan`` at ``t`` s from its start (clamped to the plan; after the end:
    final attitude, zero rate and torque); the attitude is the Hermite interpolant of the module
    docstring. ``torque_R`` is the plan's torque at ``t`` (per wheel for a plan of wheel torques),
    or with ``hold`` > 0 its mean over ``[t, t + hold]`` (:func:`mean_torque`): a command held for a
    control step puts that impulse on the body, where the torque sampled at ``t`` would leave the
    body half a step's change of torque behind the plan at every step (zero-order-hold compensation)."""
    t_knots, q, omega, torque = plan.t, plan.q, plan.omega, plan.torque
    if t >= t_knots[-1]:
        return Reference(q[-1], np.zeros(3), np.zeros(3), np.zeros(3))
    if hold > 0.0:
        ref = plan_reference(plan, t)
        return Reference(ref.q_RN, ref.omega_RN_R, ref.omega_dot_RN_R, mean_torque(plan, t, t + hold))
    t = max(t, t_knots[0])
    k = min(max(int(np.searchsorted(t_knots, t, side="right")) - 1, 0), len(t_knots) - 2)
    s = (t - t_knots[k]) / (t_knots[k + 1] - t_knots[k])
    h = t_knots[k + 1] - t_knots[k]
    axis, angle = rot.to_axis_angle(rot.multiply(rot.conjugate(q[k]), q[k + 1]))
    phi1 = axis * angle
    phi = ((s**3 - 2 * s**2 + s) * h * omega[k] + (3 * s**2 - 2 * s**3) * phi1
           + (s**3 - s**2) * h * rotation_vector_rate(phi1, omega[k + 1]))
    q_RN = rot.multiply(q[k], rot.exp_map(phi))
    omega_RN_R = (1 - s) * omega[k] + s * omega[k + 1]
    tau = torque[k] if plan.interpolation == Interpolation.ZOH else (1 - s) * torque[k] + s * torque[k + 1]
    return Reference(q_RN, omega_RN_R, (omega[k + 1] - omega[k]) / h, tau)


def mean_torque(plan: Plan, t0: float, t1: float) -> np.ndarray:
    """The mean over ``[t0, t1]`` s from the plan's start (``t1 > t0``) of its torque: its samples
    by its interpolation (held or linear between knots), zero outside the plan."""
    t_knots, torque = plan.t, np.asarray(plan.torque, float)
    a, b = max(t0, t_knots[0]), min(t1, t_knots[-1])
    if not b > a:
        return np.zeros(torque.shape[1])
    ts = np.concatenate(([a], t_knots[(t_knots > a) & (t_knots < b)], [b]))
    if plan.interpolation == Interpolation.ZOH:
        k = np.clip(np.searchsorted(t_knots, ts[:-1], side="right") - 1, 0, len(t_knots) - 1)
        area = (torque[k] * np.diff(ts)[:, None]).sum(axis=0)
    else:
        values = np.stack([np.interp(ts, t_knots, column) for column in torque.T], axis=1)
        area = (0.5 * (values[1:] + values[:-1]) * np.diff(ts)[:, None]).sum(axis=0)
    return area / (t1 - t0)


class ReferenceMemo:
    """:func:`plan_reference` remembering its latest answer: controllers flying one plan object
    from one start (Monte Carlo runs of one task) share one and compute each instant's reference once."""

    def __init__(self):
        self.plan, self.t, self.hold, self.reference = None, math.nan, math.nan, None

    def __call__(self, plan: Plan, t: float, hold: float = 0.0) -> Reference:
        if plan is not self.plan or t != self.t or hold != self.hold:
            self.plan, self.t, self.hold, self.reference = plan, t, hold, plan_reference(plan, t, hold)
        return self.reference


def tracking_torque(q_BN, omega_BN_B, ref: Reference, kp: float, kd: float, feedforward: bool = True) -> np.ndarray:
    """``τ_B`` of the module docstring (N m, body axes; single vectors or rows of runs, each row's
    own reference); ``feedforward=False``: the PD feedback alone (a plan of wheel torques, whose
    torques go to the wheels directly)."""
    q_BR = pd.relative_attitude(q_BN, ref.q_RN)
    omega_BR_B = np.asarray(omega_BN_B, float) - pd.to_body(q_BR, ref.omega_RN_R)
    feedback = pd.pd_torque(q_BR, omega_BR_B, kp, kd)
    return pd.to_body(q_BR, ref.torque_R) + feedback if feedforward else feedback
