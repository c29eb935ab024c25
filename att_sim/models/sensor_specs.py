"""Sensor datasheets of a scenario: the ``sensors`` group, in datasheet units, converted once to SI.

A scenario's ``/**`` section may hold::

    sensors:
      seed: 20261202                  # every noise source of the run derives from it
      gyro: {rate_hz, arw_deg_per_sqrt_h, bias_instability_deg_per_h, rrw_deg_per_h_per_sqrt_h,
             initial_bias_deg_per_h, scale_factor_ppm, misalignment_arcsec, quantization_arcsec,
             range_deg_per_s}
      star_trackers: [{name, mounting, rate_hz, latency_s, cross_boresight_arcsec,
                       about_boresight_arcsec, max_rate_deg_per_s, exclusions: [{body, half_angle_deg,
                       direction}]}]
      magnetometer: {rate_hz, noise_nT, bias_nT, misalignment_deg, quantization_nT,
                     dipole_coupling_nT_per_Am2}
      sun_sensors: {rate_hz, normals, fov_deg, noise}
      wheel_tachometer: {rate_hz, noise_rad_per_s, quantization_rad_per_s}

Every field is optional but a sensor's presence; the 1σ figures (``initial_bias``, ``scale_factor``,
``misalignment``, ``bias``) are the spread the simulator draws the unit's actual errors from, with
the scenario's seed. Both sides read these datasheets: the simulator to make measurements, the
flight software for the nominal mounting, the noise it expects and the covariance it reports —
never the drawn errors, which only the truth side knows.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import ZONE_BODIES
from att_sim.models import config_schema as schema
from att_sim.models.config_group import Group

DEG = math.pi / 180.0
ARCSEC = DEG / 3600.0
HOUR = 3600.0
NANOTESLA = 1e-9
SENSOR_KINDS = ("seed", "gyro", "star_trackers", "magnetometer", "sun_sensors", "wheel_tachometer")
EXCLUSION_BODIES = tuple(b for b in ZONE_BODIES)


@dataclass(frozen=True)
class GyroSpec:
    """Three-axis rate gyro (SI). Rate noise model: ``ω_m = (I + S + M) ω + b + n_v`` with the bias
    ``b`` = turn-on bias + flicker (the bias instability) + rate random walk."""

    rate: float = 20.0                  # Hz
    arw: float = 0.0                    # rad/√s, angle random walk σ_v
    bias_instability: float = 0.0       # rad/s, B (Allan deviation floor 0.664 B)
    rrw: float = 0.0                    # rad/s/√s, rate random walk σ_u
    initial_bias: float = 0.0           # rad/s, 1σ per axis of the turn-on bias
    scale_factor: float = 0.0           # 1σ per axis (fraction)
    misalignment: float = 0.0           # rad, 1σ per off-diagonal element
    quantization: float = 0.0          # rad per output pulse (angle increment LSB); 0: none
    range: float = math.inf             # rad/s per axis (saturation)


@dataclass(frozen=True)
class Exclusion:
    """A cone about a body the tracker cannot look into: ``body`` (``sun``, ``moon``, ``earth_limb``,
    ``inertial`` with ``direction``) and ``half_angle`` (rad; for the Earth, beyond its limb)."""

    body: str
    half_angle: float
    direction: np.ndarray | None = None


@dataclass(frozen=True)
class StarTrackerSpec:
    """Star tracker: the sensor frame's boresight is its +z axis; ``mounting`` is the quaternion of
    the sensor frame in the body (sensor-to-body, ``v_B = R(mounting) v_S``)."""

    name: str = "star_tracker"
    mounting: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))
    rate: float = 5.0                   # Hz
    latency: float = 0.0                # s from the instant measured to the message
    cross_boresight: float = 5 * ARCSEC  # rad 1σ about each sensor axis across the boresight
    about_boresight: float = 40 * ARCSEC  # rad 1σ about the boresight
    max_rate: float = math.inf          # rad/s: faster, the tracker loses its stars (invalid)
    exclusions: tuple = ()              # Exclusion

    @property
    def covariance(self) -> np.ndarray:
        """Attitude error covariance in the sensor frame (rad²)."""
        return np.diag([self.cross_boresight**2, self.cross_boresight**2, self.about_boresight**2])


@dataclass(frozen=True)
class MagnetometerSpec:
    rate: float = 10.0                  # Hz
    noise: float = 0.0                  # T, 1σ per axis
    bias: float = 0.0                   # T, 1σ per axis of the unit's fixed bias
    misalignment: float = 0.0           # rad, 1σ per off-diagonal element
    quantization: float = 0.0           # T per count; 0: none
    dipole_coupling: float = 0.0        # T per A m² of applied magnetorquer dipole (along it)


@dataclass(frozen=True)
class SunSensorSpec:
    """Coarse sun sensors: cosine detectors with body ``normals`` (N, 3), each seeing the Sun within
    ``fov`` (half-angle, rad) of its normal; output 1 at normal incidence, ``noise`` 1σ of that."""

    normals: np.ndarray = field(default_factory=lambda: np.vstack([np.eye(3), -np.eye(3)]))
    rate: float = 10.0
    fov: float = 80 * DEG
    noise: float = 0.0


@dataclass(frozen=True)
class TachometerSpec:
    rate: float = 20.0                  # Hz
    noise: float = 0.0                  # rad/s 1σ of a measured wheel speed (relative to the body)
    quantization: float = 0.0           # rad/s per count; 0: none


@dataclass(frozen=True)
class SensorSpecs:
    seed: int = 0
    gyro: GyroSpec | None = None
    star_trackers: tuple = ()           # StarTrackerSpec
    magnetometer: MagnetometerSpec | None = None
    sun_sensors: SunSensorSpec | None = None
    tachometer: TachometerSpec | None = None

    def __bool__(self) -> bool:
        return any((self.gyro, self.star_trackers, self.magnetometer, self.sun_sensors, self.tachometer))


def gyro_from_params(g: Group) -> GyroSpec:
    def n(key):
        return g.declared(schema.Gyro, key)
    out = GyroSpec(
        rate=n("rate_hz"), arw=n("arw_deg_per_sqrt_h") * DEG / math.sqrt(HOUR),
        bias_instability=n("bias_instability_deg_per_h") * DEG / HOUR,
        rrw=n("rrw_deg_per_h_per_sqrt_h") * DEG / HOUR / math.sqrt(HOUR),
        initial_bias=n("initial_bias_deg_per_h") * DEG / HOUR, scale_factor=n("scale_factor_ppm") * 1e-6,
        misalignment=n("misalignment_arcsec") * ARCSEC, quantization=n("quantization_arcsec") * ARCSEC,
        range=n("range_deg_per_s") * DEG)
    g.done()
    return out


def exclusion_from_params(g: Group, epoch_known: bool) -> Exclusion:
    body = g.choice("body", EXCLUSION_BODIES)
    limb = body == "earth_limb"
    angle = g.number("half_angle_deg", None, 0.0, 90.0 if limb else 180.0, low_open=not limb, high_open=True)
    direction = g.unit_vectors("direction")[0] if body == "inertial" else None
    if body != "inertial" and "direction" in g:
        raise ValueError(f"{g.field('direction')} is only for body inertial")
    if body in ("sun", "moon") and not epoch_known:
        raise ValueError(f"{g.field('body')} {body} needs the scenario's epoch (the {body}'s position)")
    g.done()
    return Exclusion(body, angle * DEG, direction)


def star_tracker_from_params(g: Group, epoch_known: bool) -> StarTrackerSpec:
    def n(key):
        return g.declared(schema.StarTracker, key)
    out = StarTrackerSpec(
        name=g.name("name"), mounting=g.quaternion("mounting", schema.StarTracker.model_fields["mounting"].default),
        rate=n("rate_hz"), latency=n("latency_s"), cross_boresight=n("cross_boresight_arcsec") * ARCSEC,
        about_boresight=n("about_boresight_arcsec") * ARCSEC, max_rate=n("max_rate_deg_per_s") * DEG,
        exclusions=tuple(exclusion_from_params(e, epoch_known) for e in g.items("exclusions")))
    g.done()
    return out


def magnetometer_from_params(g: Group) -> MagnetometerSpec:
    def n(key):
        return g.declared(schema.Magnetometer, key)
    out = MagnetometerSpec(
        rate=n("rate_hz"), noise=n("noise_nT") * NANOTESLA, bias=n("bias_nT") * NANOTESLA,
        misalignment=n("misalignment_deg") * DEG, quantization=n("quantization_nT") * NANOTESLA,
        dipole_coupling=n("dipole_coupling_nT_per_Am2") * NANOTESLA)
    g.done()
    return out


def sun_sensors_from_params(g: Group, epoch_known: bool) -> SunSensorSpec:
    if not epoch_known:
        raise ValueError(f"{g.label} needs the scenario's epoch (the Sun's position and the Earth's shadow)")
    out = SunSensorSpec(normals=g.unit_vectors("normals", schema.SunSensors.model_fields["normals"].default),
                        rate=g.declared(schema.SunSensors, "rate_hz"),
                        fov=g.declared(schema.SunSensors, "fov_deg") * DEG,
                        noise=g.declared(schema.SunSensors, "noise"))
    g.done()
    return out


def tachometer_from_params(g: Group) -> TachometerSpec:
    out = TachometerSpec(rate=g.declared(schema.WheelTachometer, "rate_hz"),
                         noise=g.declared(schema.WheelTachometer, "noise_rad_per_s"),
                         quantization=g.declared(schema.WheelTachometer, "quantization_rad_per_s"))
    g.done()
    return out


def sensors_from_params(values, epoch_known: bool, label: str = "sensors") -> SensorSpecs:
    """The ``sensors`` group (ValueError naming the field); ``epoch_known``: the scenario has an
    epoch (Sun and Moon exclusions and sun sensors need it)."""
    g = Group(values, label)
    seed = g.raw("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise ValueError(f"{g.field('seed')} must be an integer in [0, 2^63), got {seed!r}"[:200])
    trackers = tuple(star_tracker_from_params(t, epoch_known) for t in g.items("star_trackers"))
    names = [t.name for t in trackers]
    if len(set(names)) != len(names):
        raise ValueError(f"{g.field('star_trackers')}: names must be unique, got {', '.join(names)}")
    out = SensorSpecs(
        seed=seed,
        gyro=gyro_from_params(g.group("gyro")) if "gyro" in g else None,
        star_trackers=trackers,
        magnetometer=magnetometer_from_params(g.group("magnetometer")) if "magnetometer" in g else None,
        sun_sensors=sun_sensors_from_params(g.group("sun_sensors"), epoch_known) if "sun_sensors" in g else None,
        tachometer=tachometer_from_params(g.group("wheel_tachometer")) if "wheel_tachometer" in g else None)
    for kind in ("gyro", "magnetometer", "sun_sensors", "wheel_tachometer"):
        g.read.add(kind)
    g.done()
    return out
