"""Scenario files: one YAML per spacecraft/scenario under ``config/``, in ROS 2 parameter-file form.

A scenario file has a ``/**: ros__parameters:`` section shared by every node (the spacecraft and
its orbit) and one section per node (``simulator``, ``controller``, ``planner``, ``recorder``); each
node reads its section from the file named by its ``scenario`` parameter. This module reads the
shared part without ROS, for the planner (which plans for any named spacecraft) and for tools.
Files are read with :func:`att_sim.models.config_files.read_yaml` (PyYAML's safe loader: nothing in them
is ever evaluated; tags, duplicate keys and alias bombs are refused).

Keys of the shared part: ``frame_id``, ``body_frame_id``, ``spacecraft``, ``orbit`` and the real
sky's (files without them fly the circular orbit and tilted dipole, the gravity gradient
only as the simulator's parameter): ``epoch`` (ISO 8601 UTC, sim time zero), ``orbit.type``
(``circular``, ``kepler``, ``tle``: :func:`att_sim.models.orbit.orbit_from_mapping`), ``field_model``
(``dipole`` or ``igrf14``), ``environment`` (disturbance switches, residual dipole, facets:
:func:`environment_from_params`) and ``zones`` (:func:`zones_from_params`). Every key is checked;
an unknown one is refused (a typo must not silently mean a default). ``facets`` and ``zones`` are
lists of mappings, which rcl's parameter-file parser refuses: such a scenario is read by the nodes
through ``-p scenario:=NAME`` only, never as a ``--params-file``.
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
from att_msgs_py.types import ZONE_BODIES, Zone
from att_sim.models import config_files, disturbances
from att_sim.models import config_schema as schema
from att_sim.models import epoch as epochs
from att_sim.models import orbit as orbits
from att_sim.models.actuator_specs import ActuatorSpecs, actuators_from_params
from att_sim.models.dynamics import Spacecraft
from att_sim.models.environment import OrbitParams
from att_sim.models.geomagnetic import GeomagneticField
from att_sim.models.sensor_specs import SensorSpecs, sensors_from_params

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


SPACECRAFT_KEYS = ("inertia", "torque_max", "wheel_axes", "wheel_inertia", "wheel_torque_max", "wheel_speed_max",
                   "dipole_max")
LIMIT_KEYS = ("torque_max", "wheel_torque_max", "wheel_speed_max", "dipole_max")   # > 0 (.inf: no limit)
ORBIT_KEYS = ("altitude", "inclination_deg", "raan_deg", "arg0")
SHARED_KEYS = ("frame_id", "body_frame_id", "spacecraft", "orbit", "epoch", "field_model", "environment", "zones",
               "sensors", "actuators")
FIELD_MODELS = ("dipole", "igrf14")
ENVIRONMENT_KEYS = ("gravity_gradient", "solar_pressure", "drag", "drag_coefficient", "residual_dipole", "facets")
ZONE_KEYS = ("name", "body", "sensor_axis", "half_angle_deg", "keep_in", "direction")
UNIT_TOLERANCE = 1e-3          # |‖v‖ − 1| accepted for a unit vector of a file (then normalised)
DEFAULT_DRAG_COEFFICIENT = schema.Environment.model_fields["drag_coefficient"].default
MAX_FILE_BYTES = config_files.MAX_FILE_BYTES


def shared_params(doc: dict) -> dict:
    return (doc.get("/**") or {}).get("ros__parameters") or {}


def _invalid(path, message: str) -> ConfigError:
    return ConfigError(ErrorCode.INVALID_CONFIG, f"scenario file {clip(path, 200)}: {message}")


def _refuse_unknown(path, group: dict, known: tuple, label: str) -> None:
    """ConfigError when ``group`` has a key outside ``known`` (a typo must not silently mean a default)."""
    unknown = sorted(str(k) for k in set(group) - set(known))
    if unknown:
        raise _invalid(path, f"{label} has unknown key(s) {clip(', '.join(unknown), 120)} (known: {', '.join(known)})")


def _as_float(v) -> float | None:
    """``v`` as a float if it is a YAML number (or a string that reads as one), else None."""
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        return None
    try:
        return float(v)
    except ValueError:
        return None


def _numbers(path, group: dict, key: str, label: str, default=None) -> np.ndarray:
    """``group[key]`` (or ``default``) as a float array of finite numbers."""
    v = group.get(key, default)
    values = [_as_float(x) for x in (v if isinstance(v, list) else [v])]
    if not all(x is not None and math.isfinite(x) for x in values):
        raise _invalid(path, f"{label} must be {'a list of finite numbers' if isinstance(v, list) else 'a number'}, "
                             f"got {clip(repr(v), 80)}")
    return np.asarray(values, float)


def check_spacecraft_group(path, p) -> None:
    """The ``spacecraft`` group of a scenario: known keys, numbers, sizes, positive limits."""
    if not isinstance(p, dict):
        raise _invalid(path, f"'/**: ros__parameters: spacecraft' must be a mapping, got {type(p).__name__}")
    _refuse_unknown(path, p, SPACECRAFT_KEYS, "spacecraft")
    if "inertia" not in p:
        raise _invalid(path, "spacecraft.inertia is missing (3 principal or 9 row-major numbers, kg m^2)")
    inertia = _numbers(path, p, "inertia", "spacecraft.inertia")
    if not isinstance(p["inertia"], list) or inertia.size not in (3, 9):
        raise _invalid(path, f"spacecraft.inertia must be 3 principal or 9 row-major numbers (kg m^2), got "
                             f"{inertia.size if isinstance(p['inertia'], list) else 'a single number'}")
    for key in LIMIT_KEYS:
        v = p.get(key, math.inf)
        if not ((_as_float(v) or 0.0) > 0):
            raise _invalid(path, f"spacecraft.{key} must be a positive number (.inf: no limit), "
                                 f"got {clip(repr(v), 80)}")
    axes = _numbers(path, p, "wheel_axes", "spacecraft.wheel_axes", [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])
    if not isinstance(p.get("wheel_axes", []), list) or axes.size % 3:
        raise _invalid(path, f"spacecraft.wheel_axes must list 3 numbers per wheel, got {axes.size} numbers")
    norms = np.linalg.norm(axes.reshape(-1, 3), axis=1)
    if np.any(np.abs(norms - 1.0) > 1e-3):
        raise _invalid(path, f"spacecraft.wheel_axes[{int(np.argmax(np.abs(norms - 1.0)))}] is not a unit vector")
    wheel_inertia = float(_numbers(path, p, "wheel_inertia", "spacecraft.wheel_inertia", 0.0)[0])
    if wheel_inertia < 0 or (axes.size and wheel_inertia == 0):
        raise _invalid(path, f"spacecraft.wheel_inertia must be positive when there are wheels, got {wheel_inertia:g}")


def check_document(path, doc) -> dict:
    """The shared parameters of a parsed scenario file (ConfigError naming what is wrong)."""
    if not isinstance(doc, dict):
        raise _invalid(path, f"expected a mapping of ROS 2 parameter sections, got "
                             f"{'an empty file' if doc is None else type(doc).__name__}")
    for node, section in doc.items():
        if not (isinstance(section, dict) and isinstance(section.get("ros__parameters"), dict)):
            raise _invalid(path, f"section '{clip(node, 80)}' must be a mapping with a 'ros__parameters' mapping")
    if "/**" not in doc:
        raise _invalid(path, "no '/**: ros__parameters:' section with the spacecraft: not a scenario file")
    shared = shared_params(doc)
    if "spacecraft" not in shared:
        raise _invalid(path, "no 'spacecraft' group in '/**: ros__parameters': not a scenario file")
    _refuse_unknown(path, shared, SHARED_KEYS, "'/**: ros__parameters'")
    check_spacecraft_group(path, shared["spacecraft"])
    orbit = shared.get("orbit", {})
    if not isinstance(orbit, dict):
        raise _invalid(path, f"orbit must be a mapping, got {type(orbit).__name__}")
    if orbit.get("type", "circular") == "circular":
        if set(orbit) - {*ORBIT_KEYS, "type"}:
            raise _invalid(path, f"orbit must be a mapping with keys among type, {', '.join(ORBIT_KEYS)}")
        for key in set(orbit) - {"type"}:
            _numbers(path, orbit, key, f"orbit.{key}")
        if _as_float(orbit.get("altitude", 1.0)) <= 0:
            raise _invalid(path, f"orbit.altitude must be positive (m), got {orbit['altitude']!r}")
    for key in ("frame_id", "body_frame_id"):
        v = shared.get(key, "x")
        if not (isinstance(v, str) and v and len(v) <= 128 and v.isprintable()):
            raise _invalid(path, f"{key} must be a non-empty printable name of at most 128 characters")
    return shared


def _attached(path, what: str, err: ValueError) -> ConfigError:
    """A model's ValueError sentence as the file's ConfigError (``what``: the group it came from)."""
    sentence = str(err)
    return _invalid(path, sentence if sentence.startswith(what) else f"{what}: {sentence}")


def epoch_from_params(path, shared: dict) -> datetime | None:
    if "epoch" not in shared:
        return None
    try:
        return epochs.parse_epoch(shared["epoch"])
    except ValueError as err:
        raise _attached(path, "epoch", err) from None


def orbit_model_from_params(path, shared: dict, epoch: datetime | None) -> orbits.Orbit:
    """The ``orbit`` group as an :class:`att_sim.models.orbit.Orbit` (circular: the circular orbit's keys
    and defaults)."""
    p = shared.get("orbit", {})
    if p.get("type", "circular") == "circular":
        return orbits.CircularOrbit(orbit_from_params(p))
    try:
        orbit = orbits.orbit_from_mapping(p, epoch)
        orbits.check_altitude(orbit, 0.0, 0.0)          # SGP4 propagates and the orbit is above 150 km at t = 0
    except ValueError as err:
        raise _attached(path, "orbit", err) from None
    return orbit


def field_model_from_params(path, shared: dict, epoch: datetime | None) -> str:
    model = shared.get("field_model", "dipole")
    if model not in FIELD_MODELS:
        raise _invalid(path, f"field_model must be one of {', '.join(FIELD_MODELS)}, got {clip(repr(model), 80)}")
    if model == "igrf14" and epoch is None:
        raise _invalid(path, "field_model igrf14 needs the scenario's epoch (the field and the Earth's rotation "
                             "depend on the date)")
    try:
        GeomagneticField(model, epoch)                   # IGRF-14's span of years
    except ValueError as err:
        raise _attached(path, "field_model", err) from None
    return model


def _flag(path, group: dict, key: str, label: str) -> bool:
    v = group.get(key, False)
    if not isinstance(v, bool):
        raise _invalid(path, f"{label} must be true or false, got {clip(repr(v), 80)}")
    return v


def _vector3(path, group: dict, key: str, label: str, unit: bool = False) -> np.ndarray:
    v = _numbers(path, group, key, label)
    if not isinstance(group[key], list) or v.size != 3:
        raise _invalid(path, f"{label} must be a list of 3 numbers, got {clip(repr(group[key]), 80)}")
    if unit:
        norm = float(np.linalg.norm(v))
        if abs(norm - 1.0) > UNIT_TOLERANCE:
            raise _invalid(path, f"{label} must be a unit vector (norm within {UNIT_TOLERANCE:g} of 1), got norm "
                                 f"{norm:.6g}")
        v = v / norm
    return v


def environment_from_params(path, shared: dict, epoch: datetime | None) -> dict:
    """The ``environment`` group, checked: ``gravity_gradient``, ``solar_pressure``, ``drag`` (bools,
    default false), ``drag_coefficient`` (> 0, default 2.2), ``residual_dipole`` (A m², body, default
    zero) and ``facets`` (:func:`att_sim.models.disturbances.facets_from_params`; needed by pressure and
    drag). Solar pressure needs the epoch (the Sun's position)."""
    p = shared.get("environment", {})
    if not isinstance(p, dict):
        raise _invalid(path, f"environment must be a mapping, got {type(p).__name__}")
    _refuse_unknown(path, p, ENVIRONMENT_KEYS, "environment")
    out = {key: _flag(path, p, key, f"environment.{key}") for key in ("gravity_gradient", "solar_pressure", "drag")}
    cd = float(_numbers(path, p, "drag_coefficient", "environment.drag_coefficient", DEFAULT_DRAG_COEFFICIENT)[0])
    if not 0.0 < cd <= 10.0:
        raise _invalid(path, f"environment.drag_coefficient must be in (0, 10], got {cd:g}")
    out["drag_coefficient"] = cd
    out["residual_dipole"] = (_vector3(path, p, "residual_dipole", "environment.residual_dipole")
                              if "residual_dipole" in p else np.zeros(3))
    facets = p.get("facets", [])
    if not isinstance(facets, list):
        raise _invalid(path, f"environment.facets must be a list of facet mappings, got {type(facets).__name__}")
    try:
        out["facets"] = disturbances.facets_from_params(facets)
    except ValueError as err:
        raise _attached(path, "environment.facets", err) from None
    for key in ("solar_pressure", "drag"):
        if out[key] and not out["facets"]:
            raise _invalid(path, f"environment.{key} needs environment.facets (the surfaces it acts on)")
    if out["solar_pressure"] and epoch is None:
        raise _invalid(path, "environment.solar_pressure needs the scenario's epoch (the Sun's position)")
    return out


def zones_from_params(path, shared: dict, epoch: datetime | None) -> list[Zone]:
    """The ``zones`` group, checked, as :class:`att_msgs_py.types.Zone` (``sensor_axis`` unit in body
    axes, ``half_angle`` rad, ``direction`` unit inertial only for body ``inertial``).
    ``half_angle_deg`` is in (0, 180) — for ``earth_limb`` it is the margin beyond the limb, in
    [0, 90) (:func:`att_msgs_py.validation.zone`); ``sun`` and ``moon`` need the epoch."""
    p = shared.get("zones", [])
    if not isinstance(p, list):
        raise _invalid(path, f"zones must be a list of zone mappings, got {type(p).__name__}")
    zones, names = [], set()
    for k, z in enumerate(p):
        label = f"zones[{k}]"
        if not isinstance(z, dict):
            raise _invalid(path, f"{label} must be a mapping with keys among {', '.join(ZONE_KEYS)}")
        _refuse_unknown(path, z, ZONE_KEYS, label)
        missing = [x for x in ("name", "body", "sensor_axis", "half_angle_deg") if x not in z]
        if missing:
            raise _invalid(path, f"{label} needs key(s) {', '.join(missing)}")
        name = z["name"]
        if not (isinstance(name, str) and name and len(name) <= 128 and name.isprintable()):
            raise _invalid(path, f"{label}.name must be a non-empty printable name of at most 128 characters")
        if name in names:
            raise _invalid(path, f"{label}.name '{name}' is used by an earlier zone")
        names.add(name)
        body = z["body"]
        if body not in ZONE_BODIES:
            raise _invalid(path, f"{label}.body must be one of {', '.join(ZONE_BODIES)}, got {clip(repr(body), 80)}")
        if body in ("sun", "moon") and epoch is None:
            raise _invalid(path, f"{label}.body {body} needs the scenario's epoch (the {body}'s position)")
        axis = _vector3(path, z, "sensor_axis", f"{label}.sensor_axis", unit=True)
        angle = float(_numbers(path, z, "half_angle_deg", f"{label}.half_angle_deg")[0])
        limb = body == "earth_limb"
        if not ((0.0 <= angle < 90.0) if limb else (0.0 < angle < 180.0)):
            what = "the margin beyond the Earth limb, in [0, 90)" if limb else "the cone half-angle, in (0, 180)"
            raise _invalid(path, f"{label}.half_angle_deg ({what} deg) got {angle:g}")
        keep_in = _flag(path, z, "keep_in", f"{label}.keep_in")
        if (body == "inertial") != ("direction" in z):
            need = "needed for" if body == "inertial" else "only for"
            raise _invalid(path, f"{label}.direction (a unit inertial vector) is {need} body inertial")
        direction = _vector3(path, z, "direction", f"{label}.direction", unit=True) if body == "inertial" else None
        try:       # the suite's one zone check (half-angle (0, 180) deg; earth_limb margin [0, 90) deg)
            zones.append(validation.zone(Zone(name=name, body=body, sensor_axis=axis, half_angle=math.radians(angle),
                                              keep_in=keep_in, direction=direction), label))
        except RequestError as err:
            raise _invalid(path, err.message) from None
    return zones


def sensors_and_actuators(path, shared: dict, epoch: datetime | None) -> tuple[SensorSpecs, ActuatorSpecs]:
    """The ``sensors`` (:mod:`att_sim.models.sensor_specs`) and ``actuators`` (:mod:`att_sim.truth.actuators`)
    groups, checked; Sun and Moon exclusions and sun sensors need the epoch."""
    try:
        sensors = sensors_from_params(shared.get("sensors", {}), epoch is not None)
    except ValueError as err:
        raise _attached(path, "sensors", err) from None
    try:
        actuators = actuators_from_params(shared.get("actuators", {}))
    except ValueError as err:
        raise _attached(path, "actuators", err) from None
    return sensors, actuators


def spacecraft_from_params(p: dict) -> Spacecraft:
    """Build a Spacecraft from the ``spacecraft`` parameter group (SI units)."""
    inertia = np.asarray(p["inertia"], float)
    inertia = np.diag(inertia) if inertia.size == 3 else inertia.reshape(3, 3)
    axes = np.asarray(p.get("wheel_axes", np.eye(3).ravel().tolist()), float)
    n = axes.size // 3
    inf = float("inf")
    return Spacecraft(
        inertia=inertia,
        wheel_axes=axes.reshape(n, 3).T,          # listed one wheel axis (3 numbers) after another
        wheel_inertia=float(p.get("wheel_inertia", 0.0)),
        wheel_torque_max=float(p.get("wheel_torque_max", inf)),
        wheel_speed_max=float(p.get("wheel_speed_max", inf)),
        body_torque_max=float(p.get("torque_max", inf)),
        dipole_max=float(p.get("dipole_max", inf)),
    )


def orbit_from_params(p: dict) -> OrbitParams:
    """The circular orbit of an ``orbit`` group, defaults from :class:`att_sim.models.config_schema.CircularOrbit`."""
    d = {key: info.default for key, info in schema.CircularOrbit.model_fields.items()}
    return OrbitParams(altitude=float(p.get("altitude", d["altitude_m"])),
                       inclination=math.radians(float(p.get("inclination_deg", d["inclination_deg"]))),
                       raan=math.radians(float(p.get("raan_deg", d["raan_deg"]))),
                       arg0=float(p.get("arg0", d["arg0_rad"])))


def read_document(path: Path) -> dict:
    """The parsed YAML of a scenario file, read by :func:`att_sim.models.config_files.read_yaml` (size
    cap before parsing; tags and duplicate keys refused; aliases as ``yaml.safe_dump`` writes them,
    their expansion bounded); ConfigError if it cannot be read or parsed."""
    try:
        return config_files.read_yaml(Path(path), aliases=True)[0]
    except config_files.ConfigFileError as err:
        p = err.problems[0]
        where = f"line {p.line}: " if p.line else ""
        if p.expected == "valid YAML":
            raise _invalid(path, f"is not valid YAML ({where}{clip(p.found, 200)})") from None
        if p.expected in ("a readable file", "UTF-8 text"):
            raise _invalid(path, f"cannot be read ({where}{p.expected} expected, found {clip(p.found, 120)})") from None
        field = f"{p.field}: " if p.field else ""
        raise _invalid(path, f"{where}{field}expected {p.expected}; found {clip(p.found, 120)}") from None


def load(name: str) -> Scenario:
    """Scenario ``name`` (a file stem or a ``*.yaml`` path): KeyError for an unknown name,
    :class:`ConfigError` (a ValueError) naming the file and field for a file that is not a valid
    scenario."""
    path = find(name)
    doc = read_document(path)
    shared = check_document(path, doc)
    nodes = {k: v["ros__parameters"] for k, v in doc.items() if k != "/**"}
    epoch = epoch_from_params(path, shared)
    orbit_model = orbit_model_from_params(path, shared, epoch)
    field_model = field_model_from_params(path, shared, epoch)
    environment = environment_from_params(path, shared, epoch)
    zones = zones_from_params(path, shared, epoch)
    sensors, actuators = sensors_and_actuators(path, shared, epoch)
    return Scenario(
        name=path.stem, path=path,
        spacecraft=spacecraft_from_params(shared["spacecraft"]),
        orbit=orbit_model.params if isinstance(orbit_model, orbits.CircularOrbit) else None,
        frame_id=shared.get("frame_id", "eci"), body_frame_id=shared.get("body_frame_id", "body"),
        node_params=nodes, epoch=epoch, orbit_model=orbit_model, field_model=field_model, environment=environment,
        zones=zones, sensors=sensors, actuators=actuators)


def with_epoch(scenario: Scenario, epoch: datetime) -> Scenario:
    """``scenario`` with another epoch: everything its file builds from the epoch (orbit, field
    model, environment, zones, sensors and actuators) rebuilt from that file for ``epoch``."""
    doc = read_document(scenario.path)
    shared = check_document(scenario.path, doc)
    orbit_model = orbit_model_from_params(scenario.path, shared, epoch)
    sensors, actuators = sensors_and_actuators(scenario.path, shared, epoch)
    return replace(scenario, epoch=epoch, orbit_model=orbit_model,
                   field_model=field_model_from_params(scenario.path, shared, epoch),
                   environment=environment_from_params(scenario.path, shared, epoch),
                   zones=zones_from_params(scenario.path, shared, epoch), sensors=sensors, actuators=actuators)


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
