"""A mission file: which targets to observe, from which scenario, for how long, and how
the day is flown. One YAML file under ``config/missions/`` (read with ``yaml.safe_load`` only)::

    targets: observatory           # a target list (config/targets/observatory.yaml); its scenario is flown
    sensor_axis: [0, 1, 0]         # body axis put on each source
    horizon_s: 21600               # s of sim time from the scenario's epoch
    margin_deg: 1.0                # a target counts as visible this far outside every zone
    rate_Hz: 5.0                   # simulator step, state, control and estimate rate of the day
    start_lead_s: 240              # s of sim time from a slew's request to its start (planning)
    time_budget_s: 10              # planner wall-time budget per slew (the day runs at most
                                   # start_lead_s / time_budget_s times real time: a plan is back in time)
    method: ""                     # planning method ("": the planner's default; ground sites on_law: one
                                   # that ends a slew on a pointing mode, END_POINTING_METHODS)
    pointing_tolerance_deg: 0.05   # a dwell counts as observed within this pointing error
    momentum_dumping: true         # the controller's magnetorquer dumping while it holds (pointing mode)
    rate_max_deg_per_s: 0.2        # per body axis, the slews' rate bound (default: :func:`gyroscopic_rate_limit`)
    zones: [sun, moon]             # the scenario's zones the mission keeps, by name (default: all of them)
    secondary: velocity            # ground sites: the direction the secondary axis is kept nearest
    secondary_axis: [0, 0, 1]      # ground sites: that body axis (default: ``targets.next_axis`` of the sensor)
    site_arrival: at_rest          # ground sites: slews end on the site's law (on_law, the default), or at
                                   # rest on its attitude, the controller then blending into the law
    handover_blend_s: 180          # ground sites at_rest: that blend (s)
    start_pointing: nadir          # the day starts with sensor_axis on the nadir (default: scenario, the
                                   # simulator's initial_attitude)

An inertial source is held at the attitude of :func:`~att_planner.mission.targets.pointing_attitude`;
a ground site is reached by a slew that ends on its law (or at rest, ``site_arrival``) and tracked
through its dwell with the controller's ``ground`` pointing mode (:mod:`att_planner.mission.ground`)
while the spacecraft stands ``min_elevation_deg`` (the target list's) above it. An Earth-observation
mission drops the scenario's Earth-limb zone of the payload (``zones``): its payload looks at the Earth.

Every key is checked against :class:`att_planner.mission.schema.Mission` (its ranges and defaults)
by :mod:`att_sim.models.config_files`; a bad file is refused with a
:class:`~att_sim.models.config_files.ConfigFileError` naming the file, the line and the key of
every problem; then the target list, its scenario and the zones named are resolved.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_msgs_py.types import PointingMode
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.methods import END_POINTING_METHODS
from att_planner.mission import targets as target_lists
from att_planner.mission.ground import site_track
from att_planner.mission.scheduler import MissionTarget
from att_planner.mission.schema import Mission
from att_sim.models import config_files, world
from att_sim.models import scenario as scen

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
    handover_blend: float         # s: the controller's blend into a site's law after a slew ending at rest
    start_pointing: str = "scenario"   # "scenario" or "nadir" (:meth:`start_attitude`)
    site_arrival: str = "on_law"  # ground sites: "on_law" (a slew ends on the site's law) or "at_rest"

    def targets(self) -> dict:
        """Target name -> :class:`~att_planner.mission.scheduler.MissionTarget`, in the list's order."""
        tl = self.target_list
        if tl.kind == "inertial":
            return {t.name: MissionTarget(t.name, t.dwell, target_lists.pointing_attitude(
                self.sensor_axis, t.direction, tl.roll_reference), t.direction) for t in tl.targets}
        return {t.name: MissionTarget(t.name, t.dwell, track=site_track(
            self.scenario, t, self.sensor_axis, self.secondary_axis, self.secondary, tl.min_elevation))
            for t in tl.targets}


    def start_attitude(self) -> np.ndarray | None:
        """The attitude the simulator starts the day at ([x, y, z, w], body to inertial): None for the
        scenario's ``initial_attitude``; ``nadir``: the controller's nadir pointing law at the epoch
        (the sensor axis on the nadir, the secondary axis towards ``secondary``), at rest."""
        if self.start_pointing != "nadir":
            return None
        mode = PointingMode("nadir", primary_axis=self.sensor_axis, secondary_axis=self.secondary_axis,
                            secondary=self.secondary)
        geometry = PointingGeometry.of(world.Environment.from_scenario(self.scenario))
        return np.asarray(law_of(mode, geometry, 0.0, np.array([0.0, 0.0, 0.0, 1.0])).attitude(0.0), float)


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
    """The mission ``name`` (:func:`find`): the file checked against :class:`Mission`, then the names it
    refers to resolved (module docstring)."""
    path = find(name)
    m = config_files.load_file(path, Mission).model
    try:
        target_list = target_lists.load(m.targets)
    except KeyError as err:
        raise _invalid(path, f"targets: {err.args[0]}") from None
    vec = np.asarray(m.sensor_axis, float)
    second = (np.asarray(m.secondary_axis, float) if m.secondary_axis is not None
              else target_lists.next_axis(vec))
    scenario = scen.load_checked(target_list.scenario)
    rate_max = (gyroscopic_rate_limit(scenario.spacecraft) if m.rate_max_deg_per_s is None
                else math.radians(m.rate_max_deg_per_s))
    if scenario.epoch is None:
        raise _invalid(path, f"scenario '{scenario.name}' has no epoch: a mission flies the real sky")
    strips = [t.name for t in target_list.targets if getattr(t, "strip", None) is not None]
    if strips and m.site_arrival != "on_law":
        raise _invalid(path, f"site_arrival {m.site_arrival}: the target list's strips "
                             f"({clip(', '.join(strips), 80)}) are scanned from the slew's arrival: "
                             "site_arrival on_law")
    if target_list.kind == "ground" and m.site_arrival == "on_law" and m.method and \
            m.method not in END_POINTING_METHODS:
        raise _invalid(path, f"method {m.method}: site_arrival on_law ends each slew on the site's law, which "
                             f"{', '.join(END_POINTING_METHODS)} plan (or empty: the planner's default); or "
                             "site_arrival at_rest")
    return MissionConfig(path, target_list, scenario, vec, m.horizon_s, math.radians(m.margin_deg), m.rate_Hz,
                         m.start_lead_s, m.time_budget_s, m.method, math.radians(m.pointing_tolerance_deg),
                         m.momentum_dumping, rate_max, _zones(path, m.zones, scenario), m.secondary, second,
                         m.handover_blend_s, m.start_pointing, m.site_arrival)


def _zones(path, names: list | None, scenario) -> list:
    """The scenario's zones named by ``zones`` (all of them without the key)."""
    known = [z.name for z in scenario.zones]
    if names is None:
        return list(scenario.zones)
    if not all(n in known for n in names):
        raise _invalid(path, f"zones = {clip(repr(names), 80)} is not a list of distinct zone names of scenario "
                             f"'{scenario.name}' ({', '.join(known) or 'none'})")
    return [z for z in scenario.zones if z.name in names]
