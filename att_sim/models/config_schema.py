"""The typed schema of a spacecraft and of a scenario file (pydantic v2 models).

A scenario file is a ROS 2 parameter file whose ``/**: ros__parameters:`` section holds the
spacecraft (:class:`Spacecraft`: inertia, wheels, magnetorquers, sensors, actuator imperfections)
and its sky (epoch, orbit, field model, environment with facets, zones, frames); every other
top-level section is one node's ``ros__parameters`` (typed by the nodes' own parameter schemas).

Each key carries its unit in its name where it has one; each default and range is written once,
here and in the modules of the sensors (:mod:`att_sim.models.config_sensors`) and actuators
(:mod:`att_sim.models.config_actuators`), on the base of :mod:`att_sim.models.config_base`; a key
of an older name is refused with its new name (each model's ``renamed`` table, reported by
:mod:`att_sim.models.config_files`). Physical checks: the inertia is symmetric, positive definite
and satisfies the triangle inequalities (each principal moment at most the sum of the other two);
axes, normals and directions are unit vectors; quaternions are [x, y, z, w] of unit norm.
"""
from __future__ import annotations

from datetime import datetime
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import AfterValidator, ConfigDict, Discriminator, Field, Tag, field_validator, model_validator

from att_sim.models import epoch as epochs
from att_sim.models.config_actuators import Actuators
from att_sim.models.config_base import (
    Cone,
    Finite,
    Name,
    Quaternion,
    Schema,
    UnitVector3,
    UnitVectors,
    Vector3,
    distinct_names,
    limit,
    number,
)
from att_sim.models.config_faults import MAX_FAULTS, Fault, Hardware
from att_sim.models.config_sensors import Sensors

IDENTITY_AXES = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)


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
# the sky: orbit, environment, zones


class CircularOrbit(Schema):
    renamed: ClassVar = {"altitude": "altitude_m", "arg0": "arg0_rad"}

    type: Literal["circular"] = "circular"
    altitude_m: float = number(450e3, gt=0.0, unit="m",
                               meaning="altitude above the WGS-84 equatorial radius, 6378.137 km")
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


class Zone(Cone):
    """A keep-out (or keep-in) cone of a scenario for the sensor along ``sensor_axis``."""

    name: Name
    sensor_axis: UnitVector3 = Field(description="unit body axis of the sensor the zone constrains")
    keep_in: bool = False


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
    faults: list[Fault] = Field([], max_length=MAX_FAULTS, description="hardware faults the truth starts at their "
                                                                       "onset (att_sim.truth.faults)")
    allow_fault_injection: bool = Field(False, description="the simulator serves /simulator/inject_fault")

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

    @model_validator(mode="after")
    def _faults_on_hardware(self):
        hardware = self.hardware()
        for k, f in enumerate(self.faults):
            problem = f.problem(hardware)
            if problem:
                raise ValueError(problem.phrase(f"faults[{k}]."))
        return self

    def hardware(self) -> Hardware:
        """What of this spacecraft can fail (the counts a fault's index ranges over)."""
        s = self.sensors
        return Hardware(wheels=len(self.spacecraft.wheel_axes) // 3, star_trackers=len(s.star_trackers),
                        gyro=s.gyro is not None, magnetometer=s.magnetometer is not None,
                        tachometer=s.wheel_tachometer is not None)


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
