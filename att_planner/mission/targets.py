"""Target lists of a mission: YAML files of what to observe and for how long.

Two kinds, one file each (``config/targets/``; read with ``yaml.safe_load`` only)::

    kind: inertial                 # an observatory's sources: J2000 right ascension and declination
    scenario: leo_observatory      # the spacecraft and sky they are observed from
    roll_reference: [0, 0, 1]      # inertial direction the roll axis is kept nearest (default: celestial north)
    targets:
      - {name: crab, ra_deg: 83.633, dec_deg: 22.015, dwell_s: 600}

    kind: ground                   # Earth observation: sites tracked through the dwell
    scenario: leo_observatory
    min_elevation_deg: 30          # a site is observable while the spacecraft is this high in its sky
    targets:
      - {name: toulouse, lat_deg: 43.60, lon_deg: 1.44, alt_m: 150, dwell_s: 60}

An inertial source becomes a schedule target attitude (:func:`pointing_attitude`): the scenario's
sensor axis on the source, the body axis after it (x → z → y → x) as near ``roll_reference`` as the
pointing allows (the vernal equinox where the source lies within a degree of the reference). A
ground site stays a site: the pointing modes track it through its dwell. Every field is
checked; a bad file is refused with a :class:`~att_msgs_py.errors.ConfigError` naming the file,
the target and the field.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_msgs_py.limits import MAX_TARGETS  # as a PlanSchedule request
from att_planner.mission import schema
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.config_schema import declared

KINDS = {"inertial": ("name", "ra_deg", "dec_deg", "dwell_s"),
         "ground": ("name", "lat_deg", "lon_deg", "alt_m", "dwell_s")}
FILE_KEYS = {"inertial": ("kind", "scenario", "roll_reference", "targets"),
             "ground": ("kind", "scenario", "min_elevation_deg", "targets")}
CELESTIAL_NORTH = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Source:
    """An inertial target: its unit direction (GCRS ≈ J2000) and its dwell (s)."""

    name: str
    direction: np.ndarray
    dwell: float


@dataclass(frozen=True)
class Site:
    """A ground target: geodetic latitude and longitude (rad), altitude (m) and its dwell (s)."""

    name: str
    latitude: float
    longitude: float
    altitude: float
    dwell: float


@dataclass(frozen=True)
class TargetList:
    path: Path
    kind: str
    scenario: str
    targets: list                        # Source or Site, in file order
    roll_reference: np.ndarray = field(default_factory=CELESTIAL_NORTH.copy)
    min_elevation: float = 0.0           # rad (ground)

    def dwell(self) -> dict:
        return {t.name: t.dwell for t in self.targets}


def _invalid(path, message: str) -> ConfigError:
    return ConfigError(ErrorCode.INVALID_CONFIG, f"target list {clip(path, 200)}: {message}")


def _number(path, entry: dict, key: str, label: str, low: float, high: float) -> float:
    value = entry.get(key)
    number = None if isinstance(value, bool) or not isinstance(value, (int, float)) else float(value)
    if number is None or not (math.isfinite(number) and low <= number <= high):
        raise _invalid(path, f"{label}.{key} = {clip(repr(value), 60)} is not a number in [{low:g}, {high:g}]")
    return number


def _declared(path, entry: dict, key: str, label: str, model) -> float:
    """``entry[key]`` (or the default ``model`` declares) checked against the range ``model`` declares."""
    default, low, high = declared(model, key)[:3]
    return _number(path, entry if default is None else {key: default, **entry}, key, label, low, high)


def _target(path, kind: str, i: int, entry) -> Source | Site:
    label = f"targets[{i}]"
    if not isinstance(entry, dict):
        raise _invalid(path, f"{label} is not a mapping of {', '.join(KINDS[kind])}")
    unknown = sorted(str(k) for k in set(entry) - set(KINDS[kind]))
    missing = [k for k in KINDS[kind] if k not in entry and k != "alt_m"]
    if unknown or missing:
        raise _invalid(path, f"{label} has {'unknown' if unknown else 'no'} key(s) "
                             f"{clip(', '.join(unknown or missing), 120)} "
                             f"(a {kind} target has {', '.join(KINDS[kind])})")
    name = entry["name"]
    if not isinstance(name, str) or not name or not name.isprintable() or len(name) > 128:
        raise _invalid(path, f"{label}.name = {clip(repr(name), 60)} is not a printable name of 1-128 characters")
    label = f"{label} ('{name}')"
    model = schema.Source if kind == "inertial" else schema.Site

    def number(key):
        return _declared(path, entry, key, label, model)
    dwell = number("dwell_s")
    if kind == "inertial":
        ra, dec = math.radians(number("ra_deg")), math.radians(number("dec_deg"))
        return Source(name, np.array([math.cos(dec) * math.cos(ra), math.cos(dec) * math.sin(ra), math.sin(dec)]),
                      dwell)
    return Site(name, math.radians(number("lat_deg")), math.radians(number("lon_deg")), number("alt_m"), dwell)


def config_file(folder: str, name: str, what: str) -> Path:
    """An explicit ``*.yaml`` path, or the stem ``name`` under ``folder/`` of the config directories
    (KeyError naming ``what`` and the known stems)."""
    if name.endswith(".yaml") and Path(name).is_file():
        return Path(name)
    for d in scen.config_dirs():
        path = d / folder / f"{name}.yaml"
        if path.is_file():
            return path
    known = sorted({p.stem for d in scen.config_dirs() for p in (d / folder).glob("*.yaml")})
    raise KeyError(f"unknown {what} '{clip(name, 120)}' (known: {', '.join(known) or 'none'})")


def find(name: str) -> Path:
    """A target list: an explicit ``*.yaml`` path, or a stem under ``targets/`` of the config directories."""
    return config_file("targets", name, "target list")


def load(name: str) -> TargetList:
    """The target list ``name`` (:func:`find`), every field checked (module docstring)."""
    path = find(name)
    doc = scen.read_document(path)
    if not isinstance(doc, dict) or doc.get("kind") not in KINDS:
        kind = doc.get("kind") if isinstance(doc, dict) else None
        raise _invalid(path, f"kind = {clip(repr(kind), 60)}; a target list is of kind {' or '.join(KINDS)}")
    kind = doc["kind"]
    unknown = sorted(str(k) for k in set(doc) - set(FILE_KEYS[kind]))
    if unknown:
        raise _invalid(path, f"unknown key(s) {clip(', '.join(unknown), 120)} (known: {', '.join(FILE_KEYS[kind])})")
    scenario = doc.get("scenario")
    if not isinstance(scenario, str) or scenario not in scen.available():
        raise _invalid(path, f"scenario = {clip(repr(scenario), 80)} is not a known scenario")
    entries = doc.get("targets")
    if not isinstance(entries, list) or not entries or len(entries) > MAX_TARGETS:
        raise _invalid(path, f"targets must list 1 to {MAX_TARGETS} targets, got "
                             f"{len(entries) if isinstance(entries, list) else clip(repr(entries), 60)}")
    targets = [_target(path, kind, i, e) for i, e in enumerate(entries)]
    names = [t.name for t in targets]
    repeat = next((n for i, n in enumerate(names) if n in names[:i]), None)
    if repeat is not None:
        raise _invalid(path, f"target name '{repeat}' appears twice; names must be distinct")
    extra = {}
    if kind == "inertial":
        ref = doc.get("roll_reference", CELESTIAL_NORTH.tolist())
        vec = np.asarray(ref, float) if isinstance(ref, list) and len(ref) == 3 and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in ref) else None
        if vec is None or not np.isfinite(vec).all() or np.linalg.norm(vec) < 1e-9:
            raise _invalid(path, f"roll_reference = {clip(repr(ref), 60)} is not a non-zero 3-vector")
        extra["roll_reference"] = vec / np.linalg.norm(vec)
    else:
        extra["min_elevation"] = math.radians(_declared(path, doc, "min_elevation_deg", "file", schema.GroundTargets))
    return TargetList(path, kind, scenario, targets, **extra)


def pointing_attitude(sensor_axis, direction, roll_reference=CELESTIAL_NORTH) -> np.ndarray:
    """Body-to-inertial quaternion putting body ``sensor_axis`` on inertial ``direction``, the next
    body axis (x → z → y → x after the sensor's largest component) nearest ``roll_reference``
    (the vernal equinox when the direction lies within a degree of the reference)."""
    s = rot.normalize(np.asarray(sensor_axis, float))
    d = rot.normalize(np.asarray(direction, float))
    r_body = next_axis(s)
    ref = np.asarray(roll_reference, float)
    if abs(ref @ d) > math.cos(math.radians(1.0)):
        ref = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    r_inertial = rot.normalize(ref - (ref @ d) * d)
    body = np.column_stack([s, r_body, np.cross(s, r_body)])
    inertial = np.column_stack([d, r_inertial, np.cross(d, r_inertial)])
    return rot.from_dcm_NB(inertial @ body.T)


def next_axis(sensor_axis) -> np.ndarray:
    """The body axis after the sensor's largest component (x → z → y → x), made normal to the sensor."""
    s = rot.normalize(np.asarray(sensor_axis, float))
    axis = np.roll(np.eye(3), 1, axis=0)[int(np.argmax(np.abs(s)))]
    return rot.normalize(axis - (axis @ s) * s)
