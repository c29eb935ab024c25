"""The envelope the healthy wheels leave the planner (no ROS, pure): the torque and momentum box.

The controller allocates a body vector ``v`` on the healthy wheels by ``A = G_h⁺``
(:func:`att_planner.control.wheels.healthy_allocation`), so wheel ``i`` carries ``A_i v``. The box
``|v_k| ≤ V`` (every axis at once, as the planner's per-axis bound ``T̄`` means) stays within a
wheel's limit ``L`` when ``V ‖A_i‖₁ ≤ L`` for every wheel (the worst corner ``v = V sign(A_i)``):
``V = L / max_i ‖A_i‖₁``. One axis alone reaches ``L / max_i |A_ik|``. With the motor torque limit
this is the torque box, with the momentum a wheel stores at its speed limit ``I_w Ω_max`` the
momentum box. Healthy wheels that do not span the body leave no box (zero): the attitude cannot be
controlled on the wheels.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from att_planner.control.wheels import healthy_allocation
from att_sim.models.dynamics import Spacecraft


@dataclass(frozen=True)
class Envelope:
    """What the healthy wheels can do, per body axis and as a box."""

    healthy: tuple[bool, ...]
    controllable: bool               # the healthy axes span the body
    torque_box_Nm: float             # every axis at once
    torque_axis_Nm: np.ndarray       # (3,) one axis alone
    momentum_box_Nms: float
    momentum_axis_Nms: np.ndarray    # (3,)


def envelope(sc: Spacecraft, healthy) -> Envelope:
    """The torque and momentum box of the ``healthy`` wheels of ``sc`` (module docstring)."""
    mask = np.asarray(healthy, bool)
    A = healthy_allocation(sc.wheel_axes, mask)
    controllable = bool(mask.any()) and np.linalg.matrix_rank(sc.wheel_axes[:, mask]) == 3
    if not controllable:
        zero = np.zeros(3)
        return Envelope(tuple(mask.tolist()), False, 0.0, zero, 0.0, zero)
    row_l1, column_max = np.abs(A).sum(axis=1).max(), np.abs(A).max(axis=0)
    h_max = sc.wheel_inertia * sc.wheel_speed_max
    return Envelope(tuple(mask.tolist()), True, sc.wheel_torque_max / row_l1, sc.wheel_torque_max / column_max,
                    h_max / row_l1, h_max / column_max)


def planning_spacecraft(sc: Spacecraft, healthy) -> Spacecraft:
    """The spacecraft the planner plans for on the ``healthy`` wheels: only their axes, and the
    per-axis torque bound no larger than their torque box (ValueError when they cannot control
    the attitude)."""
    env = envelope(sc, healthy)
    if not env.controllable:
        raise ValueError(f"healthy wheels {list(env.healthy)} that span the body (three independent axes)")
    mask = np.asarray(healthy, bool)
    return replace(sc, wheel_axes=sc.wheel_axes[:, mask], body_torque_max=min(sc.body_torque_max, env.torque_box_Nm))
