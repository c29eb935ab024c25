"""Wheel momentum management (no ROS, pure): magnetorquer desaturation and null-space control.

* **Desaturation** (the cross-product law; Camillo & Markley 1980, Basilisk ``mtbMomentumManagement``):
  with ``Δh = h_w − h_target`` the wheels' momentum above its target (body axes, ``h_w = G I_w Ω``),
  ``m = k (Δh × B)/|B|²`` gives the magnetic torque ``m × B = −k Δh⊥`` (the part of ``Δh`` across the
  field), which the attitude loop then takes out of the wheels. The dipole is scaled down as a
  whole to the coils' limit (its direction kept). The controller feeds the magnetic torque forward to
  the wheels, so the attitude does not feel it.
* **Null-space control** (more wheels than axes): ``u_n = −k_n I_w N Nᵀ (Ω − Ω_b)``, ``N`` an
  orthonormal basis of the null space of the mounting matrix ``G`` (``G N = 0``: no body torque),
  ``Ω_b = N c_b`` the bias speeds (``c_b`` = ``null_space_speed`` along each null direction): the
  wheels' speeds are steered away from zero (no zero crossings, where friction is worst) without
  touching the attitude.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft


def desaturation_dipole(h_wheels_B, h_target_B, field_B, gain: float, dipole_max: float) -> np.ndarray:
    """``m = k (Δh × B)/|B|²`` (A m², body axes) of the wheels' momentum ``h_wheels_B`` above
    ``h_target_B`` (N m s) in the field ``field_B`` (T), scaled down as a whole to ``dipole_max`` per
    coil; zero without a field."""
    b = np.asarray(field_B, float)
    b2 = float(b @ b)
    if not b2 > 0.0:
        return np.zeros(3)
    m = gain * rot.cross(np.asarray(h_wheels_B, float) - np.asarray(h_target_B, float), b) / b2
    peak = float(np.max(np.abs(m)))
    return m * (dipole_max / peak) if peak > dipole_max else m


@lru_cache(maxsize=8)
def _null_basis(axes: bytes, n: int) -> np.ndarray:
    G = np.frombuffer(axes).reshape(3, n)
    _, s, vt = np.linalg.svd(G)
    rank = int(np.sum(s > 1e-9 * s.max()))
    return vt[rank:].T                         # (n, n − rank), orthonormal columns


def null_space(sc: Spacecraft) -> np.ndarray:
    """An orthonormal basis (N, N − rank G) of the wheels' null space (empty for three wheels)."""
    return _null_basis(np.ascontiguousarray(sc.wheel_axes, float).tobytes(), sc.n_wheels)


def null_space_torques(sc: Spacecraft, wheel_speeds, bias_speed: float, gain: float) -> np.ndarray:
    """``u_n = −k_n I_w N (Nᵀ Ω − c_b)`` (N m per wheel): drives each null-space speed component to
    ``bias_speed`` and puts no torque on the body (rows of runs' speeds: each row's, to its bits alone)."""
    w = np.asarray(wheel_speeds, float)
    N = null_space(sc)
    if not N.size:
        return np.zeros(w.shape[:-1] + (sc.n_wheels,))
    if w.ndim == 2:
        return np.matmul(-gain * sc.wheel_inertia * N, np.matmul(N.T, w[:, :, None]) - bias_speed)[:, :, 0]
    return -gain * sc.wheel_inertia * N @ (N.T @ w - bias_speed)
