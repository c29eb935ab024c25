"""Actuator datasheets of a scenario: the ``actuators`` group, in datasheet units, converted once to SI.

A scenario's ``/**`` section may hold (datasheet units; every key optional)::

    actuators:
      wheels: {coulomb_friction_Nm, viscous_friction_Nm_s, friction_speed_rad_s,
               torque_quantization_Nm, torque_noise_Nm, power_max_W}
      magnetorquers: {quantization_Am2, misalignment_deg}

The datasheets are shared: the truth's imperfect actuators (:mod:`att_sim.truth.actuators`) apply
them, and the flight software compensates the friction it expects from them
(:meth:`WheelDriveSpec.friction`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_sim.models import config_actuators
from att_sim.models.sensor_specs import validated

DEG = math.pi / 180.0


@dataclass(frozen=True)
class WheelDriveSpec:
    coulomb_friction: float = 0.0       # N m
    viscous_friction: float = 0.0       # N m s/rad
    friction_speed: float = 1.0         # rad/s: the Coulomb term's smoothing ν_s
    torque_quantization: float = 0.0    # N m per count; 0: none
    torque_noise: float = 0.0           # N m 1σ, per control step
    power_max: float = math.inf         # W: motor torque ≤ P_max/|ν| while speeding the wheel up
    torque_scale: tuple = ()            # per wheel: delivered/commanded torque (a campaign's dispersion); (): 1

    def friction(self, speed: np.ndarray) -> np.ndarray:
        """Friction torques opposing relative wheel speeds ``speed`` (N m): :func:`friction_torque`."""
        return friction_torque(self.coulomb_friction, self.viscous_friction, self.friction_speed,
                               np.asarray(speed, float))


def friction_torque(coulomb, viscous, friction_speed, speed: np.ndarray) -> np.ndarray:
    """Friction torque opposing relative wheel speeds ``ν`` (N m): ``c tanh(ν/ν_s) + b ν`` (Bialke 1998);
    the parameters numbers or columns of runs (rows of ``speed``)."""
    return coulomb * np.tanh(speed / friction_speed) + viscous * speed


@dataclass(frozen=True)
class MagnetorquerSpec:
    quantization: float = 0.0           # A m² per count; 0: none
    misalignment: float = 0.0           # rad 1σ per off-diagonal element
    scale: tuple = ()                   # per coil: produced/commanded dipole (a campaign's dispersion); (): 1


@dataclass(frozen=True)
class ActuatorSpecs:
    wheels: WheelDriveSpec | None = None
    magnetorquers: MagnetorquerSpec | None = None


def actuators_from_model(a: config_actuators.Actuators) -> ActuatorSpecs:
    """The validated ``actuators`` group (:class:`att_sim.models.config_actuators.Actuators`) in SI."""
    w, m = a.wheels, a.magnetorquers
    wheels = None if w is None else WheelDriveSpec(
        w.coulomb_friction_Nm, w.viscous_friction_Nm_s, w.friction_speed_rad_s, w.torque_quantization_Nm,
        w.torque_noise_Nm, w.power_max_W)
    magnetorquers = None if m is None else MagnetorquerSpec(quantization=m.quantization_Am2,
                                                            misalignment=m.misalignment_deg * DEG)
    return ActuatorSpecs(wheels, magnetorquers)


def actuators_from_params(values, label: str = "actuators") -> ActuatorSpecs:
    """The ``actuators`` group (a mapping), validated by :class:`att_sim.models.config_actuators.Actuators`
    (ValueError naming the field)."""
    return actuators_from_model(validated(config_actuators.Actuators, values, label))
