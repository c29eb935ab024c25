"""A body torque demand realised by the reaction wheels (no ROS, pure, on rows of runs).

The body receives ``−G u − ω_BN_B × G h_w`` from motor torques ``u`` (``G`` the mounting matrix,
``h_w = I_w Ω`` the wheels' momentum about their axes), so ``u = −G⁺ (τ_B + ω_BN_B × G I_w Ω)``
(pseudo-inverse: least norm, any number of wheels), scaled down as a whole to the limit when a
wheel would exceed it. Every function takes rows of runs (leading axis n; one controller passes
one row) and computes each row by the operations it gets alone.

With some wheels failed (a ``healthy`` mask), the demand is allocated on the healthy ones only:
``G⁺`` is replaced by :func:`healthy_allocation`, the pseudo-inverse of the healthy columns ``G_h``
placed in their rows (the failed wheels' rows zero), the null space is that of ``G_h``, and a failed
wheel is commanded no torque. The gyroscopic term keeps every wheel's measured momentum: a wheel
switched off still spins.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from att_planner.control import momentum
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft


def matvec_rows(A: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``A @ v`` of each row ``v`` (a stack of products: each row gets the bits of ``A @ v`` alone)."""
    return np.matmul(A, rows[:, :, None])[:, :, 0]


def healthy_allocation(wheel_axes: np.ndarray, healthy) -> np.ndarray:
    """The allocation (N × 3) of a body vector on the ``healthy`` wheels (a mask of N): the
    pseudo-inverse of the healthy columns of ``wheel_axes`` (3 × N) in their rows, zero rows for the
    others (least norm on the healthy set; exact when the healthy axes span the body)."""
    G = np.asarray(wheel_axes, float)
    mask = np.asarray(healthy, bool)
    A = np.zeros((G.shape[1], 3))
    if mask.any():
        A[mask] = np.linalg.pinv(G[:, mask])
    return A


def healthy_spacecraft(sc: Spacecraft, healthy) -> Spacecraft:
    """``sc`` with the axes of the wheels not ``healthy`` zeroed: its ``wheel_axes_pinv`` is
    :func:`healthy_allocation` and its null space that of the healthy wheels (plus the failed ones'
    own axes, which command only them)."""
    mask = np.asarray(healthy, bool)
    return replace(sc, wheel_axes=sc.wheel_axes * mask[None, :])


def wheel_torques(sc: Spacecraft, torque_B, omega_BN_B, wheel_speeds, extra=None, healthy=None) -> np.ndarray:
    """Motor torques u (runs × wheels, N m) that put ``torque_B`` (runs × 3) on the body at rates
    ``omega_BN_B`` (runs × 3) with inertial wheel spin rates ``wheel_speeds`` (runs × wheels), the
    gyroscopic wheel term compensated, scaled down as a whole (the torque keeps its direction rather
    than being bent by clipping one wheel); ``extra`` (runs × wheels: the drive friction expected at
    the measured speeds, null-space torques) is added after, and clipped. ``healthy`` (a mask of the
    wheels; None: all): the demand allocated on the healthy wheels only, the others commanded zero."""
    omega_BN_B = np.asarray(omega_BN_B, float)
    h_w = matvec_rows(sc.wheel_axes, sc.wheel_inertia * np.asarray(wheel_speeds, float))
    allocation = sc.wheel_axes_pinv if healthy is None else healthy_allocation(sc.wheel_axes, healthy)
    u = matvec_rows(-allocation, np.asarray(torque_B, float) + rot.cross(omega_BN_B, h_w))
    peak = np.abs(u).max(axis=1, initial=0.0)
    over = peak > sc.wheel_torque_max
    if over.any():
        u = u * np.where(over, sc.wheel_torque_max / np.where(over, peak, 1.0), 1.0)[:, None]
    if extra is not None:
        u = u + extra
    u = np.minimum(np.maximum(u, -sc.wheel_torque_max), sc.wheel_torque_max)
    return u if healthy is None else u * np.asarray(healthy, bool)


def wheel_command(sc: Spacecraft, torque_B, omega_BN_B, wheel_speeds, null_space_speed: float,
                  null_space_gain: float, friction=None, gyroscopic_speeds=None, healthy=None) -> np.ndarray:
    """:func:`wheel_torques` of ``torque_B`` with, as ``extra``, the null-space control of the wheel
    speeds (more than three wheels: :func:`~.momentum.null_space_torques`) and the drive friction
    ``friction(ν)`` expected at the relative speeds ``ν = Ω − Gᵀ ω_BN_B`` (None: not compensated).
    ``gyroscopic_speeds``: the spin rates the gyroscopic term uses (default ``wheel_speeds``);
    ``healthy``: the wheels the demand and the null-space control use (None: all)."""
    omega_BN_B, wheel_speeds = np.asarray(omega_BN_B, float), np.asarray(wheel_speeds, float)
    null = sc if healthy is None else healthy_spacecraft(sc, healthy)
    extra = momentum.null_space_torques(null, wheel_speeds, null_space_speed, null_space_gain)
    if friction is not None:
        extra = extra + friction(wheel_speeds - matvec_rows(sc.wheel_axes.T, omega_BN_B))
    speeds = wheel_speeds if gyroscopic_speeds is None else gyroscopic_speeds
    return wheel_torques(sc, torque_B, omega_BN_B, speeds, extra, healthy)
