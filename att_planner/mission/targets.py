"""Target lists of a mission: YAML files of what to observe and for how long.

Two kinds, one file each (``config/targets/``; read by the one loader,
:mod:`att_sim.models.config_files`, and validated by :mod:`att_planner.mission.schema`)::

    kind: inertial                 # an observatory's sources: J2000 right ascension and declination
    scenario: leo_observatory      # the spacecraft and sky they are observed from
    roll_reference: [0, 0, 1]      # inertial direction the roll axis is kept nearest (default: celestial north)
    targets:
      - {name: crab, ra_deg: 83.633, dec_deg: 22.015, dwell_s: 600}

    kind: ground                   # Earth observation: sites tracked through the dwell, strips scanned
    scenario: leo_observatory
    min_elevation_deg: 30          # a site is observable while the spacecraft is this high in its sky
    targets:
      - {name: toulouse, lat_deg: 43.60, lon_deg: 1.44, alt_m: 150, dwell_s: 60}
      - {name: garonne, lat_deg: 44.0, lon_deg: 0.0, end_lat_deg: 44.5, end_lon_deg: 0.5, scan_speed_m_s: 7000}

An inertial source becomes a schedule target attitude (:func:`pointing_attitude`): the scenario's
sensor axis on the source, the body axis after it (x → z → y → x) as near ``roll_reference`` as the
pointing allows (the vernal equinox where the source lies within a degree of the reference). A
ground site stays a site: the pointing modes track it through its dwell. A strip (``end_lat_deg``,
``end_lon_deg``, ``scan_speed_m_s``; no ``dwell_s``) is the great-ellipse segment from its start to
its end (:class:`~att_planner.guidance.strip.Strip`), scanned at that ground speed: its dwell is its
scan. Every field is checked; a bad file is refused with a :class:`~att_msgs_py.errors.ConfigError`
(``INVALID_CONFIG``) listing every problem as ``file:line: targets[i].field: expected ...; found ...``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_planner.guidance.strip import Strip
from att_planner.mission import schema
from att_sim.models import config_files
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

CELESTIAL_NORTH = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Source:
    """An inertial target: its unit direction (GCRS ≈ J2000) and its dwell (s)."""

    name: str
    direction: np.ndarray
    dwell: float


@dataclass(frozen=True)
class Site:
    """A ground target: geodetic latitude and longitude (rad), altitude (m) and its dwell (s); a strip
    (:class:`~att_planner.guidance.strip.Strip`) starts there and its dwell is its scan."""

    name: str
    latitude: float
    longitude: float
    altitude: float
    dwell: float
    strip: Strip | None = None


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


def _target(kind: str, entry: schema.Source | schema.Site) -> Source | Site:
    if kind == "inertial":
        ra, dec = math.radians(entry.ra_deg), math.radians(entry.dec_deg)
        return Source(entry.name, np.array([math.cos(dec) * math.cos(ra), math.cos(dec) * math.sin(ra),
                                            math.sin(dec)]), entry.dwell_s)
    lat, lon = math.radians(entry.lat_deg), math.radians(entry.lon_deg)
    if entry.end_lat_deg is None:
        return Site(entry.name, lat, lon, entry.alt_m, entry.dwell_s)
    strip = Strip.between(lat, lon, math.radians(entry.end_lat_deg), math.radians(entry.end_lon_deg), entry.alt_m,
                          entry.scan_speed_m_s)
    return Site(entry.name, lat, lon, entry.alt_m, strip.duration_s, strip)


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


def read(path) -> config_files.Loaded:
    """The target list file ``path`` read by the one loader and validated by its kind's model
    (:func:`att_planner.mission.schema.target_list_model`), its scenario resolved;
    :class:`att_sim.models.config_files.ConfigFileError` (``INVALID_CONFIG``) with every problem.
    Anchors and aliases are accepted as ``yaml.safe_dump`` writes them, their expansion bounded."""
    path = Path(path)
    data, lines = config_files.read_yaml(path, aliases=True)
    model = config_files.validate(path, schema.target_list_model, data, lines)
    if model.scenario not in scen.available():
        raise config_files.ConfigFileError([config_files.Problem(
            str(path), lines.get(("scenario",)), "scenario", "the name of a scenario",
            f"{clip(repr(model.scenario), 80)}, which names none (known: {', '.join(scen.available()) or 'none'})")])
    return config_files.Loaded(path, model, data, lines)


def load(name: str) -> TargetList:
    """The target list ``name`` (:func:`find`), read and validated (:func:`read`)."""
    path = find(name)
    m = read(path).model
    extra = ({"roll_reference": np.asarray(m.roll_reference, float) / np.linalg.norm(m.roll_reference)}
             if m.kind == "inertial" else {"min_elevation": math.radians(m.min_elevation_deg)})
    targets = []
    for i, entry in enumerate(m.targets):
        try:
            targets.append(_target(m.kind, entry))
        except ValueError as err:          # a strip with no plane, shorter than 1 m or longer than a pass
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"target list {clip(path, 200)}: targets[{i}] "
                                                        f"({clip(entry.name, 40)}): {err}") from None
    return TargetList(path, m.kind, m.scenario, targets, **extra)


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
