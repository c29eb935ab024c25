"""The quaternion PD law every attitude law of the controller is built on (no ROS, pure).

With the body B at ``q_BN`` and the reference R at ``q_RN`` (both [x, y, z, w], to N), the attitude
error is ``q_BR = q_RN* ⊗ q_BN`` and the rate error ``ω_BR_B = ω_BN_B − [BR] ω_RN_R``: the reference
rate, given in R's axes, rotated into B's (Schaub & Junkins, *Analytical Mechanics of Space
Systems*, §8.3). The feedback torque on the body, in B's axes, is::

    τ_fb = −K_p 2 sign(q_BR,w) q_BR,v − K_d ω_BR_B

(Wie, *Space Vehicle Dynamics and Control*, §7.3): the sign takes the shortest way back. The
tracking, pointing and safe-mode laws add their feedforward to it. Every function takes single
vectors or rows of runs (leading axes), the same operations either way.
"""
from __future__ import annotations

import numpy as np

from att_sim.models import rotations as rot


def relative_attitude(q_BN, q_RN) -> np.ndarray:
    """``q_BR = q_RN* ⊗ q_BN``: the body's attitude relative to the reference."""
    return rot.multiply(rot.conjugate(np.asarray(q_RN, float)), np.asarray(q_BN, float))


def to_body(q_BR, v_R) -> np.ndarray:
    """``[BR] v_R``: a vector given in R's axes, in B's axes (``q_BR`` from :func:`relative_attitude`)."""
    return rot.to_body(q_BR, v_R)


def attitude_feedback(q_BR, kp) -> np.ndarray:
    """``−K_p 2 sign(q_BR,w) q_BR,v`` (N m, B axes)."""
    q_BR = np.asarray(q_BR, float)
    sign = np.where(q_BR[..., 3:] < 0.0, -1.0, 1.0)
    return -kp * 2.0 * (q_BR[..., :3] * sign)


def rate_feedback(omega_BR_B, kd) -> np.ndarray:
    """``−K_d ω_BR_B`` (N m, B axes)."""
    return -kd * np.asarray(omega_BR_B, float)


def pd_torque(q_BR, omega_BR_B, kp, kd) -> np.ndarray:
    """``τ_fb`` of the module docstring from the attitude error ``q_BR`` and rate error ``ω_BR_B``."""
    return attitude_feedback(q_BR, kp) + rate_feedback(omega_BR_B, kd)
