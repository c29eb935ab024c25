"""Plan tracking law of the controller (no ROS): feedforward plan torque + quaternion PD feedback.

Reference at time t from the plan samples (:func:`plan_reference`: attitude by slerp, rate and
torque by the plan's interpolation). Body torque demand::

    τ = τ_ff(t) − K_p · 2 sign(e_w) e_v − K_d (ω − ω_ref)      with e = q_ref* ⊗ q

(a quaternion PD in body axes; Wie, *Space Vehicle Dynamics and Control*, §7.3). The demand is
realised by reaction wheels: the body receives ``−G u − ω × G h_w`` so
``u = −G⁺ (τ + ω × G I_w Ω)`` (pseudo-inverse for any number of wheels), clipped to the limit.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import Interpolation, Plan
from att_sim import rotations as rot
from att_sim.dynamics import Spacecraft


@dataclass
class Reference:
    q: np.ndarray
    omega: np.ndarray
    torque: np.ndarray


def plan_reference(plan: Plan, t: float) -> Reference:
    """The reference of ``plan`` at ``t`` s from its start (clamped to the plan; after the end:
    final attitude, zero rate and torque)."""
    t_knots, q, omega, torque = plan.t, plan.q, plan.omega, plan.torque
    if t >= t_knots[-1]:
        return Reference(q[-1], np.zeros(3), np.zeros(3))
    t = max(t, t_knots[0])
    k = int(np.clip(np.searchsorted(t_knots, t, side="right") - 1, 0, len(t_knots) - 2))
    s = (t - t_knots[k]) / (t_knots[k + 1] - t_knots[k])
    q_ref = rot.slerp(q[k], q[k + 1], s)
    w_ref = (1 - s) * omega[k] + s * omega[k + 1]
    tau = torque[k] if plan.interpolation == Interpolation.ZOH else (1 - s) * torque[k] + s * torque[k + 1]
    return Reference(q_ref, w_ref, tau)


def tracking_torque(q, omega, ref: Reference, kp: float, kd: float) -> np.ndarray:
    e = rot.error_vector(q, ref.q)     # sign chosen so that e_w >= 0 (shortest way back)
    return ref.torque - kp * 2.0 * e - kd * (np.asarray(omega) - ref.omega)


def wheel_torques(sc: Spacecraft, body_torque, omega, wheel_speed) -> np.ndarray:
    """Motor torques u that put ``body_torque`` on the body (gyroscopic wheel term compensated)."""
    h_w = sc.wheel_axes @ (sc.wheel_inertia * np.asarray(wheel_speed, float))
    demand = np.asarray(body_torque, float) + np.cross(omega, h_w)
    u = -sc.wheel_axes_pinv @ demand
    return np.clip(u, -sc.wheel_torque_max, sc.wheel_torque_max)
