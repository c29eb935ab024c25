"""The typed schema of a spacecraft's sensors (pydantic v2 models, datasheet units): gyro, star
trackers with their exclusion cones, magnetometer, sun sensors and wheel tachometer. It is the
``sensors`` group of a spacecraft file (:class:`att_sim.models.config_schema.SpacecraftFile`),
converted to SI by :mod:`att_sim.models.sensor_specs`.
"""
from __future__ import annotations

import math
from typing import Any, ClassVar

from pydantic import Field, field_validator

from att_sim.models.config_base import Cone, Name, Quaternion, Schema, UnitVectors, distinct_names, number

MAX_SENSOR_RATE_HZ = 1000.0
RENAMED = {"rate_hz": "rate_Hz"}     # every sensor's output rate


def output_rate(default: float) -> Any:
    return number(default, gt=0.0, le=MAX_SENSOR_RATE_HZ, unit="Hz", meaning="output rate")


class Gyro(Schema):
    renamed: ClassVar = RENAMED

    rate_Hz: float = output_rate(20.0)
    arw_deg_per_sqrt_h: float = number(0.0, ge=0.0, le=100.0, unit="deg/sqrt(h)", meaning="angle random walk")
    bias_instability_deg_per_h: float = number(0.0, ge=0.0, le=1e4, unit="deg/h", meaning="bias instability")
    rrw_deg_per_h_per_sqrt_h: float = number(0.0, ge=0.0, le=1e4, unit="deg/h/sqrt(h)", meaning="rate random walk")
    initial_bias_deg_per_h: float = number(0.0, ge=0.0, le=1e5, unit="deg/h", meaning="turn-on bias, 1 sigma per axis")
    scale_factor_ppm: float = number(0.0, ge=0.0, le=1e5, unit="ppm", meaning="scale factor error, 1 sigma per axis")
    misalignment_arcsec: float = number(0.0, ge=0.0, le=3600.0, unit="arcsec", meaning="misalignment, 1 sigma")
    quantization_arcsec: float = number(0.0, ge=0.0, le=3600.0, unit="arcsec", meaning="angle increment LSB")
    range_deg_per_s: float = Field(math.inf, gt=0.0, description="saturation per axis (deg/s); .inf: none")


class Exclusion(Cone):
    """A cone a star tracker's boresight must stay out of (the tracker is blinded inside it)."""


class StarTracker(Schema):
    renamed: ClassVar = RENAMED

    name: Name
    mounting: Quaternion = Field([0.0, 0.0, 0.0, 1.0], description="sensor-to-body quaternion [x, y, z, w]; "
                                                                    "the boresight is the sensor's +z")
    rate_Hz: float = output_rate(5.0)
    latency_s: float = number(0.0, ge=0.0, le=10.0, unit="s", meaning="from the instant measured to the message")
    cross_boresight_arcsec: float = number(5.0, gt=0.0, le=3600.0, unit="arcsec", meaning="1 sigma across the "
                                                                                           "boresight")
    about_boresight_arcsec: float = number(40.0, gt=0.0, le=36000.0, unit="arcsec", meaning="1 sigma about the "
                                                                                             "boresight")
    max_rate_deg_per_s: float = Field(math.inf, gt=0.0, description="faster, the tracker loses its stars (deg/s)")
    exclusions: list[Exclusion] = Field([], max_length=16)


class Magnetometer(Schema):
    renamed: ClassVar = RENAMED

    rate_Hz: float = output_rate(10.0)
    noise_nT: float = number(0.0, ge=0.0, le=1e5, unit="nT", meaning="1 sigma per axis")
    bias_nT: float = number(0.0, ge=0.0, le=1e5, unit="nT", meaning="fixed bias, 1 sigma per axis")
    misalignment_deg: float = number(0.0, ge=0.0, le=10.0, unit="deg", meaning="misalignment, 1 sigma")
    quantization_nT: float = number(0.0, ge=0.0, le=1e4, unit="nT", meaning="per count")
    dipole_coupling_nT_per_Am2: float = number(0.0, ge=0.0, le=1e5, unit="nT per A m^2",
                                               meaning="field of the applied magnetorquer dipole")


class SunSensors(Schema):
    renamed: ClassVar = RENAMED

    normals: UnitVectors = Field([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0,
                                  0.0, 0.0, -1.0], description="unit body normal of each cosine detector")
    rate_Hz: float = output_rate(10.0)
    fov_deg: float = number(80.0, gt=0.0, le=90.0, unit="deg", meaning="half-angle of each detector's view")
    noise: float = number(0.0, ge=0.0, le=1.0, unit="", meaning="1 sigma of the normal-incidence output")


class WheelTachometer(Schema):
    renamed: ClassVar = RENAMED

    rate_Hz: float = output_rate(20.0)
    noise_rad_per_s: float = number(0.0, ge=0.0, le=100.0, unit="rad/s", meaning="1 sigma of a wheel speed")
    quantization_rad_per_s: float = number(0.0, ge=0.0, le=100.0, unit="rad/s", meaning="per count")


class Sensors(Schema):
    seed: int = Field(0, ge=0, lt=2**63, description="seed of every noise source and drawn error of the run")
    gyro: Gyro | None = None
    star_trackers: list[StarTracker] = Field([], max_length=8)
    magnetometer: Magnetometer | None = None
    sun_sensors: SunSensors | None = None
    wheel_tachometer: WheelTachometer | None = None

    @field_validator("star_trackers")
    @classmethod
    def _distinct(cls, trackers):
        return distinct_names(trackers, "star tracker")
