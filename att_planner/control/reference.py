"""The reference every control law tracks: one frame R at one instant, its rates in its own axes.

A plan (:func:`att_planner.control.tracking.plan_reference`) and a pointing law
(:func:`att_planner.control.pointing.law_reference`) both give the attitude of a reference frame R
relative to the inertial frame N and the rate of R relative to N in R's own axes: a plan's
``omega`` samples are the planned body rates, i.e. in the axes of the body as planned (R). The laws
rotate those rates into the body's axes with ``[BR]`` (:func:`att_planner.control.pd.to_body`)
before they compare them with the body's rate (Schaub & Junkins, *Analytical Mechanics of Space
Systems*, §8.3).

Fields are single instants (``(4,)``, ``(3,)``) or rows of runs (``(n, 4)``, ``(n, 3)``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _zeros3() -> np.ndarray:
    return np.zeros(3)


@dataclass(frozen=True)
class Reference:
    """Attitude ``q_RN`` ([x, y, z, w], R to N), rate ``omega_RN_R`` (rad/s) and acceleration
    ``omega_dot_RN_R`` (rad/s², the derivative of ``omega_RN_R`` in R) of the reference frame, and
    the feedforward body torque ``torque_R`` (N m) a plan applies when the body is on R, in R's axes."""

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
