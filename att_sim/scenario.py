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


def shared_params(doc: dict) -> dict:
    return (doc.get("/**") or {}).get("ros__parameters") or {}


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


def load(name: str) -> Scenario:
    path = find(name)
    with open(path) as fh:
        doc = yaml.safe_load(fh) or {}
    shared = shared_params(doc)
    nodes = {k: (v or {}).get("ros__parameters", {}) for k, v in doc.items() if k != "/**"}
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
