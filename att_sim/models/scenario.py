"""Scenario files: one YAML per spacecraft/scenario under ``config/``, in ROS 2 parameter-file form.

A scenario file has a ``/**: ros__parameters:`` section shared by every node (the spacecraft and
its sky) and one section per node (``simulator``, ``controller``, ``planner``, ``recorder``); each
node reads its section from the file named by its ``scenario`` parameter. This module reads the
file without ROS, for the planner (which plans for any named spacecraft) and for tools.

A file is read by the one configuration loader (:mod:`att_sim.models.config_files`: PyYAML's safe
loader, nothing evaluated; tags, duplicate keys and alias bombs refused) and validated by the
pydantic model :class:`att_sim.models.config_schema.ScenarioFile`, which holds every key, its
default, range and unit; :func:`load` builds the :class:`Scenario` from that model. What the
model cannot know — an orbit SGP4 cannot propagate or that dips below 150 km, a date outside
IGRF-14's span — is refused in the same words, ``file:line: field.path: expected ...; found ...``.
``facets`` and ``zones`` are lists of mappings, which rcl's parameter-file parser refuses: such a
scenario is read by the nodes through ``-p scenario:=NAME`` only, never as a ``--params-file``.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace
from datetime import datetime
from pathlib import Path

import numpy as np
import yaml

from att_msgs_py import validation
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.types import Zone
from att_sim.models import config_files, disturbances
from att_sim.models import config_schema as schema
from att_sim.models import epoch as epochs
from att_sim.models import orbit as orbits
from att_sim.models.actuator_specs import ActuatorSpecs, actuators_from_model
from att_sim.models.dynamics import Spacecraft
from att_sim.models.environment import OrbitParams
from att_sim.models.geomagnetic import GeomagneticField
from att_sim.models.sensor_specs import SensorSpecs, sensors_from_model

CONFIG_ENV = "ATT_CONFIG_PATH"


def config_dirs() -> list[Path]:
    """Where scenario files are looked up: $ATT_CONFIG_PATH (os.pathsep list), the source tree's
    config/ and the installed share/att_suite/config."""
    dirs = [Path(p) for p in os.environ.get(CONFIG_ENV, "").split(os.pathsep) if p]
    dirs.append(Path(__file__).resolve().parents[2] / "config")
    import sys
    dirs.append(Path(sys.prefix) / "share" / "att_suite" / "config")
    return [d for d in dirs if d.is_dir()]


def available() -> list[str]:
    return sorted({p.stem for d in config_dirs() for p in d.glob("*.yaml")})


def find(name: str) -> Path:
    """Path of scenario ``name`` (a file stem) or of an explicit ``*.yaml`` path."""
    if name.endswith(".yaml") and Path(name).is_file():
        return Path(name)
    for d in config_dirs():
        p = d / f"{name}.yaml"
        if p.is_file():
            return p
    raise KeyError(f"unknown spacecraft/scenario '{name}' (known: {', '.join(available()) or 'none'})")


@dataclass(frozen=True)
class Scenario:
    name: str
    path: Path
    spacecraft: Spacecraft
    orbit: OrbitParams | None   # the circular orbit's parameters (None for a kepler or tle orbit)
    frame_id: str
    body_frame_id: str
    node_params: dict          # node name -> its ros__parameters (plain dict)
    epoch: datetime | None = None                  # UTC of sim time zero (None: no epoch)
    orbit_model: orbits.Orbit | None = None        # the orbit (CircularOrbit(orbit) without 'type')
    field_model: str = "dipole"                    # 'dipole' (Bruni–Celani) or 'igrf14'
    environment: dict = field(default_factory=dict)   # environment_from_params of the 'environment' group
    zones: list[Zone] = field(default_factory=list)   # zones_from_params of the 'zones' group
    sensors: SensorSpecs = field(default_factory=SensorSpecs)        # the 'sensors' group
    actuators: ActuatorSpecs = field(default_factory=ActuatorSpecs)  # the 'actuators' group


MAX_FILE_BYTES = config_files.MAX_FILE_BYTES


def read(path) -> config_files.Loaded:
    """The scenario file ``path`` read and validated (:class:`att_sim.models.config_schema.ScenarioFile`);
    :class:`att_sim.models.config_files.ConfigFileError` (code ``INVALID_CONFIG``) with every problem.
    Anchors and aliases are accepted as ``yaml.safe_dump`` writes them, their expansion bounded."""
    path = Path(path)
    data, lines = config_files.read_yaml(path, aliases=True)
    return config_files.Loaded(path, config_files.validate(path, schema.ScenarioFile, data, lines), data, lines)


class _Build:
    """The objects of a validated scenario; a check beyond the model is a problem on its line."""

    def __init__(self, loaded: config_files.Loaded):
        self.loaded = loaded
        self.shared = loaded.model.shared.ros__parameters

    def refuse(self, path: tuple, expected: str, found: str) -> config_files.ConfigFileError:
        full = ("/**", "ros__parameters", *path)
        line = next((self.loaded.lines[full[:n]] for n in range(len(full), 0, -1) if full[:n] in self.loaded.lines),
                    None)
        return config_files.ConfigFileError([config_files.Problem(str(self.loaded.path), line,
                                                                  config_files.field_path(full), expected, found)])

    def epoch(self) -> datetime | None:
        return None if self.shared.epoch is None else epochs.parse_epoch(self.shared.epoch)

    def orbit(self, epoch: datetime | None) -> orbits.Orbit:
        o = self.shared.orbit
        if o.type == "circular":
            return orbits.CircularOrbit(orbit_params(o))
        try:
            orbit = (orbits.TLEOrbit(epoch, o.line1, o.line2) if o.type == "tle" else orbits.KeplerOrbit(
                epoch, o.semi_major_axis_m, o.eccentricity, math.radians(o.inclination_deg), math.radians(o.raan_deg),
                math.radians(o.arg_perigee_deg), math.radians(o.mean_anomaly_deg)))
            orbits.check_altitude(orbit, 0.0, 0.0)       # SGP4 propagates and the orbit is above 150 km at t = 0
        except ValueError as err:
            raise self.refuse(("orbit",), f"an orbit that propagates above 150 km at the epoch ({o.type})",
                              clip(err, 200)) from None
        return orbit

    def field_model(self, epoch: datetime | None) -> str:
        model = self.shared.field_model
        try:
            GeomagneticField(model, epoch)                   # IGRF-14's span of years
        except ValueError as err:
            raise self.refuse(("field_model",), f"a field model defined at the epoch ({model})",
                              clip(err, 200)) from None
        return model

    def environment(self) -> dict:
        e = self.shared.environment
        return {"gravity_gradient": e.gravity_gradient, "solar_pressure": e.solar_pressure, "drag": e.drag,
                "drag_coefficient": e.drag_coefficient, "residual_dipole": np.asarray(e.residual_dipole_Am2, float),
                "facets": [disturbances.Facet(f.area_m2, tuple(f.normal), tuple(f.center_m), f.specular, f.diffuse)
                           for f in e.facets]}

    def zones(self) -> list[Zone]:
        out = []
        for k, z in enumerate(self.shared.zones):
            try:        # the suite's one zone check, the vectors normalised
                out.append(validation.zone(Zone(
                    name=z.name, body=z.body, sensor_axis=np.asarray(z.sensor_axis, float),
                    half_angle=math.radians(z.half_angle_deg), keep_in=z.keep_in,
                    direction=None if z.direction is None else np.asarray(z.direction, float)), f"zones[{k}]"))
            except RequestError as err:
                raise self.refuse(("zones", k), "a valid zone", clip(err.message, 200)) from None
        return out

    def scenario(self, epoch: datetime | None) -> Scenario:
        path, shared = self.loaded.path, self.shared
        orbit_model = self.orbit(epoch)
        return Scenario(
            name=path.stem, path=path, spacecraft=spacecraft_from_model(shared.spacecraft),
            orbit=orbit_model.params if isinstance(orbit_model, orbits.CircularOrbit) else None,
            frame_id=shared.frame_id, body_frame_id=shared.body_frame_id,
            node_params={k: v["ros__parameters"] for k, v in self.loaded.data.items() if k != "/**"},
            epoch=epoch, orbit_model=orbit_model, field_model=self.field_model(epoch),
            environment=self.environment(), zones=self.zones(), sensors=sensors_from_model(shared.sensors),
            actuators=actuators_from_model(shared.actuators))


def spacecraft_from_model(p: schema.Spacecraft) -> Spacecraft:
    """The rigid body of a validated ``spacecraft`` group (SI units)."""
    axes = np.asarray(p.wheel_axes, float).reshape(-1, 3)
    return Spacecraft(
        inertia=schema.inertia_matrix(p.inertia_kg_m2),
        wheel_axes=(axes / np.linalg.norm(axes, axis=1)[:, None]).T,   # listed one wheel axis after another
        wheel_inertia=p.wheel_inertia_kg_m2, wheel_torque_max=p.wheel_torque_max_Nm,
        wheel_speed_max=p.wheel_speed_max_rad_s, body_torque_max=p.torque_max_Nm, dipole_max=p.dipole_max_Am2)


def orbit_params(p: schema.CircularOrbit) -> OrbitParams:
    """The circular orbit of a validated ``orbit`` group."""
    return OrbitParams(altitude=p.altitude_m, inclination=math.radians(p.inclination_deg),
                       raan=math.radians(p.raan_deg), arg0=p.arg0_rad)


def load(name: str) -> Scenario:
    """Scenario ``name`` (a file stem or a ``*.yaml`` path): KeyError for an unknown name,
    :class:`ConfigError` (a ValueError, code ``INVALID_CONFIG``) naming the file, line and field of
    every problem of a file that is not a valid scenario."""
    build = _Build(read(find(name)))
    return build.scenario(build.epoch())


def with_epoch(scenario: Scenario, epoch: datetime) -> Scenario:
    """``scenario`` with another epoch: everything its file builds from the epoch (orbit, field
    model, environment, zones, sensors and actuators) rebuilt from that file for ``epoch``."""
    return replace(_Build(read(scenario.path)).scenario(epoch), name=scenario.name)


def load_checked(name: str) -> Scenario:
    """:func:`load` for a node's ``scenario`` parameter: every failure is one :class:`ConfigError`
    line naming the scenario or file and what is expected."""
    try:
        return load(name)
    except KeyError as exc:
        raise ConfigError(ErrorCode.INVALID_CONFIG, f"parameter 'scenario': {exc.args[0]}") from None
    except ConfigError:
        raise
    except (ValueError, TypeError, OSError, yaml.YAMLError) as exc:
        raise ConfigError(ErrorCode.INVALID_CONFIG, f"scenario '{clip(name, 200)}': {clip(exc, 300)}") from None
