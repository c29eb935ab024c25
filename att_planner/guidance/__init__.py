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
from dataclasses import dataclass, field

import numpy as np

from att_sim.models import rotations as rot

DIFFERENCE_STEP = 0.5          # s: the step of the central differences


def _zeros3() -> np.ndarray:
    return np.zeros(3)


@dataclass(frozen=True)
class Reference:
    """The reference every control law tracks: the reference frame R at one instant.

    Attitude ``q_RN`` ([x, y, z, w], R relative to N), rate ``omega_RN_R`` (rad/s) of R relative
    to N and its derivative ``omega_dot_RN_R`` (rad/s²), both in R's own axes, and the feedforward
    body torque ``torque_R`` (N m) a plan applies when the body is on R, in R's axes (zero for a
    pointing law). A plan's ``omega`` samples are the planned body rates, i.e. in the axes of the
    body as planned (R); a pointing law's rates come from :func:`reference`. The control laws
    rotate them into the body's axes with ``[BR]`` before comparing them with the body's rate
    (Schaub & Junkins, *Analytical Mechanics of Space Systems*, §8.3). Fields are single instants
    (``(4,)``, ``(3,)``) or rows of runs (``(n, 4)``, ``(n, 3)``).
    """

    q_RN: np.ndarray
    omega_RN_R: np.ndarray = field(default_factory=_zeros3)
    omega_dot_RN_R: np.ndarray = field(default_factory=_zeros3)
    torque_R: np.ndarray = field(default_factory=_zeros3)


def at_rest(q_RN: np.ndarray) -> Reference:
    """A reference frame fixed in N at ``q_RN`` (a held attitude), with no feedforward."""
    return Reference(np.asarray(q_RN, float))


def stack(references: list[Reference]) -> Reference:
    """The references of several runs as one of rows (field by field)."""
    return Reference(np.array([r.q_RN for r in references]), np.array([r.omega_RN_R for r in references]),
                     np.array([r.omega_dot_RN_R for r in references]), np.array([r.torque_R for r in references]))


def reference(attitude: Callable[[float], np.ndarray], t: float, h: float = DIFFERENCE_STEP) -> Reference:
    """``q_RN = attitude(t)`` and its rate and acceleration by central differences: the mean rates
    over [t − h, t] and [t, t + h] are the rotation vectors ``log(q_RN(t−h)* ⊗ q_RN(t))/h`` and
    ``log(q_RN(t)* ⊗ q_RN(t+h))/h`` (R axes); their mean is ω_RN_R(t) and their difference over h is
    ω̇_RN_R(t)."""
    q_before, q_now, q_after = attitude(t - h), attitude(t), attitude(t + h)
    before = rot.log_map(rot.multiply(rot.conjugate(q_before), q_now)) / h
    after = rot.log_map(rot.multiply(rot.conjugate(q_now), q_after)) / h
    return Reference(q_now, 0.5 * (before + after), (after - before) / h)
