"""A mission file: which targets to observe, from which scenario, for how long, and how
the day is flown. One YAML file under ``config/missions/`` (read with ``yaml.safe_load`` only)::

    targets: observatory           # a target list (config/targets/observatory.yaml); its scenario is flown
    sensor_axis: [0, 1, 0]         # body axis put on each source
    horizon_s: 21600               # s of sim time from the scenario's epoch
    margin_deg: 1.0                # a target counts as visible this far outside every zone
    rate_hz: 5.0                   # simulator step, state, control and estimate rate of the day
    start_lead_s: 240              # s of sim time from a slew's request to its start (planning)
    time_budget_s: 10              # planner wall-time budget per slew (the day runs at most
                                   # start_lead_s / time_budget_s times real time: a plan is back in time)
    method: ""                     # planning method ("": the planner's default)
    pointing_tolerance_deg: 0.05   # a dwell counts as observed within this pointing error
    momentum_dumping: true         # the controller's magnetorquer dumping while it holds (pointing mode)
    rate_max_deg_per_s: 0.2        # per body axis, the slews' rate bound (default: :func:`gyroscopic_rate_limit`)
    zones: [sun, moon]             # the scenario's zones the mission keeps, by name (default: all of them)
    secondary: velocity            # ground sites: the direction the secondary axis is kept nearest
    secondary_axis: [0, 0, 1]      # ground sites: that body axis (default: ``targets.next_axis`` of the sensor)
    handover_blend_s: 180          # ground sites: the controller's blend from rest into the site's law (s)

An inertial source is held at the attitude of :func:`~att_planner.mission.targets.pointing_attitude`;
a ground site is tracked through its dwell with the controller's ``ground`` pointing mode
(:mod:`att_planner.mission.ground`) while the spacecraft stands ``min_elevation_deg`` (the target
list's) above it. An Earth-observation mission drops the scenario's Earth-limb zone of the payload
(``zones``): its payload looks at the Earth.

Every key is checked; a bad file is refused with a :class:`~att_msgs_py.errors.ConfigError` naming
the file and the key.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_msgs_py.types import SECONDARY_KINDS
from att_planner.mission import targets as target_lists
from att_planner.mission.ground import GroundTrack, site_mode
from att_planner.mission.scheduler import MissionTarget
from att_sim.models import scenario as scen

# key -> (default, low, high); None default: required
NUMBERS = {"horizon_s": (None, 60.0, 7 * 86_400.0), "margin_deg": (1.0, 0.0, 30.0), "rate_hz": (5.0, 0.5, 50.0),
           "start_lead_s": (240.0, 1.0, 3600.0), "time_budget_s": (10.0, 0.05, 600.0),
           "pointing_tolerance_deg": (0.05, 1e-4, 10.0), "handover_blend_s": (60.0, 0.0, 3600.0)}
KEYS = ("targets", "sensor_axis", "method", "momentum_dumping", "rate_max_deg_per_s", "zones", "secondary",
        "secondary_axis", *NUMBERS)
GYROSCOPIC_SHARE = 0.8        # of the wheels' torque margin over the planning limit the gyroscopic torque may take


@dataclass(frozen=True)
class MissionConfig:
    """A checked mission file: the target list, its scenario and how the day is flown (SI units)."""

    path: Path
    target_list: target_lists.TargetList
    scenario: scen.Scenario
    sensor_axis: np.ndarray
    horizon: float
    margin: float                 # rad
    rate: float                   # Hz
    start_lead: float             # s of sim time
    time_budget: float            # s of wall time
    method: str
    pointing_tolerance: float     # rad
    momentum_dumping: bool
    rate_max: float               # rad/s per body axis, passed to the planner as option rate_max
    zones: list                   # att_msgs_py.types.Zone: those of the scenario the mission keeps
    secondary: str                # ground sites: the pointing mode's secondary direction
    secondary_axis: np.ndarray    # ground sites: its body axis
    handover_blend: float         # s: the controller's blend into a site's law (its parameter handover_blend)

    def targets(self) -> dict:
        """Target name -> :class:`~att_planner.mission.scheduler.MissionTarget`, in the list's order."""
        tl = self.target_list
        if tl.kind == "inertial":
            return {t.name: MissionTarget(t.name, t.dwell, target_lists.pointing_attitude(
                self.sensor_axis, t.direction, tl.roll_reference), t.direction) for t in tl.targets}
        return {t.name: MissionTarget(t.name, t.dwell, track=GroundTrack(
            self.scenario, t, site_mode(t, self.sensor_axis, self.secondary_axis, self.secondary), tl.min_elevation))
            for t in tl.targets}


def gyroscopic_rate_limit(sc) -> float:
    """The per-axis body rate (rad/s) that keeps the gyroscopic torque the plans leave to the wheels
    within :data:`GYROSCOPIC_SHARE` of their margin over the planning limit.

    The planners bound the body torque ``u = J ω̇ + ω × J ω`` by ``torque_max``; the wheels must
    give ``J ω̇ + ω × H`` (``H`` the total momentum, near zero), which differs by ``ω × J ω``: at most
    ``a² (J_max − J_min)`` per axis with every rate within ``a`` (principal axes). So
    ``a = sqrt(share (T_w − T) / (J_max − J_min))``; inf (no bound) for a spherical inertia or
    without a margin to share out (then the margin is what is missing, not a rate bound).
    """
    J = np.linalg.eigvalsh(np.asarray(sc.inertia, float))                # principal moments
    spread, margin = float(J.max() - J.min()), float(sc.wheel_torque_max - sc.body_torque_max)
    if spread <= 0.0 or not (margin > 0.0 and math.isfinite(margin)):
        return math.inf
    return math.sqrt(GYROSCOPIC_SHARE * margin / spread)


def find(name: str) -> Path:
    """A mission file: an explicit ``*.yaml`` path, or a stem under ``missions/`` of the config directories."""
    return target_lists.config_file("missions", name, "mission")


def _invalid(path, message: str) -> ConfigError:
    return ConfigError(ErrorCode.INVALID_CONFIG, f"mission {clip(path, 200)}: {message}")


def load(name: str) -> MissionConfig:
    """The mission ``name`` (:func:`find`), every key checked (module docstring)."""
    path = find(name)
    doc = scen.read_document(path)
    if not isinstance(doc, dict):
        raise _invalid(path, f"the file is not a mapping of {', '.join(KEYS)}")
    unknown = sorted(str(k) for k in set(doc) - set(KEYS))
    if unknown:
        raise _invalid(path, f"unknown key(s) {clip(', '.join(unknown), 120)} (known: {', '.join(KEYS)})")
    numbers = {}
    for key, (default, low, high) in NUMBERS.items():
        value = doc.get(key, default)
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) and low <= value <= high
        if not ok:
            raise _invalid(path, f"{key} = {clip(repr(value), 60)} is not a number in [{low:g}, {high:g}]"
                                 + (" (required)" if default is None and key not in doc else ""))
        numbers[key] = float(value)
    if not isinstance(doc.get("targets"), str):
        raise _invalid(path, f"targets = {clip(repr(doc.get('targets')), 60)} is not the name of a target list")
    try:
        target_list = target_lists.load(doc["targets"])
    except KeyError as err:
        raise _invalid(path, f"targets: {err.args[0]}") from None
    vec = _unit_axis(path, doc, "sensor_axis", doc.get("sensor_axis"))
    second = _unit_axis(path, doc, "secondary_axis", doc.get("secondary_axis", target_lists.next_axis(vec).tolist()))
    if np.linalg.norm(np.cross(vec, second)) < 1e-3:
        raise _invalid(path, f"secondary_axis = {clip(repr(doc.get('secondary_axis')), 60)} is parallel to sensor_axis")
    secondary = doc.get("secondary", "velocity")
    if secondary not in SECONDARY_KINDS or secondary == "inertial":
        raise _invalid(path, f"secondary = {clip(repr(secondary), 60)} is not one of "
                             f"{', '.join(k for k in SECONDARY_KINDS if k != 'inertial')}")
    method = doc.get("method", "")
    if not isinstance(method, str) or not method.isprintable() or len(method) > 64:
        raise _invalid(path, f"method = {clip(repr(method), 60)} is not a method name")
    dumping = doc.get("momentum_dumping", True)
    if not isinstance(dumping, bool):
        raise _invalid(path, f"momentum_dumping = {clip(repr(dumping), 60)} is not true or false")
    scenario = scen.load_checked(target_list.scenario)
    rate = doc.get("rate_max_deg_per_s")
    if rate is None:
        rate_max = gyroscopic_rate_limit(scenario.spacecraft)
    elif isinstance(rate, (int, float)) and not isinstance(rate, bool) and 1e-4 <= rate <= 10.0:
        rate_max = math.radians(rate)
    else:
        raise _invalid(path, f"rate_max_deg_per_s = {clip(repr(rate), 60)} is not a number in [0.0001, 10]")
    if scenario.epoch is None:
        raise _invalid(path, f"scenario '{scenario.name}' has no epoch: a mission flies the real sky")
    return MissionConfig(path, target_list, scenario, vec, numbers["horizon_s"], math.radians(numbers["margin_deg"]),
                         numbers["rate_hz"], numbers["start_lead_s"], numbers["time_budget_s"], method,
                         math.radians(numbers["pointing_tolerance_deg"]), dumping, rate_max,
                         _zones(path, doc, scenario), secondary, second, numbers["handover_blend_s"])


def _unit_axis(path, doc: dict, key: str, axis) -> np.ndarray:
    vec = np.asarray(axis, float) if isinstance(axis, list) and len(axis) == 3 and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in axis) else None
    if vec is None or not np.isfinite(vec).all() or abs(np.linalg.norm(vec) - 1.0) > 1e-6:
        raise _invalid(path, f"{key} = {clip(repr(axis), 60)} is not a unit 3-vector (body axes)")
    return vec


def _zones(path, doc: dict, scenario) -> list:
    """The scenario's zones named by ``zones`` (all of them without the key), each named once."""
    names = doc.get("zones")
    known = [z.name for z in scenario.zones]
    if names is None:
        return list(scenario.zones)
    if not isinstance(names, list) or not all(isinstance(n, str) and n in known for n in names) \
            or len(set(names)) != len(names):
        raise _invalid(path, f"zones = {clip(repr(names), 80)} is not a list of distinct zone names of scenario "
                             f"'{scenario.name}' ({', '.join(known) or 'none'})")
    return [z for z in scenario.zones if z.name in names]
