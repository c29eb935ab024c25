"""Scenarios: a spacecraft in its sky, and the nodes' tuning, found by name.

A scenario ``NAME`` is ``config/scenarios/NAME.yaml`` (:class:`~att_sim.models.config_schema.ScenarioSky`:
the spacecraft it flies, by name, and its epoch, orbit, field model, environment switches and
zones), the spacecraft file it names (``config/spacecraft/<name>.yaml``,
:class:`~att_sim.models.config_schema.SpacecraftFile`: inertia, wheels, magnetorquers, surface,
sensors, actuator imperfections), the nodes' tuning beside it (``NAME.params.yaml``, a plain ROS 2
parameter file: one ``<node>: ros__parameters:`` section per node) and the demo maneuver
(``NAME.demo.yaml``). Each node reads its section of the scenario named by its ``scenario``
parameter; this module reads the files without ROS, for the nodes, the planner (which plans for any
named spacecraft) and the tools. A self-contained file (a ``/**: ros__parameters:`` section with
all of it, then the node sections; :class:`~att_sim.models.config_schema.ScenarioFile`) is read too.

Every file is read by the one configuration loader (:mod:`att_sim.models.config_files`: PyYAML's
safe loader, nothing evaluated; tags, duplicate keys and alias bombs refused) and validated by its
pydantic model, which holds every key, its default, range and unit; the scenario and its spacecraft
resolve into :class:`~att_sim.models.config_schema.Shared`, and :func:`load` builds the
:class:`Scenario` from it. What the models cannot know — an orbit SGP4 cannot propagate or that dips
below 150 km, a date outside IGRF-14's span — is refused in the same words,
``file:line: field.path: expected ...; found ...``.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace
from datetime import datetime
from pathlib import Path

import numpy as np
import yaml
from pydantic import ValidationError

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


SCENARIOS, SPACECRAFT = "scenarios", "spacecraft"      # the folders of a configuration directory
PARAMS_SUFFIX, DEMO_SUFFIX = ".params.yaml", ".demo.yaml"


def _stems(folder: Path) -> set[str]:
    return {p.name[:-len(".yaml")] for p in folder.glob("*.yaml") if "." not in p.name[:-len(".yaml")]}


def available() -> list[str]:
    """The scenario names: ``scenarios/NAME.yaml`` and the self-contained ``NAME.yaml`` of each config directory."""
    return sorted({n for d in config_dirs() for n in _stems(d / SCENARIOS) | _stems(d)})


def find(name: str) -> Path:
    """Path of scenario ``name`` (``scenarios/NAME.yaml``, else a self-contained ``NAME.yaml``, of the
    first config directory holding one) or of an explicit ``*.yaml`` path."""
    if name.endswith(".yaml") and Path(name).is_file():
        return Path(name)
    for d in config_dirs():
        for p in (d / SCENARIOS / f"{name}.yaml", d / f"{name}.yaml"):
            if p.is_file():
                return p
    raise KeyError(f"unknown spacecraft/scenario '{name}' (known: {', '.join(available()) or 'none'})")


def find_spacecraft(name: str, beside: Path | None = None) -> Path:
    """Path of spacecraft ``name``: ``spacecraft/NAME.yaml`` of the config directory of the scenario
    file ``beside`` first, then of every config directory; KeyError naming the known ones."""
    roots = ([beside.resolve().parent.parent] if beside is not None else []) + config_dirs()
    for d in roots:
        p = d / SPACECRAFT / f"{name}.yaml"
        if p.is_file():
            return p
    known = sorted({n for d in roots for n in _stems(d / SPACECRAFT)})
    raise KeyError(f"unknown spacecraft '{name}' (known: {', '.join(known) or 'none'})")


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
    spacecraft_path: Path | None = None            # config/spacecraft/NAME.yaml (None: a self-contained file)
    params_path: Path | None = None                # the file of node_params (the scenario's own when None)
    faults: tuple = ()                             # FaultSpec: the hardware faults the truth starts
    allow_fault_injection: bool = False            # the simulator serves /simulator/inject_fault

    @property
    def node_params_path(self) -> Path:
        """The file the nodes' sections come from (named in a refused parameter)."""
        return self.params_path or self.path


MAX_FILE_BYTES = config_files.MAX_FILE_BYTES


@dataclass(frozen=True)
class Files:
    """A scenario read and validated: its resolved spacecraft and sky, the node sections, and where
    each came from (``lines``: field path of :class:`att_sim.models.config_schema.Shared` → (file, line))."""

    path: Path
    shared: schema.Shared
    lines: dict
    node_params: dict
    spacecraft_path: Path | None = None
    params_path: Path | None = None
    demo_path: Path | None = None


def read(path) -> Files:
    """The scenario file ``path`` read and validated with the files it names; a
    :class:`att_sim.models.config_files.ConfigFileError` (code ``INVALID_CONFIG``) with every problem.

    A scenario file of ``scenarios/`` (:class:`~att_sim.models.config_schema.ScenarioSky`) names its
    spacecraft (``spacecraft/NAME.yaml``, :class:`~att_sim.models.config_schema.SpacecraftFile`);
    the nodes' sections are in ``NAME.params.yaml`` beside it (a ROS 2 ``--params-file``) and the
    demo maneuver in ``NAME.demo.yaml``, both optional. A self-contained file
    (:class:`~att_sim.models.config_schema.ScenarioFile`: a ``/**: ros__parameters:`` section and the
    node sections) holds all of it. Anchors and aliases are accepted as ``yaml.safe_dump`` writes
    them, their expansion bounded."""
    path = Path(path)
    data, lines = config_files.read_yaml(path, aliases=True)
    if "/**" in data or "spacecraft" not in data:
        model = config_files.validate(path, schema.ScenarioFile, data, lines)
        prefix = ("/**", "ros__parameters")
        own = {k[2:]: (path, v) for k, v in lines.items() if k[:2] == prefix}
        return Files(path, model.shared.ros__parameters, own,
                     {k: v["ros__parameters"] for k, v in data.items() if k != "/**"})
    sky = config_files.validate(path, schema.ScenarioSky, data, lines)
    try:
        craft_path = find_spacecraft(sky.spacecraft, path)
    except KeyError as err:
        raise config_files.ConfigFileError([config_files.Problem(
            str(path), lines.get(("spacecraft",)), "spacecraft", "the name of a spacecraft file",
            f"{clip(repr(sky.spacecraft), 80)}: {clip(err.args[0], 200)}")]) from None
    craft_data, craft_lines = config_files.read_yaml(craft_path, aliases=True)
    craft = config_files.validate(craft_path, schema.SpacecraftFile, craft_data, craft_lines)
    origin = {k: (path, v) for k, v in lines.items()}
    body = set(schema.Spacecraft.model_fields)
    for k, v in craft_lines.items():
        if not k:
            continue
        key = (("spacecraft",) if k[0] in body else ("environment",) if k[0] in schema.Surface.model_fields
               else ()) + k
        origin[key] = (craft_path, v)
    composed = schema.resolved(sky, craft)
    try:
        shared = schema.Shared.model_validate(composed)
    except ValidationError as exc:          # what the two files say together: reported on the scenario's lines
        flat = {k: v for k, (_, v) in origin.items()}
        raise config_files.ConfigFileError(config_files.problems_of(exc, schema.Shared, composed, flat,
                                                                    str(path))) from None
    params_path, demo_path = path.with_name(path.stem + PARAMS_SUFFIX), path.with_name(path.stem + DEMO_SUFFIX)
    nodes = {}
    if params_path.is_file():
        p_data, p_lines = config_files.read_yaml(params_path)
        config_files.validate(params_path, schema.ParametersFile, p_data, p_lines)
        nodes = {k: v["ros__parameters"] for k, v in p_data.items()}
    if demo_path.is_file():
        d_data, d_lines = config_files.read_yaml(demo_path)
        nodes["demo"] = config_files.validate(demo_path, schema.DemoFile, d_data, d_lines).demo.model_dump()
    return Files(path, shared, origin, nodes, craft_path, params_path if params_path.is_file() else None,
                 demo_path if demo_path.is_file() else None)


class _Build:
    """The objects of a validated scenario; a check beyond the model is a problem on its line."""

    def __init__(self, files: Files):
        self.files = files
        self.shared = files.shared

    def refuse(self, path: tuple, expected: str, found: str) -> config_files.ConfigFileError:
        where = next((self.files.lines[path[:n]] for n in range(len(path), 0, -1) if path[:n] in self.files.lines),
                     (self.files.path, None))
        return config_files.ConfigFileError([config_files.Problem(str(where[0]), where[1],
                                                                  config_files.field_path(path), expected, found)])

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
        path, shared, files = self.files.path, self.shared, self.files
        orbit_model = self.orbit(epoch)
        return Scenario(
            name=path.stem, path=path, spacecraft=spacecraft_from_model(shared.spacecraft),
            orbit=orbit_model.params if isinstance(orbit_model, orbits.CircularOrbit) else None,
            frame_id=shared.frame_id, body_frame_id=shared.body_frame_id,
            node_params=files.node_params, spacecraft_path=files.spacecraft_path, params_path=files.params_path,
            epoch=epoch, orbit_model=orbit_model, field_model=self.field_model(epoch),
            environment=self.environment(), zones=self.zones(), sensors=sensors_from_model(shared.sensors),
            actuators=actuators_from_model(shared.actuators), faults=tuple(f.spec() for f in shared.faults),
            allow_fault_injection=shared.allow_fault_injection)


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


def refusal(name: str) -> str | None:
    """Why scenario ``name`` cannot be loaded, in one sentence, or None when it can: the
    :func:`load` message of a scenario not shipped or of a file that is not a valid scenario (its
    line and what is expected). For tools that refuse their arguments before any work starts."""
    try:
        load(name)
    except KeyError as err:
        return err.args[0]
    except ConfigError as err:
        return str(err)
    return None


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
