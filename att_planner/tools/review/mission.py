"""The review of a mission's log: numpy, and two figures.

:func:`mission_of` gathers a log with ``/mission/events`` (``att-mission``): the events, the truth
states (attitude, wheels relative to the body, applied dipole), the controller's modes and the
zones' margins at every state (their true positions on the scenario's sky), and the per-target table
of :func:`att_planner.mission.day.target_table` (dwell, observed, pointing error, or why missed).
:func:`figure_mission` draws ``mission.png``: the timeline (a Gantt row per target: slews, dwells
green when observed and red when not, parks; the controller's mode below), the zones' margins over
the day, each wheel's momentum against its limit, the dipoles. :func:`figure_mission_sky` draws
``mission_sky.png``: the day's boresight track in right ascension and declination, the targets
(observed, missed), and the tracks of the Sun, the Moon and the nadir (the Earth zone's axis). A
mission of ground sites also gets :func:`figure_mission_ground`, ``mission_ground.png``: the ground
track (the sub-satellite point and the boresight's ground point over the day, in geodetic latitude
and longitude, the slews and dwells marked on the boresight's), the sites imaged, missed and refused,
and each image's pointing error against the tolerance.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from att_msgs_py.log import TopicLog
from att_msgs_py.topics import CONTROLLER_STATUS, MISSION_EVENTS, STATE
from att_msgs_py.types import MissionEventKind as Kind
from att_planner.mission.day import events_of, mission_zones, target_table
from att_planner.mission.ground import ground_track
from att_planner.tools.review.run import MODE_NAMES
from att_planner.zones import FittedZones
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world
from att_sim.models.ephemeris import Ephemeris

TOPICS = [STATE, CONTROLLER_STATUS, MISSION_EVENTS]
SKY_SAMPLES = 2000                 # points of each track on the sky plot


@dataclass
class MissionLog:
    events: list                   # MissionEvent, in order
    rows: list                     # target_table rows
    t: np.ndarray                  # (n,) s of sim time, states
    q: np.ndarray                  # (n, 4)
    margins: np.ndarray            # (n, Z) rad
    zone_names: list
    wheel_momentum: np.ndarray     # (n, N) N m s, relative speeds × I_w
    dipole: np.ndarray             # (n, 3) A m², applied
    mode_t: np.ndarray             # (m,) controller status instants
    mode: np.ndarray               # (m,)
    limit: float                   # N m s per wheel
    sky: Ephemeris
    sensor_axis: np.ndarray
    ground: dict | None = None     # ground sites: :func:`att_planner.mission.ground.ground_track` at the states' times


GROUND_KINDS = ("ground", "strip")    # pointing modes of a mission's ground sites and strips


def mission_of(log: dict[str, TopicLog], scenario: scen.Scenario | None) -> MissionLog | None:
    """The mission review's data of a log with mission events and a real-sky scenario (else None)."""
    events = events_of(log)
    if not events or scenario is None or scenario.epoch is None or STATE not in log:
        return None
    state, sc = log[STATE], scenario.spacecraft
    t, q = np.asarray(state["header.stamp"], float), np.asarray(state["attitude"], float)
    sky = Ephemeris(scenario.epoch, scenario.orbit_model)
    zones = FittedZones(mission_zones(events, scenario), sky, window=max(1.0, float(t[-1] - t[0])))
    margins = zones.margins(t, q, true=True)
    relative = np.asarray(state["wheel_speeds"], float) - np.asarray(state["body_rate"], float) @ sc.wheel_axes
    status = log.get(CONTROLLER_STATUS)
    mode_t = np.asarray(status["header.stamp"], float) if status is not None else np.zeros(0)
    mode = np.asarray(status["mode"]) if status is not None else np.zeros(0)
    sensor_axis = next((e.sensor_axis for e in events if e.target), np.array([0.0, 0.0, 1.0]))
    ground = None
    if any(e.pointing is not None and e.pointing.kind in GROUND_KINDS for e in events):
        ground = ground_track(world.Environment.from_scenario(scenario), t, q, sensor_axis)
    return MissionLog(events, target_table(events, t, q, margins, scenario), t, q, margins, zones.names,
                      relative * sc.wheel_inertia, np.asarray(state["dipole"], float), mode_t, mode,
                      sc.wheel_inertia * sc.wheel_speed_max, sky, sensor_axis, ground)


def strip_ends(run: MissionLog) -> dict:
    """The strips of the mission's events: name -> ((start latitude, longitude), (end latitude,
    longitude)) in deg."""
    return {e.target: tuple((math.degrees(a), math.degrees(b)) for a, b in (
        (e.pointing.latitude, e.pointing.longitude), (e.pointing.end_latitude, e.pointing.end_longitude)))
        for e in run.events if e.target and e.pointing is not None and e.pointing.kind == "strip"}


def site_outcomes(run: MissionLog) -> dict:
    """Ground sites by outcome: ``imaged`` (observed within the tolerance on the truth), ``refused``
    (not imaged, after at least one refusal: a plan, a slew or an arrival refused) and ``missed``
    (the others: never reachable, or not reached before the horizon); name -> (latitude, longitude)
    in deg (a strip's start), from the events' ground and strip pointing modes."""
    sites = {}
    for e in run.events:
        if e.target and e.pointing is not None and e.pointing.kind in GROUND_KINDS and e.target not in sites:
            sites[e.target] = (math.degrees(e.pointing.latitude), math.degrees(e.pointing.longitude))
    observed = {r["name"] for r in run.rows if r["observed"]}
    refused = {e.target for e in run.events if e.event == Kind.REFUSED and e.target}
    out = {"imaged": {}, "refused": {}, "missed": {}}
    for name, where in sites.items():
        out["imaged" if name in observed else "refused" if name in refused else "missed"][name] = where
    return out


def mission_summary(run: MissionLog) -> dict:
    """Targets observed and missed (the table), the smallest zone margin, the peak wheel momentum."""
    observed = sum(r["observed"] for r in run.rows)
    out = {"observed": observed, "missed": len(run.rows) - observed, "targets": run.rows,
           "min_zone_margin_deg": float(np.degrees(run.margins.min())) if run.margins.size else math.inf,
           "peak_wheel_momentum_ratio": float(np.abs(run.wheel_momentum).max() / run.limit)
           if run.wheel_momentum.size else 0.0}
    if run.ground is not None:
        out["sites"] = {k: sorted(v) for k, v in site_outcomes(run).items()}
    return out


def timeline_bars(events) -> list[tuple]:
    """(event, start, end) of every slew, dwell and park flown. A slew the controller refused or
    aborted ends at the refusal (not drawn when that came at its start); a park ends when the next
    of them starts, which may come before the time it waited until (the mission decided again and
    left early)."""
    refused_at = {e.plan_id: e.t for e in events if e.event == Kind.REFUSED and e.plan_id}

    def slew_end(e) -> float:
        return min(e.end, refused_at.get(e.plan_id, math.inf)) if e.event == Kind.SLEW and e.plan_id else e.end

    flown = [e for e in events if e.event in (Kind.SLEW, Kind.DWELL, Kind.PARK) and slew_end(e) > e.start]

    def end(e) -> float:
        if e.event != Kind.PARK:
            return slew_end(e)
        return min([e.end] + [n.start for n in flown if n.start > e.start])

    return [(e, e.start, end(e)) for e in flown]


def figure_mission(run: MissionLog, path: Path) -> Path:
    """``mission.png``: timeline, zone margins, wheel momentum against its limit, dipoles."""
    from att_planner.tools.review.figures import _figure, _save

    plt, fig = _figure(figsize=(12, 13))
    axes = fig.subplots(4, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.3, 1.3, 1]})
    h = 3600.0
    names = list(dict.fromkeys(e.target for e in run.events if e.target))
    observed = {r["name"]: r["observed"] for r in run.rows}
    colours = {Kind.SLEW: "0.6", Kind.PARK: "tab:blue"}
    for e, start, end in timeline_bars(run.events):
        colour = colours.get(e.event) or ("tab:green" if observed.get(e.target) else "tab:red")
        axes[0].broken_barh([(start / h, (end - start) / h)], (names.index(e.target) - 0.35, 0.7), color=colour)
    for e in run.events:
        if e.event == Kind.MISSED:
            axes[0].plot(e.t / h, names.index(e.target), "rx", ms=6)
    base = len(names) + 0.5
    if run.mode.size:
        axes[0].step(run.mode_t / h, base + run.mode / max(MODE_NAMES) * 1.5, where="post", color="k", lw=0.8)
    axes[0].set_yticks(range(len(names)), [f"{n} ({'observed' if observed.get(n) else 'missed'})" for n in names],
                       fontsize=7)
    axes[0].set_ylim(-1, base + 2)
    axes[0].invert_yaxis()
    axes[0].set_title("slews (grey), dwells (green: observed, red: not), parks (blue), missed (x); "
                      "top line: controller mode " + ", ".join(f"{k}={v}" for k, v in MODE_NAMES.items()), fontsize=8)
    for i, name in enumerate(run.zone_names):
        axes[1].plot(run.t / h, np.degrees(run.margins[:, i]), lw=0.7, label=name)
    axes[1].axhline(0.0, color="r", lw=0.8)
    axes[1].set_ylabel("zone margin\n(deg)")
    axes[1].legend(ncol=len(run.zone_names), fontsize=7, loc="upper right")
    for i in range(run.wheel_momentum.shape[1]):
        axes[2].plot(run.t / h, run.wheel_momentum[:, i], lw=0.8, label=f"wheel {i}")
    for sign in (1, -1):
        axes[2].axhline(sign * run.limit, color="r", ls="--", lw=0.8)
    axes[2].set_ylabel("wheel momentum\n(N m s; dashed: limit)")
    axes[2].legend(ncol=4, fontsize=7, loc="upper right")
    for i, axis in enumerate("xyz"):
        axes[3].plot(run.t / h, run.dipole[:, i], lw=0.6, label=axis)
    axes[3].set_ylabel("dipole applied\n(A m²)")
    axes[3].legend(ncol=3, fontsize=7, loc="upper right")
    axes[-1].set_xlabel("sim time (h from the epoch)")
    for ax in axes:
        ax.grid(alpha=0.3)
    return _save(plt, fig, path)


def _ra_dec(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.atleast_2d(v)
    return np.degrees(np.arctan2(v[:, 1], v[:, 0])) % 360.0, np.degrees(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))


def _track(ax, v: np.ndarray, **kwargs) -> None:
    """A track in RA/Dec, broken where it wraps through RA 0/360."""
    ra, dec = _ra_dec(v)
    ra = np.where(np.abs(np.diff(ra, prepend=ra[0])) > 180.0, np.nan, ra)
    ax.plot(ra, dec, **kwargs)


def figure_mission_sky(run: MissionLog, path: Path) -> Path:
    """``mission_sky.png``: boresight, targets, Sun, Moon and nadir over the day (RA, Dec)."""
    from att_planner.tools.review.figures import _figure, _save

    plt, fig = _figure(figsize=(12, 6.5))
    ax = fig.subplots()
    pick = np.unique(np.linspace(0, len(run.t) - 1, SKY_SAMPLES).astype(int))
    t = run.t[pick]
    _track(ax, rot.dcm_NB(run.q[pick]) @ run.sensor_axis, color="k", lw=0.6, label="boresight")
    _track(ax, run.sky.sun_direction(t), color="orange", lw=3, label="Sun")
    _track(ax, run.sky.moon_direction(t), color="0.5", lw=3, label="Moon")
    _track(ax, run.sky.nadir(t), color="tab:blue", lw=0.5, ls=":", label="nadir (Earth zone axis)")
    observed = {r["name"]: r["observed"] for r in run.rows}
    seen = set()
    for e in run.events:
        if e.target and e.target not in seen and np.linalg.norm(e.direction) > 0.5:
            seen.add(e.target)
            ra, dec = _ra_dec(e.direction)
            ok = observed.get(e.target, False)
            ax.plot(ra, dec, "o" if ok else "x", color="tab:green" if ok else "tab:red", ms=7)
            ax.annotate(e.target, (ra[0], dec[0]), fontsize=7, xytext=(4, 4), textcoords="offset points")
    ax.set_xlim(360, 0)
    ax.set_ylim(-90, 90)
    ax.set_xlabel("right ascension (deg, GCRS)")
    ax.set_ylabel("declination (deg)")
    ax.set_title("the day's boresight track; targets observed (o) and missed (x)", fontsize=9)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(alpha=0.3)
    return _save(plt, fig, path)


def _intervals(t: np.ndarray, spans) -> np.ndarray:
    """Whether each time of ``t`` lies in one of the (start, end) ``spans``."""
    inside = np.zeros(len(t), bool)
    for start, end in spans:
        inside |= (t >= start) & (t <= end)
    return inside


def _lon_track(ax, lon: np.ndarray, lat: np.ndarray, **kwargs) -> None:
    """A lat/lon track, broken where it wraps through longitude ±180 or leaves the Earth (NaN)."""
    lon = np.where(np.abs(np.diff(lon, prepend=lon[:1])) > 180.0, np.nan, lon)
    ax.plot(lon, lat, **kwargs)


def figure_mission_ground(run: MissionLog, path: Path) -> Path:
    """``mission_ground.png``: the ground track (sub-satellite point, boresight's ground point with its
    slews and dwells), the sites imaged, missed and refused, each image's pointing error."""
    from att_planner.tools.review.figures import _figure, _save

    g = run.ground
    plt, fig = _figure(figsize=(12, 10))
    ax, bars = fig.subplots(2, 1, gridspec_kw={"height_ratios": [3, 1]})
    sites = site_outcomes(run)
    _lon_track(ax, g["sub_lon"], g["sub_lat"], color="tab:blue", lw=0.8, label="sub-satellite point")
    _lon_track(ax, g["bore_lon"], g["bore_lat"], color="k", lw=0.6, label="boresight's ground point")
    bar_spans = timeline_bars(run.events)
    for kind, colour, label in ((Kind.SLEW, "tab:orange", "slews"), (Kind.DWELL, "tab:green", "dwells")):
        on = _intervals(run.t, [(s, e) for ev, s, e in bar_spans if ev.event == kind])
        _lon_track(ax, np.where(on, g["bore_lon"], np.nan), g["bore_lat"], color=colour, lw=2.5, label=label)
    errors = {r["name"]: r["pointing_error_deg"] for r in run.rows}
    styles = {"imaged": ("o", "tab:green"), "refused": ("^", "tab:orange"), "missed": ("x", "tab:red")}
    strips = strip_ends(run)
    for outcome, found in sites.items():
        marker, colour = styles[outcome]
        for name in found.keys() & strips.keys():           # a strip: its segment, from its start's marker
            (lat0, lon0), (lat1, lon1) = strips[name]
            ax.plot([lon0, lon1], [lat0, lat1], "-", color=colour, lw=3.0, alpha=0.6)
        for i, (name, (lat, lon)) in enumerate(found.items()):
            ax.plot(lon, lat, marker, color=colour, ms=9, mfc="none" if marker == "o" else colour,
                    label=f"{outcome} ({len(found)})" if i == 0 else None)
            note = f"{name}\n{errors[name]:.3f} deg" if outcome == "imaged" and errors.get(name) is not None else name
            ax.annotate(note, (lon, lat), fontsize=7, xytext=(5, 4), textcoords="offset points")
    lats = np.concatenate([g["bore_lat"][np.isfinite(g["bore_lat"])], g["sub_lat"],
                           [v[0] for f in sites.values() for v in f.values()]])
    lons = np.concatenate([g["bore_lon"][np.isfinite(g["bore_lon"])], g["sub_lon"],
                           [v[1] for f in sites.values() for v in f.values()]])
    ax.set_xlim(max(-180.0, lons.min() - 5.0), min(180.0, lons.max() + 5.0))
    ax.set_ylim(max(-90.0, lats.min() - 5.0), min(90.0, lats.max() + 5.0))
    ax.set_xlabel("longitude (deg east)")
    ax.set_ylabel("geodetic latitude (deg)")
    ax.set_title("ground track: sub-satellite point and the boresight's ground point (WGS-84) with its slews "
                 "and dwells; sites imaged (o, pointing error on the truth), refused (^), missed (x)", fontsize=8)
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
    imaged = [r for r in run.rows if r["pointing_error_deg"] is not None]
    tolerance = next((math.degrees(e.tolerance) for e in run.events if e.event == Kind.DWELL), None)
    bars.bar(range(len(imaged)), [r["pointing_error_deg"] for r in imaged],
             color=["tab:green" if r["observed"] else "tab:red" for r in imaged])
    bars.set_xticks(range(len(imaged)), [r["name"] for r in imaged], fontsize=7)
    if tolerance is not None:
        bars.axhline(tolerance, color="r", ls="--", lw=0.8, label=f"tolerance {tolerance:g} deg")
        bars.legend(fontsize=7)
    bars.set_ylabel("largest pointing error\nover the dwell (deg, truth)")
    bars.grid(alpha=0.3, axis="y")
    return _save(plt, fig, path)
