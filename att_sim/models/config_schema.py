"""The typed schema of a spacecraft and of a scenario file (pydantic v2 models).

A scenario file is a ROS 2 parameter file whose ``/**: ros__parameters:`` section holds the
spacecraft (:class:`Spacecraft`: inertia, wheels, magnetorquers, sensors, actuator imperfections)
and its sky (epoch, orbit, field model, environment with facets, zones, frames); every other
top-level section is one node's ``ros__parameters`` (typed by the nodes' own parameter schemas).

Each key carries its unit in its name where it has one; each default and range is written once,
here; a key of an older name is refused with its new name (each model's ``renamed`` table,
reported by :mod:`att_sim.models.config_files`). Physical checks: the inertia is symmetric,
positive definite and satisfies the triangle inequalities (each principal moment at most the sum
of the other two); axes, normals and directions are unit vectors (within
:data:`UNIT_TOLERANCE`); quaternions are [x, y, z, w] of unit norm; numbers are finite but the
limits documented as accepting ``.inf`` (no limit).
"""
from __future__ import annotations

import math
from datetime import datetime
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import AfterValidator, BaseModel, ConfigDict, Discriminator, Field, Tag, field_validator, model_validator

from att_msgs_py.types import ZONE_BODIES
from att_sim.models import epoch as epochs

UNIT_TOLERANCE = 1e-3          # |‖v‖ − 1| accepted for a unit vector or quaternion of a file
MAX_NAME = 128
MAX_SENSOR_RATE_HZ = 1000.0
IDENTITY_AXES = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)


class Schema(BaseModel):
    """A mapping of a configuration file: unknown keys refused, values immutable once read."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, populate_by_name=True,
                              ser_json_inf_nan="strings")
    renamed: ClassVar[dict[str, str]] = {}     # old key -> its new name (refused, answered with it)


def _finite(x: float) -> float:
    if not math.isfinite(x):
        raise ValueError(f"a finite number, got {x!r}")
    return x


def distinct_names(items: list, what: str) -> list:
    """``items`` when their ``name`` fields differ (a validator's ValueError naming them otherwise)."""
    names = [item.name for item in items]
    if len(set(names)) != len(names):
        raise ValueError(f"distinct {what} names, got {', '.join(names)}")
    return items


def _norm_near_one(v: list[float]) -> list[float]:
    norm = float(np.linalg.norm(v))
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise ValueError(f"a unit vector (norm within {UNIT_TOLERANCE:g} of 1), got norm {norm:.6g}")
    return v


def _unit_triples(v: list[float]) -> list[float]:
    rows = np.asarray(v, float).reshape(-1, 3)
    norms = np.linalg.norm(rows, axis=1)
    bad = np.flatnonzero(np.abs(norms - 1.0) > UNIT_TOLERANCE)
    if bad.size:
        raise ValueError(f"3 numbers per unit vector; vector {int(bad[0])} has norm {norms[bad[0]]:.6g}")
    return v


def _triples(v: list[float]) -> list[float]:
    if len(v) % 3:
        raise ValueError(f"3 numbers per vector, got {len(v)} numbers")
    return v


def _printable(name: str) -> str:
    if not name.isprintable():
        raise ValueError("a printable name (no control characters)")
    return name


Finite = Annotated[float, AfterValidator(_finite)]
Vector3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
UnitVector3 = Annotated[Vector3, AfterValidator(_norm_near_one)]
UnitVectors = Annotated[list[Finite], Field(max_length=3 * 64), AfterValidator(_triples),
                        AfterValidator(_unit_triples)]
Quaternion = Annotated[list[Finite], Field(min_length=4, max_length=4), AfterValidator(_norm_near_one)]
Name = Annotated[str, Field(min_length=1, max_length=MAX_NAME), AfterValidator(_printable)]


def number(default: Any = ..., *, unit: str, meaning: str, ge: float | None = None, gt: float | None = None,
           le: float | None = None, lt: float | None = None) -> Any:
    """A float field with its default, range, unit and meaning (the JSON Schema's description)."""
    return Field(default, ge=ge, gt=gt, le=le, lt=lt, description=f"{meaning} ({unit})" if unit else meaning)


def limit(meaning: str, unit: str) -> Any:
    """A positive limit; ``.inf`` (the default) for no limit."""
    return Field(math.inf, gt=0.0, description=f"{meaning} ({unit}); .inf: no limit")


def declared(model: type[BaseModel], field: str) -> tuple:
    """``(default, low, high, low_open, high_open)`` of a number field of ``model`` (default None when
    the field is required; bounds ±inf where it has none): for readers that check a value against
    the range written here."""
    info = model.model_fields[field]
    bounds = {name: getattr(m, name) for m in info.metadata for name in ("ge", "gt", "le", "lt")
              if getattr(m, name, None) is not None}
    return (None if info.is_required() else info.default, bounds.get("ge", bounds.get("gt", -math.inf)),
            bounds.get("le", bounds.get("lt", math.inf)), "gt" in bounds, "lt" in bounds)


# ---------------------------------------------------------------------------------------------
# the spacecraft: body, wheels, magnetorquers


def inertia_problem(inertia: np.ndarray) -> str | None:
    """Why the 3×3 ``inertia`` is not a rigid body's (None when it is): symmetric, positive
    definite, each principal moment at most the sum of the other two."""
    if not np.all(np.isfinite(inertia)):
        return "finite numbers"
    if not np.allclose(inertia, inertia.T, rtol=1e-9, atol=1e-12 * max(1.0, float(np.abs(inertia).max()))):
        return "a symmetric matrix (row-major: element [i][j] equal to [j][i])"
    moments = np.linalg.eigvalsh(inertia)
    if moments[0] <= 0:
        return f"a positive definite matrix, got principal moments {np.array2string(moments, precision=4)}"
    if moments[2] > moments[0] + moments[1] * (1 + 1e-12):
        return (f"principal moments satisfying the triangle inequality, got {moments[2]:.6g} > "
                f"{moments[0]:.6g} + {moments[1]:.6g}")
    return None


def inertia_matrix(values) -> np.ndarray:
    """3 principal or 9 row-major numbers as the 3×3 inertia (kg m²)."""
    a = np.asarray(values, float)
    return np.diag(a) if a.size == 3 else a.reshape(3, 3)


def _physical_inertia(v: list[float]) -> list[float]:
    if len(v) not in (3, 9):
        raise ValueError(f"3 principal or 9 row-major numbers, got {len(v)} numbers")
    why = inertia_problem(inertia_matrix(v))
    if why:
        raise ValueError(why)
    return v


class Spacecraft(Schema):
    """The rigid body and its actuators' limits (the planning and the truth models' spacecraft)."""

    renamed: ClassVar = {"inertia": "inertia_kg_m2", "torque_max": "torque_max_Nm",
                         "wheel_inertia": "wheel_inertia_kg_m2", "wheel_torque_max": "wheel_torque_max_Nm",
                         "wheel_speed_max": "wheel_speed_max_rad_s", "dipole_max": "dipole_max_Am2"}

    inertia_kg_m2: Annotated[list[Finite], AfterValidator(_physical_inertia)] = Field(
        description="inertia about the centre of mass in body axes (kg m^2): 3 principal moments or 9 row-major")
    torque_max_Nm: float = limit("body torque per axis, the planning limit", "N m")
    wheel_axes: UnitVectors = Field(list(IDENTITY_AXES), description="one unit spin axis per wheel, body axes, "
                                                                     "3 numbers after 3 numbers")
    wheel_inertia_kg_m2: float = number(0.0, ge=0.0, unit="kg m^2", meaning="spin inertia of each wheel")
    wheel_torque_max_Nm: float = limit("motor torque of each wheel", "N m")
    wheel_speed_max_rad_s: float = limit("speed of each wheel relative to the body", "rad/s")
    dipole_max_Am2: float = limit("dipole of each magnetorquer coil", "A m^2")

    @model_validator(mode="after")
    def _wheels_spin(self):
        if self.wheel_axes and self.wheel_inertia_kg_m2 <= 0:
            raise ValueError("wheel_inertia_kg_m2 > 0 when there are wheels")
        return self


# ---------------------------------------------------------------------------------------------
# sensors (datasheet units)


def rate_hz(default: float) -> Any:
    return number(default, gt=0.0, le=MAX_SENSOR_RATE_HZ, unit="Hz", meaning="output rate")


class Gyro(Schema):
    rate_hz: float = rate_hz(20.0)
    arw_deg_per_sqrt_h: float = number(0.0, ge=0.0, le=100.0, unit="deg/sqrt(h)", meaning="angle random walk")
    bias_instability_deg_per_h: float = number(0.0, ge=0.0, le=1e4, unit="deg/h", meaning="bias instability")
    rrw_deg_per_h_per_sqrt_h: float = number(0.0, ge=0.0, le=1e4, unit="deg/h/sqrt(h)", meaning="rate random walk")
    initial_bias_deg_per_h: float = number(0.0, ge=0.0, le=1e5, unit="deg/h", meaning="turn-on bias, 1 sigma per axis")
    scale_factor_ppm: float = number(0.0, ge=0.0, le=1e5, unit="ppm", meaning="scale factor error, 1 sigma per axis")
    misalignment_arcsec: float = number(0.0, ge=0.0, le=3600.0, unit="arcsec", meaning="misalignment, 1 sigma")
    quantization_arcsec: float = number(0.0, ge=0.0, le=3600.0, unit="arcsec", meaning="angle increment LSB")
    range_deg_per_s: float = Field(math.inf, gt=0.0, description="saturation per axis (deg/s); .inf: none")


def _cone_angle(body: str, angle: float, label: str) -> None:
    limb = body == "earth_limb"
    if not ((0.0 <= angle < 90.0) if limb else (0.0 < angle < 180.0)):
        what = "the margin beyond the Earth limb in [0, 90) deg" if limb else "a cone half-angle in (0, 180) deg"
        raise ValueError(f"{label} {what}, got {angle:g}")


def _direction_for(body: str, direction) -> None:
    if (body == "inertial") != (direction is not None):
        raise ValueError("direction (a unit inertial vector) for body inertial, and only for it")


class Exclusion(Schema):
    body: Literal[ZONE_BODIES] = Field(description="the body the tracker cannot look near")
    half_angle_deg: float = Field(description="cone half-angle (deg); for earth_limb the margin beyond the limb")
    direction: UnitVector3 | None = Field(None, description="unit inertial direction (body inertial only)")

    @model_validator(mode="after")
    def _consistent(self):
        _cone_angle(self.body, self.half_angle_deg, "half_angle_deg")
        _direction_for(self.body, self.direction)
        return self


class StarTracker(Schema):
    name: Name
    mounting: Quaternion = Field([0.0, 0.0, 0.0, 1.0], description="sensor-to-body quaternion [x, y, z, w]; "
                                                                    "the boresight is the sensor's +z")
    rate_hz: float = rate_hz(5.0)
    latency_s: float = number(0.0, ge=0.0, le=10.0, unit="s", meaning="from the instant measured to the message")
    cross_boresight_arcsec: float = number(5.0, gt=0.0, le=3600.0, unit="arcsec", meaning="1 sigma across the "
                                                                                           "boresight")
    about_boresight_arcsec: float = number(40.0, gt=0.0, le=36000.0, unit="arcsec", meaning="1 sigma about the "
                                                                                             "boresight")
    max_rate_deg_per_s: float = Field(math.inf, gt=0.0, description="faster, the tracker loses its stars (deg/s)")
    exclusions: list[Exclusion] = Field([], max_length=16)


class Magnetometer(Schema):
    rate_hz: float = rate_hz(10.0)
    noise_nT: float = number(0.0, ge=0.0, le=1e5, unit="nT", meaning="1 sigma per axis")
    bias_nT: float = number(0.0, ge=0.0, le=1e5, unit="nT", meaning="fixed bias, 1 sigma per axis")
    misalignment_deg: float = number(0.0, ge=0.0, le=10.0, unit="deg", meaning="misalignment, 1 sigma")
    quantization_nT: float = number(0.0, ge=0.0, le=1e4, unit="nT", meaning="per count")
    dipole_coupling_nT_per_Am2: float = number(0.0, ge=0.0, le=1e5, unit="nT per A m^2",
                                               meaning="field of the applied magnetorquer dipole")


class SunSensors(Schema):
    normals: UnitVectors = Field([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0,
                                  0.0, 0.0, -1.0], description="unit body normal of each cosine detector")
    rate_hz: float = rate_hz(10.0)
    fov_deg: float = number(80.0, gt=0.0, le=90.0, unit="deg", meaning="half-angle of each detector's view")
    noise: float = number(0.0, ge=0.0, le=1.0, unit="", meaning="1 sigma of the normal-incidence output")


class WheelTachometer(Schema):
    rate_hz: float = rate_hz(20.0)
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


# ---------------------------------------------------------------------------------------------
# actuator imperfections (the truth's; the flight software compensates the friction)


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


# ---------------------------------------------------------------------------------------------
# the sky: orbit, environment, zones


class CircularOrbit(Schema):
    renamed: ClassVar = {"altitude": "altitude_m", "arg0": "arg0_rad"}

    type: Literal["circular"] = "circular"
    altitude_m: float = number(450e3, gt=0.0, unit="m", meaning="altitude above the mean Earth radius")
    inclination_deg: Finite = Field(87.0, description="inclination (deg)")
    raan_deg: Finite = Field(0.0, description="right ascension of the ascending node (deg)")
    arg0_rad: Finite = Field(0.0, description="argument of latitude at sim time zero (rad)")


class KeplerOrbit(Schema):
    renamed: ClassVar = {"semi_major_axis": "semi_major_axis_m"}

    type: Literal["kepler"]
    semi_major_axis_m: float = number(gt=6_378_137.0, unit="m", meaning="semi-major axis, above the Earth radius")
    eccentricity: float = number(ge=0.0, lt=1.0, unit="", meaning="eccentricity")
    inclination_deg: float = number(ge=0.0, le=180.0, unit="deg", meaning="inclination")
    raan_deg: Finite = Field(description="right ascension of the ascending node (deg)")
    arg_perigee_deg: Finite = Field(description="argument of perigee (deg)")
    mean_anomaly_deg: Finite = Field(description="mean anomaly at the epoch (deg)")


class TLEOrbit(Schema):
    type: Literal["tle"]
    line1: str = Field(min_length=69, max_length=69, description="TLE line 1 (69 characters)")
    line2: str = Field(min_length=69, max_length=69, description="TLE line 2 (69 characters)")


def _orbit_type(value) -> str:
    return value.get("type", "circular") if isinstance(value, dict) else "circular"


Orbit = Annotated[Annotated[CircularOrbit, Tag("circular")] | Annotated[KeplerOrbit, Tag("kepler")]
                  | Annotated[TLEOrbit, Tag("tle")], Discriminator(_orbit_type)]


class Facet(Schema):
    """A flat plate of the surface model (solar pressure, drag)."""

    renamed: ClassVar = {"area": "area_m2", "center": "center_m"}

    area_m2: float = number(gt=0.0, unit="m^2", meaning="area")
    normal: UnitVector3 = Field(description="outward unit normal, body axes")
    center_m: Vector3 = Field(description="centre of pressure from the centre of mass, body axes (m)")
    specular: float = number(ge=0.0, le=1.0, unit="", meaning="specular reflectivity")
    diffuse: float = number(ge=0.0, le=1.0, unit="", meaning="diffuse reflectivity")

    @model_validator(mode="after")
    def _energy(self):
        if self.specular + self.diffuse > 1.0:
            raise ValueError(f"specular + diffuse at most 1, got {self.specular:g} + {self.diffuse:g}")
        return self


class Surface(Schema):
    """The spacecraft's outer surface and magnetic cleanliness, as the disturbances see them."""

    renamed: ClassVar = {"residual_dipole": "residual_dipole_Am2"}

    drag_coefficient: float = number(2.2, gt=0.0, le=10.0, unit="", meaning="drag coefficient C_D")
    residual_dipole_Am2: Vector3 = Field([0.0, 0.0, 0.0], description="residual magnetic dipole, body (A m^2)")
    facets: list[Facet] = Field([], max_length=256)


class Disturbances(Schema):
    """Which environment torques act on the spacecraft in a scenario."""

    gravity_gradient: bool = False
    solar_pressure: bool = False
    drag: bool = False


class Environment(Disturbances, Surface):
    """The disturbances of a scenario with the surface they act on."""

    renamed: ClassVar = Surface.renamed

    @model_validator(mode="after")
    def _surfaces(self):
        for key in ("solar_pressure", "drag"):
            if getattr(self, key) and not self.facets:
                raise ValueError(f"facets (the surfaces {key} acts on) when {key} is true")
        return self


class Zone(Schema):
    name: Name
    body: Literal[ZONE_BODIES]
    sensor_axis: UnitVector3 = Field(description="unit body axis of the sensor the zone constrains")
    half_angle_deg: float = Field(description="cone half-angle in (0, 180) deg; earth_limb: margin in [0, 90) deg")
    keep_in: bool = False
    direction: UnitVector3 | None = Field(None, description="unit inertial direction (body inertial only)")

    @model_validator(mode="after")
    def _consistent(self):
        _cone_angle(self.body, self.half_angle_deg, "half_angle_deg")
        _direction_for(self.body, self.direction)
        return self


def _epoch(value):
    if isinstance(value, (str, datetime)):
        epochs.parse_epoch(value)
    return value


class Sky(Schema):
    """Where and when a scenario flies: frames, orbit, epoch, field model, zones."""

    frame_id: Name = Field("eci", description="the inertial frame's name")
    body_frame_id: Name = Field("body", description="the body frame's name")
    orbit: Orbit = Field(default_factory=CircularOrbit)
    epoch: Annotated[str | datetime, AfterValidator(_epoch)] | None = Field(
        None, description="UTC of sim time zero, ISO 8601 with Z or an offset; none: a fixed sky")
    field_model: Literal["dipole", "igrf14"] = "dipole"
    zones: list[Zone] = Field([], max_length=64)

    @field_validator("zones")
    @classmethod
    def _distinct(cls, zones):
        return distinct_names(zones, "zone")


class Shared(Sky):
    """A scenario resolved: the spacecraft and its sky, read by every node (the ``/**:
    ros__parameters`` section of a self-contained scenario file)."""

    spacecraft: Spacecraft
    environment: Environment = Field(default_factory=Environment)
    sensors: Sensors = Field(default_factory=Sensors)
    actuators: Actuators = Field(default_factory=Actuators)

    @model_validator(mode="after")
    def _needs_epoch(self):
        if self.epoch is not None:
            return self
        needs = []
        if self.orbit.type != "circular":
            needs.append(f"orbit type {self.orbit.type}")
        if self.field_model == "igrf14":
            needs.append("field_model igrf14")
        if self.environment.solar_pressure:
            needs.append("environment.solar_pressure")
        needs += [f"zone {z.name} (body {z.body})" for z in self.zones if z.body in ("sun", "moon")]
        needs += [f"star tracker {t.name}'s {e.body} exclusion" for t in self.sensors.star_trackers
                  for e in t.exclusions if e.body in ("sun", "moon")]
        if self.sensors.sun_sensors is not None:
            needs.append("sun_sensors")
        if needs:
            raise ValueError(f"an epoch (the Sun, Moon and Earth depend on the date) for {', '.join(needs)}")
        return self


class SpacecraftFile(Spacecraft, Surface):
    """A spacecraft file (``config/spacecraft/NAME.yaml``): the rigid body, wheels and magnetorquer
    limits, its surface, its sensors' datasheets and its actuators' imperfections."""

    renamed: ClassVar = {**Spacecraft.renamed, **Surface.renamed}

    sensors: Sensors = Field(default_factory=Sensors)
    actuators: Actuators = Field(default_factory=Actuators)


class ScenarioSky(Sky):
    """A scenario file (``config/scenarios/NAME.yaml``): the spacecraft it flies, by name, and its sky.
    The nodes' tuning is beside it in ``NAME.params.yaml`` (a ROS 2 ``--params-file``) and its demo
    maneuver in ``NAME.demo.yaml``."""

    spacecraft: Name = Field(description="the spacecraft flown: a file stem under config/spacecraft/")
    environment: Disturbances = Field(default_factory=Disturbances)


def resolved(sky: ScenarioSky, craft: SpacecraftFile) -> dict:
    """The data of the :class:`Shared` model of a scenario file and its spacecraft file."""
    body = set(Spacecraft.model_fields)
    return {**sky.model_dump(exclude={"spacecraft", "environment", "orbit"}), "orbit": sky.orbit.model_dump(),
            "spacecraft": craft.model_dump(include=body),
            "environment": {**sky.environment.model_dump(), **craft.model_dump(include=set(Surface.model_fields))},
            "sensors": craft.sensors.model_dump(), "actuators": craft.actuators.model_dump()}


class Demo(Schema):
    """A scenario's demo maneuver (``config/scenarios/NAME.demo.yaml``, flown by ``att-demo``)."""

    renamed: ClassVar = {"time_budget": "time_budget_s", "start_lead": "start_lead_s", "start_time": "start_time_s"}

    initial_attitude: Quaternion = Field(description="body-to-inertial quaternion [x, y, z, w] at the start")
    final_attitude: Quaternion = Field(description="body-to-inertial quaternion [x, y, z, w] at the end")
    sensor_axis: UnitVector3 = Field(description="unit body axis of the sensor the cones constrain")
    cone_names: list[Name] = Field([], max_length=64)
    cone_directions: UnitVectors = Field([], description="unit inertial direction of each cone, 3 numbers each")
    cone_half_angles_deg: list[Annotated[float, Field(gt=0.0, lt=180.0)]] = Field([], max_length=64)
    method: Annotated[str, Field(max_length=64)] = Field("", description="planning method; empty: the default")
    time_budget_s: float = number(30.0, gt=0.0, le=600.0, unit="s", meaning="planner wall time")
    start_lead_s: float = number(0.0, ge=0.0, le=86_400.0, unit="s", meaning="sim time from the request to the start")
    start_time_s: float | None = number(None, ge=0.0, unit="s", meaning="sim time of the start, the sky set for it; "
                                        "none: the request's time plus start_lead_s")

    @model_validator(mode="after")
    def _cones(self):
        n = len(self.cone_names)
        if len(self.cone_directions) != 3 * n or len(self.cone_half_angles_deg) != n:
            raise ValueError(f"one direction and one half-angle per cone name, got {n} name(s), "
                             f"{len(self.cone_directions) // 3} direction(s), {len(self.cone_half_angles_deg)} "
                             f"half-angle(s)")
        return self


class DemoFile(Schema):
    demo: Demo


class SharedSection(Schema):
    ros__parameters: Shared


class NodeSection(Schema):
    """One node's ``ros__parameters`` (typed by that node's parameter schema, not here)."""

    ros__parameters: dict[str, Any]


class ScenarioFile(Schema):
    """A scenario file: the shared section and one section per node."""

    model_config = ConfigDict(extra="allow", frozen=True, strict=True, populate_by_name=True)
    __pydantic_extra__: dict[str, NodeSection] = Field(init=False)

    shared: SharedSection = Field(alias="/**", description="the spacecraft and its sky, read by every node")


class ParametersFile(Schema):
    """A plain ROS 2 parameter file (``--params-file``): one ``ros__parameters`` mapping per node."""

    model_config = ConfigDict(extra="allow", frozen=True, strict=True)
    __pydantic_extra__: dict[str, NodeSection] = Field(init=False)
