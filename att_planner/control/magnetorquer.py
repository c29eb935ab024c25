"""PD-like magnetorquer law of Bruni & Celani (no ROS, pure), vectorised.

    m = −m* sat((1/m*) B_b × (κ_p q_v + κ_d ω))          (componentwise saturation to [−1, 1])

``q_v`` is the vector part of the attitude ``q_BN`` (``[x, y, z]`` of ``[x, y, z, w]``), ``ω`` the
body rate ``ω_BN_B`` (rad/s), ``B_b`` the field in body axes (T), ``m*`` the per-coil dipole limit
(A m²). The torque is ``m × B_b``. Without saturation the torque is ``−(I B² − B Bᵀ)(κ_p q_v + κ_d ω)``,
a PD law on the part of the error the field lets the coils act on.

Everything broadcasts: pass stacks ``(..., 3)`` (``axis=-1``) or component-first ``(3, ...)``
(``axis=0``, the batch simulator's layout), and scalar or per-case gains.
"""
from __future__ import annotations

import numpy as np

from att_sim.models.rotations import cross


def _gain(k, axis: int):
    """Per-case gains line up with the case axes, not with the vector axis."""
    k = np.asarray(k, float)
    return np.expand_dims(k, axis) if k.ndim else k


def dipole_command(q_BN, omega_BN_B, field_B, kp, kd, m_max: float, axis: int = -1) -> np.ndarray:
    """Commanded dipole (A m², body axes) of the PD-like law; ``q_BN`` the attitude or its vector part."""
    q_vec = np.asarray(q_BN, float)
    if q_vec.shape[axis] == 4:
        q_vec = np.take(q_vec, (0, 1, 2), axis)
    drive = _gain(kp, axis) * q_vec + _gain(kd, axis) * np.asarray(omega_BN_B, float)
    demand = cross(np.asarray(field_B, float), drive, axis) / m_max
    return -m_max * np.minimum(np.maximum(demand, -1.0), 1.0)


def control_torque(q_BN, omega_BN_B, field_B, kp, kd, m_max: float, axis: int = -1) -> np.ndarray:
    """Torque ``m × B_b`` (N m, body axes) of the law."""
    m = dipole_command(q_BN, omega_BN_B, field_B, kp, kd, m_max, axis)
    return cross(m, np.asarray(field_B, float), axis)
