"""Guidance (issue 15): where the spacecraft should point at each instant, without ROS.

A pointing law (:mod:`.laws`) gives the reference attitude ``q_R(t)`` (body-to-inertial) of a mode —
inertial hold, nadir/LVLH with a yaw, Sun pointing, a ground target (Earth rotation included) or an
inertial target, each with a primary body axis on its target and a secondary axis aligned as
closely as possible to a second direction (:func:`.laws.two_vector_attitude`). :func:`reference`
differentiates it into the rate and acceleration the controller's feedforward needs: central
differences of the rotation between ``q_R(t − h)``, ``q_R(t)`` and ``q_R(t + h)``, exact for a
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
    """The reference at one instant: attitude (body-to-inertial), rate and acceleration of the
    reference frame, both in its own axes (rad/s, rad/s²)."""

    q: np.ndarray
    omega: np.ndarray
    omega_dot: np.ndarray


def reference(attitude: Callable[[float], np.ndarray], t: float, h: float = DIFFERENCE_STEP) -> Reference:
    """``attitude(t)`` and its rate and acceleration by central differences: the mean rates over
    [t − h, t] and [t, t + h] are the rotation vectors ``log(q(t−h)* ⊗ q(t))/h`` and
    ``log(q(t)* ⊗ q(t+h))/h``; their mean is ω(t) and their difference over h is ω̇(t)."""
    q_before, q_now, q_after = attitude(t - h), attitude(t), attitude(t + h)
    before = rot.log_map(rot.multiply(rot.conjugate(q_before), q_now)) / h
    after = rot.log_map(rot.multiply(rot.conjugate(q_now), q_after)) / h
    return Reference(q_now, 0.5 * (before + after), (after - before) / h)
