"""Scenario files: one YAML per spacecraft/scenario under ``config/``, in ROS 2 parameter-file form.

A scenario file has a ``/**: ros__parameters:`` section shared by every node (the spacecraft and
its orbit) and one section per node (``simulator``, ``controller``, ``planner``, ``recorder``), so
the same file is passed to each node with ``--ros-args --params-file``. This module reads the
shared part without ROS, for the planner (which plans for any named spacecraft) and for tools.
Files are read with ``yaml.safe_load`` only: nothing in them is ever evaluated.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_sim.dynamics import Spacecraft
from att_sim.environment import OrbitParams

CONFIG_ENV = "ATT_CONFIG_PATH"


def config_dirs() -> list[Path]:
    """Where scenario files are looked up: $ATT_CONFIG_PATH (os.pathsep list), the source tree's
    config/ and the installed share/att_suite/config."""
    dirs = [Path(p) for p in os.environ.get(CONFIG_ENV, "").split(os.pathsep) if p]
    dirs.append(Path(__file__).resolve().parents[1] / "config")
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
    orbit: OrbitParams
    frame_id: str
    body_frame_id: str
    node_params: dict          # node name -> its ros__parameters (plain dict)


SPACECRAFT_KEYS = ("inertia", "torque_max", "wheel_axes", "wheel_inertia", "wheel_torque_max", "wheel_speed_max",
                   "dipole_max")
LIMIT_KEYS = ("torque_max", "wheel_torque_max", "wheel_speed_max", "dipole_max")   # > 0 (.inf: no limit)
ORBIT_KEYS = ("altitude", "inclination_deg", "raan_deg", "arg0")
MAX_FILE_BYTES = 1_000_000     # a scenario file is a few kB


def shared_params(doc: dict) -> dict:
    return (doc.get("/**") or {}).get("ros__parameters") or {}


def _invalid(path, message: str) -> ConfigError:
    return ConfigError(ErrorCode.INVALID_CONFIG, f"scenario file {clip(path, 200)}: {message}")


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
    unknown = sorted(set(p) - set(SPACECRAFT_KEYS))
    if unknown:
        raise _invalid(path, f"spacecraft has unknown key(s) {clip(', '.join(map(str, unknown)), 120)} "
                             f"(known: {', '.join(SPACECRAFT_KEYS)})")
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
    check_spacecraft_group(path, shared["spacecraft"])
    orbit = shared.get("orbit", {})
    if not isinstance(orbit, dict) or set(orbit) - set(ORBIT_KEYS):
        raise _invalid(path, f"orbit must be a mapping with keys among {', '.join(ORBIT_KEYS)}")
    for key in orbit:
        _numbers(path, orbit, key, f"orbit.{key}")
    if _as_float(orbit.get("altitude", 1.0)) <= 0:
        raise _invalid(path, f"orbit.altitude must be positive (m), got {orbit['altitude']!r}")
    for key in ("frame_id", "body_frame_id"):
        v = shared.get(key, "x")
        if not (isinstance(v, str) and v and len(v) <= 128 and v.isprintable()):
            raise _invalid(path, f"{key} must be a non-empty printable name of at most 128 characters")
    return shared


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
    return OrbitParams(altitude=float(p.get("altitude", 450e3)),
                       inclination=math.radians(float(p.get("inclination_deg", 87.0))),
                       raan=math.radians(float(p.get("raan_deg", 0.0))),
                       arg0=float(p.get("arg0", 0.0)))


def read_document(path: Path):
    """The parsed YAML of a scenario file (ConfigError if it cannot be read or parsed)."""
    try:
        if path.stat().st_size > MAX_FILE_BYTES:
            raise _invalid(path, f"{path.stat().st_size} bytes; a scenario file has at most {MAX_FILE_BYTES}")
        with open(path, encoding="utf-8") as fh:
            return yaml.safe_load(fh)
    except (OSError, UnicodeDecodeError) as exc:
        raise _invalid(path, f"cannot be read ({clip(exc, 200)})") from None
    except yaml.YAMLError as exc:
        raise _invalid(path, f"is not valid YAML ({clip(' '.join(str(exc).split()), 200)})") from None


def load(name: str) -> Scenario:
    """Scenario ``name`` (a file stem or a ``*.yaml`` path): KeyError for an unknown name,
    :class:`ConfigError` (a ValueError) naming the file and field for a file that is not a valid
    scenario."""
    path = find(name)
    doc = read_document(path)
    shared = check_document(path, doc)
    nodes = {k: v["ros__parameters"] for k, v in doc.items() if k != "/**"}
    return Scenario(
        name=path.stem, path=path,
        spacecraft=spacecraft_from_params(shared["spacecraft"]),
        orbit=orbit_from_params(shared.get("orbit", {})),
        frame_id=shared.get("frame_id", "eci"), body_frame_id=shared.get("body_frame_id", "body"),
        node_params=nodes)


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
