"""Pointing law (no ROS, pure): tracking a guidance reference with feedforward plus the PD law.

With the attitude error ``q_BR = q_RN* ⊗ q_BN``, the reference rate and acceleration in body axes
are ``ω_RN_B = [BR] ω_RN_R`` and ``ω̇_RN_B = [BR] ω̇_RN_R``, and the body torque demanded is
(Schaub & Junkins, *Analytical Mechanics of Space Systems*, §8.3; Basilisk ``mrpFeedback``)::

    τ_B = J (ω̇_RN_B − ω_BN_B × ω_RN_B) + ω_BN_B × J ω_BN_B − K_p 2 sign(q_BR,w) q_BR,v − K_d (ω_BN_B − ω_RN_B)

The wheels' own gyroscopic term ``ω × G I_w Ω`` is compensated where the demand becomes wheel
torques (:func:`att_planner.control.wheels.wheel_torques`). A constant-rate reference (nadir on a
circular orbit) is then held with no steady error: the feedforward carries the whole torque.
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import Plan
from att_planner.control import pd
from att_planner.guidance import Reference
from att_planner.guidance import reference as guidance_reference  # the function
from att_planner.guidance.laws import BlendedLaw
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

HANDOVER_RATE_MATCH = 1e-4     # rad/s: a plan ending this close to the law's rate hands over directly
HANDOVER_ATTITUDE_MATCH = 1e-3  # rad: ... and this close to its attitude (else: through the blend)


def law_reference(law, t: float) -> Reference:
    """The reference of the pointing ``law`` at ``t``: its attitude and the rate and acceleration
    the guidance differentiates from it (:func:`att_planner.guidance.reference`), in the law's axes."""
    return guidance_reference(law.attitude, t)


def _inertia_times(J: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.matmul(J, v[..., None])[..., 0]


def pointing_torque(sc: Spacecraft, q_BN, omega_BN_B, ref: Reference, kp: float, kd: float) -> np.ndarray:
    """Body torque ``τ_B`` (N m) that tracks ``ref`` from attitude ``q_BN`` and rate ``omega_BN_B``
    (module docstring; single vectors or rows of runs)."""
    omega = np.asarray(omega_BN_B, float)
    q_BR = pd.relative_attitude(q_BN, ref.q_RN)
    omega_RN_B, omega_dot_RN_B = pd.to_body(q_BR, ref.omega_RN_R), pd.to_body(q_BR, ref.omega_dot_RN_R)
    J = sc.inertia
    feedforward = _inertia_times(J, omega_dot_RN_B - rot.cross(omega, omega_RN_B)) + \
        rot.cross(omega, _inertia_times(J, omega))
    return feedforward + pd.pd_torque(q_BR, omega - omega_RN_B, kp, kd)


def handover_law(law, plan: Plan, t_end: float, t: float, blend: float):
    """The pointing law a plan ending at sim time ``t_end`` (its start plus its duration) hands over to
    at ``t`` (the control step that sees the end, up to a step later): the law itself when the plan ends
    on the law's attitude at its rate at ``t_end`` (a slew planned to end on the moving target, flown
    when planned), else the law entered through :class:`~att_planner.guidance.laws.BlendedLaw` from
    ``t`` over ``blend`` s (a plan ending at rest). The match is judged at ``t_end``, not ``t``: a site's
    line of sight turns 0.1 deg in one 0.2 s step of an agile pass, twice the attitude match."""
    ref = law_reference(law, t_end)
    matched = (float(np.linalg.norm(plan.omega[-1] - ref.omega_RN_R)) <= HANDOVER_RATE_MATCH
               and rot.angle_between(plan.q[-1], ref.q_RN) <= HANDOVER_ATTITUDE_MATCH)
    return law if matched or blend <= 0 else BlendedLaw(law, t, blend)
