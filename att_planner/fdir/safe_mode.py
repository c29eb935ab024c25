"""Safe mode on what is left (no ROS, pure): the actuators and the law that can still hold the body.

The controller's safe mode (:mod:`att_planner.control.safe`) damps the rate with ``τ_B = −K_d ω_BN_B``
and then points a body axis at the Sun with the pointing law, both through the wheels. With the
healthy wheels no longer spanning the body the torque is put on the magnetorquers instead, by the
cross-product law ``m = B × τ / |B|²`` (its torque ``m × B`` is the part of ``τ`` normal to the field,
the only part coils can make; Camillo & Markley 1980; Silani & Lovera 2005); with the gyro not
trusted the rate is not known and the damping is the B-dot law ``m = −k Ḃ_B`` on the magnetometer
alone (Stickler & Alfriend 1974), which dissipates energy since ``Ḃ_B = −ω × B_B`` for a field fixed
in inertial space over the step. A dipole is scaled as a whole to the coil limit (its direction kept).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from att_planner.control import safe


@dataclass(frozen=True)
class SafeActuation:
    """What safe mode commands: a body torque for the healthy wheels, or a dipole for the coils."""

    on_wheels: bool
    torque_B: np.ndarray             # (3,) N m: the demand the healthy wheels realise (zero on the coils)
    dipole_B: np.ndarray             # (3,) A m²: the magnetorquer command (zero on the wheels)
    law: str                         # "wheels", "cross_product", "b_dot"


def scaled(dipole_B: np.ndarray, dipole_max: float) -> np.ndarray:
    """``dipole_B`` scaled as a whole so that no coil exceeds ``dipole_max``."""
    peak = float(np.abs(dipole_B).max(initial=0.0))
    return dipole_B * (dipole_max / peak) if peak > dipole_max else dipole_B


def cross_product_dipole(torque_B, field_B, dipole_max: float) -> np.ndarray:
    """``m = B × τ / |B|²`` (A m²), scaled to the coil limit; zero without a field."""
    B = np.asarray(field_B, float)
    b2 = float(B @ B)
    if not b2 > 0.0:
        return np.zeros(3)
    return scaled(np.cross(B, np.asarray(torque_B, float)) / b2, dipole_max)


def bdot_dipole(field_rate_B, gain: float, dipole_max: float) -> np.ndarray:
    """``m = −k Ḃ_B`` (A m²; ``field_rate_B`` T/s in body axes), scaled to the coil limit."""
    return scaled(-gain * np.asarray(field_rate_B, float), dipole_max)


def realise(torque_B, field_B, dipole_max: float, wheels_controllable: bool) -> SafeActuation:
    """The body torque ``torque_B`` on the healthy wheels when they span the body, else on the coils."""
    tau = np.asarray(torque_B, float)
    if wheels_controllable:
        return SafeActuation(True, tau, np.zeros(3), "wheels")
    return SafeActuation(False, np.zeros(3), cross_product_dipole(tau, field_B, dipole_max), "cross_product")


def damping(omega_BN_B, field_B, field_rate_B, kd: float, bdot_gain: float, dipole_max: float,
            wheels_controllable: bool, gyro_trusted: bool) -> SafeActuation:
    """The rate damping of safe mode on what is left: ``−K_d ω`` on the wheels or the coils while the
    gyro is trusted, else B-dot on the coils."""
    if not gyro_trusted:
        return SafeActuation(False, np.zeros(3), bdot_dipole(field_rate_B, bdot_gain, dipole_max), "b_dot")
    return realise(safe.damping_torque(np.asarray(omega_BN_B, float), kd), field_B, dipole_max, wheels_controllable)
