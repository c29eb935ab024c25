"""The figures of a flown mission (issue 17), measured from its MCAP log alone (no ROS).

The log's ``/mission/events`` say what was flown (dwells, slews, parks, misses, with why); the truth
state says how: a target's pointing error is the largest angle, over its dwell, between the body
sensor axis turned inertial by the recorded attitude and the source's direction; it counts as
observed when that error stays within the mission's ``pointing_tolerance`` and no zone covers the
boresight during the dwell. The zones' margins are taken at every recorded state's time with the
Sun, Moon and Earth at their true positions (:class:`att_planner.zones.ZoneSky` on the scenario's
sky); the wheels' peak speed against the scenario's limit.
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
from att_planner.mission.config import MissionConfig
from att_planner.zones import ZoneSky
from att_sim import rotations as rot
from att_sim import scenario as scen
from att_sim.ephemeris import Sky


def utc(mission: MissionConfig, t: float) -> str:
    """ISO 8601 UTC of sim time ``t``."""
    return (mission.scenario.epoch + timedelta(seconds=float(t))).isoformat()


def boresight_errors(q: np.ndarray, sensor_axis, direction) -> np.ndarray:
    """Angles (rad) between the body ``sensor_axis`` turned inertial by each attitude of ``q`` (N, 4)
    and the inertial ``direction``."""
    b = rot.dcm(np.asarray(q, float)) @ np.asarray(sensor_axis, float)
    return np.arccos(np.clip(b @ rot.normalize(np.asarray(direction, float)), -1.0, 1.0))


def events_of(log: dict) -> list:
    """The mission events of a read log, in order."""
    topic = log.get(MISSION_EVENTS)
    return [convert.mission_event_from_msg(m) for m in topic.messages] if topic is not None else []


def day_report(mcap_path: str | Path, mission: MissionConfig) -> dict:
    """The day's figures (module docstring) in the JSON layout of ``att-bench day``."""
    log = read_log(mcap_path, topics=[STATE, MISSION_EVENTS], keep_messages=[MISSION_EVENTS])
    state, events = log[STATE], events_of(log)
    t, q = np.asarray(state["header.stamp"], float), np.asarray(state["attitude"], float)
    sc = mission.scenario
    zone_sky = ZoneSky(list(sc.zones), Sky(sc.epoch, sc.orbit_model), window=max(1.0, float(t[-1] - t[0])))
    margins = zone_sky.margins(t, q, true=True)
    targets, seen = [], set()
    for e in events:
        if e.event == Kind.DWELL:
            inside = (t >= e.start) & (t <= e.end)
            err = boresight_errors(q[inside], mission.sensor_axis, e.direction)
            covered = bool(inside.any() and margins[inside].min() < 0.0)
            observed = bool(inside.any() and t[inside][-1] >= e.end - 1.0 / mission.rate and not covered
                            and err.max() <= mission.pointing_tolerance)
            targets.append({"name": e.target, "start": utc(mission, e.start), "end": utc(mission, e.end),
                            "start_s": e.start, "end_s": e.end, "observed": observed,
                            "pointing_error_deg": math.degrees(err.max()) if err.size else math.inf,
                            **({} if observed else {"why": "a zone covered the boresight" if covered else
                                                    "pointing error beyond the tolerance" if err.size
                                                    else "the log ends before the dwell"})})
            seen.add(e.target)
        elif e.event == Kind.MISSED and e.target not in seen:
            targets.append({"name": e.target, "start": None, "end": None, "observed": False,
                            "pointing_error_deg": None, "why": e.message})
            seen.add(e.target)
    for name in (n.name for n in mission.target_list.targets if n.name not in seen):
        targets.append({"name": name, "start": None, "end": None, "observed": False, "pointing_error_deg": None,
                        "why": "not reached before the mission ended"})
    orbit = scen.shared_params(scen.read_document(sc.path)).get("orbit", {})
    wheels = np.asarray(state["wheel_speeds"], float)
    observed = sum(x["observed"] for x in targets)
    return {
        "mcap": str(mcap_path), "epoch": utc(mission, t[0]), "sim_seconds": float(t[-1] - t[0]),
        "tle": [orbit.get("line1", ""), orbit.get("line2", "")], "sensor_axis": list(mission.sensor_axis),
        "targets": targets,
        "zones": [{"name": z.name, "body": z.body, "half_angle_deg": math.degrees(z.half_angle), "keep_in": z.keep_in,
                   "sensor_axis": list(z.sensor_axis), "min_margin_deg": float(np.degrees(margins[:, i].min()))}
                  for i, z in enumerate(sc.zones)],
        "observed": observed, "missed": len(targets) - observed,
        "min_margin_deg": float(np.degrees(margins.min())) if margins.size else math.inf,
        "peak_wheel_ratio": float(np.abs(wheels).max() / sc.spacecraft.wheel_speed_max) if wheels.size else 0.0,
        "events": [{"t": e.t, "event": e.event.value, "target": e.target, "start": e.start, "end": e.end,
                    "plan_id": e.plan_id, "message": e.message} for e in events],
    }
