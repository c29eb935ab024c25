"""The typed schema of a spacecraft's actuator imperfections (pydantic v2 models): the reaction wheel
drives' friction, quantization, noise and power limit and the magnetorquers' quantization and
misalignment. They are the truth's (the flight software compensates the friction): the ``actuators``
group of a spacecraft file (:class:`att_sim.models.config_schema.SpacecraftFile`), converted to SI by
:mod:`att_sim.models.actuator_specs`.
"""
from __future__ import annotations

import math

from pydantic import Field

from att_sim.models.config_base import Schema, number


class WheelDrives(Schema):
    coulomb_friction_Nm: float = number(0.0, ge=0.0, le=10.0, unit="N m", meaning="Coulomb friction")
    viscous_friction_Nm_s: float = number(0.0, ge=0.0, le=10.0, unit="N m s/rad", meaning="viscous friction")
    friction_speed_rad_s: float = number(1.0, gt=0.0, le=1e3, unit="rad/s", meaning="Coulomb term's smoothing")
    torque_quantization_Nm: float = number(0.0, ge=0.0, le=10.0, unit="N m", meaning="per count")
    torque_noise_Nm: float = number(0.0, ge=0.0, le=10.0, unit="N m", meaning="1 sigma per control step")
    power_max_W: float = Field(math.inf, gt=0.0, description="motor power limit while speeding up (W)")


class Magnetorquers(Schema):
    quantization_Am2: float = number(0.0, ge=0.0, le=100.0, unit="A m^2", meaning="per count")
    misalignment_deg: float = number(0.0, ge=0.0, le=10.0, unit="deg", meaning="1 sigma per off-diagonal element")


class Actuators(Schema):
    wheels: WheelDrives | None = None
    magnetorquers: Magnetorquers | None = None
