"""A body torque demand realised by the reaction wheels (no ROS, pure, on rows of runs).

The body receives ``−G u − ω_BN_B × G h_w`` from motor torques ``u`` (``G`` the mounting matrix,
``h_w = I_w Ω`` the wheels' momentum about their axes), so ``u = −G⁺ (τ_B + ω_BN_B × G I_w Ω)``
(pseudo-inverse: least norm, any number of wheels), scaled down as a whole to the limit when a
wheel would exceed it. Every function takes rows of runs (leading axis n; one controller passes
one row) and computes each row by the operations it gets alone.
"""
from __future__ import annotations

import numpy as np

from att_planner.control import momentum
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft


def matvec_rows(A: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``A @ v`` of each row ``v`` (a stack of products: each row gets the bits of ``A @ v`` alone)."""
    return np.matmul(A, rows[:, :, None])[:, :, 0]


def wheel_torques(sc: Spacecraft, torque_B, omega_BN_B, wheel_speeds, extra=None) -> np.ndarray:
    """Motor torques u (runs × wheels, N m) that put ``torque_B`` (runs × 3) on the body at rates
    ``omega_BN_B`` (runs × 3) with inertial wheel spin rates ``wheel_speeds`` (runs × wheels), the
    gyroscopic wheel term compensated, scaled down as a whole (the torque keeps its direction rather
    than being bent by clipping one wheel); ``extra`` (runs × wheels: the drive friction expected at
    the measured speeds, null-space torques) is added after, and clipped."""
    omega_BN_B = np.asarray(omega_BN_B, float)
    h_w = matvec_rows(sc.wheel_axes, sc.wheel_inertia * np.asarray(wheel_speeds, float))
    u = matvec_rows(-sc.wheel_axes_pinv, np.asarray(torque_B, float) + rot.cross(omega_BN_B, h_w))
    peak = np.abs(u).max(axis=1, initial=0.0)
    over = peak > sc.wheel_torque_max
    if over.any():
        u = u * np.where(over, sc.wheel_torque_max / np.where(over, peak, 1.0), 1.0)[:, None]
    if extra is not None:
        u = u + extra
    return np.minimum(np.maximum(u, -sc.wheel_torque_max), sc.wheel_torque_max)


def wheel_command(sc: Spacecraft, torque_B, omega_BN_B, wheel_speeds, null_space_speed: float,
                  null_space_gain: float, friction=None, gyroscopic_speeds=None) -> np.ndarray:
    """:func:`wheel_torques` of ``torque_B`` with, as ``extra``, the null-space control of the wheel
    speeds (more than three wheels: :func:`~.momentum.null_space_torques`) and the drive friction
    ``friction(ν)`` expected at the relative speeds ``ν = Ω − Gᵀ ω_BN_B`` (None: not compensated).
    ``gyroscopic_speeds``: the spin rates the gyroscopic term uses (default ``wheel_speeds``)."""
    omega_BN_B, wheel_speeds = np.asarray(omega_BN_B, float), np.asarray(wheel_speeds, float)
    extra = momentum.null_space_torques(sc, wheel_speeds, null_space_speed, null_space_gain)
    if friction is not None:
        extra = extra + friction(wheel_speeds - matvec_rows(sc.wheel_axes.T, omega_BN_B))
    speeds = wheel_speeds if gyroscopic_speeds is None else gyroscopic_speeds
    return wheel_torques(sc, torque_B, omega_BN_B, speeds, extra)
