"""The figures of a flown mission, measured from its MCAP log alone (no ROS).

The log's ``/mission/events`` say what was flown (dwells, slews, parks, misses, with why); the truth
state says how: a target's pointing error is the largest angle, over its dwell, between the body
sensor axis (the event's) turned inertial by the recorded attitude and the source's direction (a
ground site's line of sight at each time, from the event's pointing mode on the scenario's orbit); it
counts as observed when that error stays within the event's tolerance (the mission's
``pointing_tolerance``), no zone covers the boresight during the dwell and the log holds all of
it. The zones' margins (those the events name as the mission's) are taken at every recorded
state's time with the Sun, Moon and Earth at their true positions (:class:`att_planner.zones.FittedZones`
on the scenario's sky); the wheels' peak speed relative to the body against the scenario's limit.
"""
from __future__ import annotations

import math
from datetime import timedelta
from pathlib import Path

import numpy as np

from att_msgs_py import convert
from att_msgs_py.log import read_log
from att_msgs_py.topics import MISSION_EVENTS, STATE
from att_msgs_py.types import MissionEventKind as Kind
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.zones import FittedZones
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world
from att_sim.models.ephemeris import Ephemeris


def events_of(log: dict) -> list:
    """The mission events of a read log, in order."""
    topic = log.get(MISSION_EVENTS)
    return [convert.mission_event_from_msg(m) for m in topic.messages] if topic is not None else []


def mission_zones(events: list, scenario: scen.Scenario) -> list:
    """The scenario's zones the mission's ``events`` name as kept (all of them when none do)."""
    named = next((set(e.zones) for e in events if e.zones), None)
    return [z for z in scenario.zones if named is None or z.name in named]


def sight_line(event, scenario: scen.Scenario):
    """The unit line of sight of ``event``'s target as a function of an array of times: a ground
    site's from its pointing mode (the controller's law on the scenario's orbit), else the direction."""
    if event.pointing is None:
        return lambda t: np.broadcast_to(rot.normalize(np.asarray(event.direction, float)), (np.size(t), 3))
    law = law_of(event.pointing, PointingGeometry.of(world.Environment.from_scenario(scenario)), event.start,
                 np.array([0.0, 0.0, 0.0, 1.0]))
    return lambda t: np.array([law.primary_N(float(x)) for x in np.atleast_1d(t)]).reshape(-1, 3)


def target_table(events: list, t: np.ndarray, q: np.ndarray, margins: np.ndarray,
                 scenario: scen.Scenario) -> list[dict]:
    """One row per target of the mission's ``events``: its dwell (sim time and UTC), whether it was
    observed and the truth pointing error over it (from the states ``t``, ``q`` and the zones'
    ``margins`` at them, along :func:`sight_line`), or why it was missed."""
    epoch = scenario.epoch
    rows, seen = [], set()
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    for e in events:
        if e.target in seen or e.event not in (Kind.DWELL, Kind.MISSED):
            continue
        seen.add(e.target)
        if e.event == Kind.MISSED:
            rows.append({"name": e.target, "start": None, "end": None, "observed": False,
                         "pointing_error_deg": None, "why": e.message})
            continue
        inside = (t >= e.start) & (t <= e.end)
        b = np.einsum("kij,j->ki", rot.dcm_NB(q[inside]).reshape(-1, 3, 3), np.asarray(e.sensor_axis, float))
        err = np.arccos(np.clip(np.einsum("ki,ki->k", b, sight_line(e, scenario)(t[inside])), -1.0, 1.0))
        covered = bool(inside.any() and margins[inside].min() < 0.0)
        complete = bool(inside.any() and t[inside][-1] >= e.end - step)
        observed = complete and not covered and float(err.max()) <= e.tolerance
        why = ("" if observed else "the log ends before the dwell does" if not complete
               else "a zone covered the boresight" if covered else
               f"pointing error beyond the tolerance of {math.degrees(e.tolerance):g} deg")
        rows.append({"name": e.target, "start": (epoch + timedelta(seconds=e.start)).isoformat(),
                     "end": (epoch + timedelta(seconds=e.end)).isoformat(), "start_s": e.start, "end_s": e.end,
                     "observed": observed, "pointing_error_deg": math.degrees(err.max()) if err.size else None,
                     **({"why": why} if why else {})})
    return rows


def day_report(mcap_path: str | Path, scenario: scen.Scenario) -> dict:
    """The day's figures (module docstring) in the JSON layout of ``att-bench day``."""
    log = read_log(mcap_path, topics=[STATE, MISSION_EVENTS], keep_messages=[MISSION_EVENTS])
    state, events = log[STATE], events_of(log)
    zones = mission_zones(events, scenario)
    t, q = np.asarray(state["header.stamp"], float), np.asarray(state["attitude"], float)
    zone_sky = FittedZones(zones, Ephemeris(scenario.epoch, scenario.orbit_model),
                       window=max(1.0, float(t[-1] - t[0])))
    margins = zone_sky.margins(t, q, true=True)
    table = target_table(events, t, q, margins, scenario)
    orbit = scen.read(scenario.path).shared.orbit
    sc = scenario.spacecraft
    relative = np.asarray(state["wheel_speeds"], float) - np.asarray(state["body_rate"], float) @ sc.wheel_axes
    sensor_axis = next((e.sensor_axis for e in events if e.target), np.zeros(3))
    observed = sum(x["observed"] for x in table)
    return {
        "mcap": str(mcap_path), "epoch": (scenario.epoch + timedelta(seconds=float(t[0]))).isoformat(),
        "sim_seconds": float(t[-1] - t[0]), "tle": [getattr(orbit, "line1", ""), getattr(orbit, "line2", "")],
        "sensor_axis": list(sensor_axis), "targets": table,
        "zones": [{"name": z.name, "body": z.body, "half_angle_deg": math.degrees(z.half_angle), "keep_in": z.keep_in,
                   "sensor_axis": list(z.sensor_axis), "min_margin_deg": float(np.degrees(margins[:, i].min()))}
                  for i, z in enumerate(zones)],
        "observed": observed, "missed": len(table) - observed,
        "min_margin_deg": float(np.degrees(margins.min())) if margins.size else math.inf,
        "peak_wheel_ratio": float(np.abs(relative).max() / sc.wheel_speed_max) if relative.size else 0.0,
        "events": [{"t": e.t, "event": e.event.value, "target": e.target, "start": e.start, "end": e.end,
                    "plan_id": e.plan_id, "message": e.message} for e in events],
    }
