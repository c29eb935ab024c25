"""Tracking a guidance reference (issue 15, no ROS): feedforward plus quaternion PD feedback.

With the body's attitude error from the reference ``q_e = q_R* ⊗ q`` and ``C = R(q_e)ᵀ`` (reference
axes to body axes), the reference rate and acceleration in body axes are ``ω_r = C ω_R`` and
``ω̇_r = C ω̇_R``, and the body torque demanded is (Schaub & Junkins, *Analytical Mechanics of Space
Systems*, §8.3; Basilisk ``mrpFeedback``)::

    τ = J (ω̇_r − ω × ω_r) + ω × J ω − K_p 2 sign(e_w) e_v − K_d (ω − ω_r)

The wheels' own gyroscopic term ``ω × G I_w Ω`` is compensated where the demand becomes wheel
torques (:func:`att_planner.control.tracking.wheel_torques`). A constant-rate reference (nadir on a
circular orbit) is then held with no steady error: the feedforward carries the whole torque.
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import Plan
from att_planner.guidance import Reference
from att_planner.guidance import reference as guidance_reference
from att_planner.guidance.laws import BlendedLaw
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

HANDOVER_RATE_MATCH = 1e-4     # rad/s: a plan ending this close to the law's rate hands over directly
HANDOVER_ATTITUDE_MATCH = 1e-3  # rad: ... and this close to its attitude (else: through the blend)


def body_reference(q, ref: Reference) -> tuple[np.ndarray, np.ndarray]:
    """The reference rate and acceleration in body axes at attitude ``q``."""
    C = rot.dcm_BN(rot.multiply(rot.conjugate(ref.q_RN), q))
    return C @ ref.omega_RN_R, C @ ref.omega_dot_RN_R


def pointing_torque(sc: Spacecraft, q, omega, ref: Reference, kp: float, kd: float) -> np.ndarray:
    """Body torque (N m) that tracks ``ref`` from attitude ``q`` and rate ``omega`` (module docstring)."""
    omega = np.asarray(omega, float)
    w_r, w_r_dot = body_reference(q, ref)
    J = sc.inertia
    feedforward = J @ (w_r_dot - rot.cross(omega, w_r)) + rot.cross(omega, J @ omega)
    return feedforward - kp * 2.0 * rot.error_vector(q, ref.q_RN) - kd * (omega - w_r)


def handover_law(law, plan: Plan, t: float, blend: float):
    """The pointing law a plan hands over to at its end (at ``t``): the law itself when the plan ends
    on the law's attitude at its rate (a slew planned to end on the moving target, flown when
    planned), else the law entered through :class:`~att_planner.guidance.laws.BlendedLaw` over
    ``blend`` s (a plan ending at rest)."""
    ref = guidance_reference(law.attitude, t)
    matched = (float(np.linalg.norm(plan.omega[-1] - ref.omega_RN_R)) <= HANDOVER_RATE_MATCH
               and rot.angle_between(plan.q[-1], ref.q_RN) <= HANDOVER_ATTITUDE_MATCH)
    return law if matched or blend <= 0 else BlendedLaw(law, t, blend)
