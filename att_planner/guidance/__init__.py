"""Guidance: where the spacecraft should point at each instant, without ROS.

A pointing law (:mod:`.laws`) gives the reference attitude ``q_RN(t)`` (body-to-inertial) of a mode —
inertial hold, nadir/LVLH with a yaw, Sun pointing, a ground target (Earth rotation included) or an
inertial target, each with a primary body axis on its target and a secondary axis aligned as
closely as possible to a second direction (:func:`.laws.two_vector_attitude`). :func:`reference`
differentiates it into the rate and acceleration the controller's feedforward needs: central
differences of the rotation between ``q_RN(t − h)``, ``q_RN(t)`` and ``q_RN(t + h)``, exact for a
constant rate and second order otherwise (the laws are smooth on scales of minutes; ``h`` = 0.5 s
leaves errors below 1e-9 rad/s on a LEO nadir reference, tested). :mod:`.modes` turns a requested
:class:`att_msgs_py.types.PointingMode` into a law, checked field by field.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from att_sim.models import rotations as rot

DIFFERENCE_STEP = 0.5          # s: the step of the central differences


@dataclass(frozen=True)
class Reference:
    """The reference frame R at one instant: its attitude ``q_RN`` (body-to-inertial), its rate
    ``omega_RN_R`` relative to N and that rate's derivative ``omega_dot_RN_R``, both in R axes
    (rad/s, rad/s²)."""

    q_RN: np.ndarray
    omega_RN_R: np.ndarray
    omega_dot_RN_R: np.ndarray


def reference(attitude: Callable[[float], np.ndarray], t: float, h: float = DIFFERENCE_STEP) -> Reference:
    """``q_RN = attitude(t)`` and its rate and acceleration by central differences: the mean rates
    over [t − h, t] and [t, t + h] are the rotation vectors ``log(q_RN(t−h)* ⊗ q_RN(t))/h`` and
    ``log(q_RN(t)* ⊗ q_RN(t+h))/h`` (R axes); their mean is ω_RN_R(t) and their difference over h is
    ω̇_RN_R(t)."""
    q_before, q_now, q_after = attitude(t - h), attitude(t), attitude(t + h)
    before = rot.log_map(rot.multiply(rot.conjugate(q_before), q_now)) / h
    after = rot.log_map(rot.multiply(rot.conjugate(q_now), q_after)) / h
    return Reference(q_now, 0.5 * (before + after), (after - before) / h)
