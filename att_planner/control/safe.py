"""Safe-mode law (no ROS, pure): rate damping, then Sun pointing once the rates are low.

The safe mode first damps the body rate through the wheels with the rate part of the PD law
(:func:`att_planner.control.pd.rate_feedback` about a reference at rest: ``τ_B = −K_d ω_BN_B``).
Once the rate is below the threshold, with a Sun to see and an attitude to trust, it points a body
axis at the Sun with the orbit normal as secondary direction (:func:`sun_mode`), flown by the
pointing law (:mod:`.pointing`).
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import PointingMode
from att_planner.control import pd
from att_sim.models import rotations as rot


def damping_torque(omega_BN_B, kd: float) -> np.ndarray:
    """``τ_B = −K_d ω_BN_B`` (N m; single vectors or rows of runs)."""
    return pd.rate_feedback(omega_BN_B, kd)


def damped(omega_BN_B, threshold: float) -> bool:
    """Whether the body rate is at or below ``threshold`` rad/s (the Sun pointing may start)."""
    return float(np.linalg.norm(omega_BN_B)) <= threshold


def sun_mode(sun_axis_B) -> PointingMode:
    """The safe Sun pointing: body axis ``sun_axis_B`` on the Sun, an axis normal to it toward the
    orbit normal."""
    axis = np.asarray(sun_axis_B, float)
    return PointingMode("sun", primary_axis=axis, secondary_axis=rot.orthonormal_basis(axis)[0],
                        secondary="orbit_normal")
