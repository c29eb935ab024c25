"""Sensor datasheets of a scenario: the ``sensors`` group, in datasheet units, converted once to SI.

A scenario's ``/**`` section may hold::

    sensors:
      seed: 20261202                  # every noise source of the run derives from it
      gyro: {rate_Hz, arw_deg_per_sqrt_h, bias_instability_deg_per_h, rrw_deg_per_h_per_sqrt_h,
             initial_bias_deg_per_h, scale_factor_ppm, misalignment_arcsec, quantization_arcsec,
             range_deg_per_s}
      star_trackers: [{name, mounting, rate_Hz, latency_s, cross_boresight_arcsec,
                       about_boresight_arcsec, max_rate_deg_per_s, exclusions: [{body, half_angle_deg,
                       direction}]}]
      magnetometer: {rate_Hz, noise_nT, bias_nT, misalignment_deg, quantization_nT,
                     dipole_coupling_nT_per_Am2}
      sun_sensors: {rate_Hz, normals, fov_deg, noise}
      wheel_tachometer: {rate_Hz, noise_rad_per_s, quantization_rad_per_s}

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
from pydantic import ValidationError

from att_msgs_py.types import ZONE_BODIES
from att_sim.models import config_files, config_sensors

DEG = math.pi / 180.0
ARCSEC = DEG / 3600.0
HOUR = 3600.0
NANOTESLA = 1e-9
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


def _refused(exc: ValidationError, model, values, label: str) -> ValueError:
    """A pydantic error of the group ``label`` as one ValueError naming each field: ``label.field:
    expected ...; found ...`` (the loader's wording, :mod:`att_sim.models.config_files`)."""
    problems = config_files.problems_of(exc, model, values if isinstance(values, dict) else {}, {}, label)
    lines = [f"{label}{'.' + p.field if p.field and not p.field.startswith('[') else p.field}: expected "
             f"{p.expected}; found {p.found}" for p in problems]
    return ValueError("\n".join(lines[:8]))


def validated(model, values, label: str):
    """``values`` (a group of a scenario) validated by the pydantic ``model`` (ValueError naming the field)."""
    try:
        return model.model_validate(values)
    except ValidationError as exc:
        raise _refused(exc, model, values, label) from None


def _epoch_needs(s: config_sensors.Sensors, label: str) -> None:
    for k, t in enumerate(s.star_trackers):
        for j, e in enumerate(t.exclusions):
            if e.body in ("sun", "moon"):
                raise ValueError(f"{label}.star_trackers[{k}].exclusions[{j}].body {e.body} needs the scenario's "
                                 f"epoch (the {e.body}'s position)")
    if s.sun_sensors is not None:
        raise ValueError(f"{label}.sun_sensors needs the scenario's epoch (the Sun's position and the Earth's "
                         f"shadow)")


def _unit(v) -> np.ndarray:
    a = np.asarray(v, float)
    return a / np.linalg.norm(a)


def sensors_from_model(s: config_sensors.Sensors) -> SensorSpecs:
    """The validated ``sensors`` group (:class:`att_sim.models.config_sensors.Sensors`, datasheet units)
    in SI."""
    g, m, ss, w = s.gyro, s.magnetometer, s.sun_sensors, s.wheel_tachometer
    gyro = None if g is None else GyroSpec(
        rate=g.rate_Hz, arw=g.arw_deg_per_sqrt_h * DEG / math.sqrt(HOUR),
        bias_instability=g.bias_instability_deg_per_h * DEG / HOUR,
        rrw=g.rrw_deg_per_h_per_sqrt_h * DEG / HOUR / math.sqrt(HOUR),
        initial_bias=g.initial_bias_deg_per_h * DEG / HOUR, scale_factor=g.scale_factor_ppm * 1e-6,
        misalignment=g.misalignment_arcsec * ARCSEC, quantization=g.quantization_arcsec * ARCSEC,
        range=g.range_deg_per_s * DEG)
    trackers = tuple(StarTrackerSpec(
        name=t.name, mounting=_unit(t.mounting), rate=t.rate_Hz, latency=t.latency_s,
        cross_boresight=t.cross_boresight_arcsec * ARCSEC, about_boresight=t.about_boresight_arcsec * ARCSEC,
        max_rate=t.max_rate_deg_per_s * DEG,
        exclusions=tuple(Exclusion(e.body, e.half_angle_deg * DEG,
                                   _unit(e.direction) if e.direction is not None else None) for e in t.exclusions))
        for t in s.star_trackers)
    magnetometer = None if m is None else MagnetometerSpec(
        rate=m.rate_Hz, noise=m.noise_nT * NANOTESLA, bias=m.bias_nT * NANOTESLA, misalignment=m.misalignment_deg * DEG,
        quantization=m.quantization_nT * NANOTESLA, dipole_coupling=m.dipole_coupling_nT_per_Am2 * NANOTESLA)
    sun = None if ss is None else SunSensorSpec(
        normals=np.asarray(ss.normals, float).reshape(-1, 3) / np.linalg.norm(
            np.asarray(ss.normals, float).reshape(-1, 3), axis=1)[:, None],
        rate=ss.rate_Hz, fov=ss.fov_deg * DEG, noise=ss.noise)
    tachometer = None if w is None else TachometerSpec(rate=w.rate_Hz, noise=w.noise_rad_per_s,
                                                       quantization=w.quantization_rad_per_s)
    return SensorSpecs(seed=s.seed, gyro=gyro, star_trackers=trackers, magnetometer=magnetometer, sun_sensors=sun,
                       tachometer=tachometer)


def sensors_from_params(values, epoch_known: bool, label: str = "sensors") -> SensorSpecs:
    """The ``sensors`` group of a scenario (a mapping), validated by
    :class:`att_sim.models.config_sensors.Sensors` (ValueError naming the field); ``epoch_known``: the
    scenario has an epoch (Sun and Moon exclusions and sun sensors need it)."""
    model = validated(config_sensors.Sensors, values, label)
    if not epoch_known:
        _epoch_needs(model, label)
    return sensors_from_model(model)
