"""Figures of merit of a reviewed run (pure): the summary dictionary and its text, and the zones of
the reviewed plan where the simulator flew them (:func:`zone_sky_for`)."""
from __future__ import annotations

import math
from datetime import timedelta

import numpy as np

from att_msgs_py.log import TopicLog
from att_planner.tools.review.run import SETTLING_THRESHOLD, Run, extract_run, settling_time
from att_planner.verification import peak_magnitude
from att_planner.zones import FittedZones, zones_from_cones
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.dynamics import Spacecraft
from att_sim.models.ephemeris import Ephemeris
from att_sim.models.epoch import format_epoch


def _ratio(peak: float, limit: float | None):
    return peak / limit if limit is not None and np.isfinite(limit) and limit > 0 else None


def finite_limit(value: float | None) -> float | None:
    """``value`` as a float, or None when it is missing or infinite (no limit to show)."""
    return float(value) if value is not None and np.isfinite(value) else None


def summarize(log: dict[str, TopicLog], spacecraft: Spacecraft | None = None, plan_id: str | None = None,
              scenario: scen.Scenario | None = None) -> dict:
    """Summary of the reviewed segment of a read log (see :func:`~.run.extract_run`).

    Keys: kind, plan (id, method, status, spacecraft); for maneuvers ``executed_time_s`` is the
    whole reviewed segment, from the execute goal's first command to the next change of mode or
    plan: ``maneuver_time_s`` (the plan's duration, t = 0 to its end) then ``after_plan_s`` of
    settle and hold on its final attitude (``goal_end_s``: when the goal itself ended);
    error_at_plan_end_deg and final_attitude_error_deg (to ``goal``: the plan's final attitude,
    identity for magnetorquer runs) with final_rate_rad_s at the end of the segment, min_margin_deg
    and closest_approach_s per cone and zone (moving zones at their true positions, from
    ``scenario``'s epoch and orbit: :func:`zone_sky_for`), ``zones_note``, peak body torque / wheel
    torque / wheel speed / dipole with when they occur, their actuator ``_limit``, ``_ratio`` and
    ``_above_limit`` (limits None without ``spacecraft``) and for the body torque also the planning
    limit (``torque_max``) and ratio, settling_time_s (magnetorquer runs: Bruni & Celani's ν = 0.05 criterion on q_v),
    command_timeouts.
    """
    run = extract_run(log, plan_id)
    return summary_of(run, spacecraft, *zone_sky_for(run, scenario))


def body_torque_limits(sc: Spacecraft | None) -> tuple[float | None, float | None]:
    """(planning, actuator) limits of the body torque per body axis: the plans' ``torque_max``, and
    the most the actuators put on one body axis: ``wheel_torque_max`` × max_k Σ_i |G_ki| with
    wheels (0.12 N m for swift_demo's three body-aligned wheels), else the direct torque input's
    limit ``torque_max``."""
    if sc is None:
        return None, None
    planning = finite_limit(sc.body_torque_max)
    if sc.n_wheels == 0:
        return planning, planning
    return planning, finite_limit(sc.wheel_torque_max * float(np.abs(sc.wheel_axes).sum(axis=1).max()))


def _phase(run: Run, t: float) -> str:
    if run.kind != "maneuver":
        return run.kind
    return "maneuver" if t <= run.plan.duration + 1e-9 else "settle/hold"


class _Later:
    """``sky`` seen ``offset`` s later (what a :class:`FittedZones` reads of a sky), so that t = 0 is
    the reviewed segment's start."""

    def __init__(self, sky: Ephemeris, offset: float):
        self.sky, self.offset = sky, float(offset)

    def sun_direction(self, t):
        return self.sky.sun_direction(np.asarray(t, float) + self.offset)

    def moon_direction(self, t):
        return self.sky.moon_direction(np.asarray(t, float) + self.offset)

    def nadir(self, t):
        return self.sky.nadir(np.asarray(t, float) + self.offset)

    def earth_angular_radius(self, t):
        return self.sky.earth_angular_radius(np.asarray(t, float) + self.offset)


def zone_sky_for(run: Run, scenario: scen.Scenario | None) -> tuple[FittedZones | None, str]:
    """The reviewed plan's cones (first) and zones over the segment, t = 0 at its start, and a note
    ('' or why moving zones are left out). Moving zones are where the simulator flew them: the
    scenario's orbit and epoch (its sim time zero), seen at sim time ``run.t0 + t``; without a
    scenario epoch the simulator flew no real sky and only the fixed zones are kept. None without
    a plan."""
    plan = run.plan
    if plan is None:
        return None, ""
    zones = zones_from_cones(plan.cones, plan.sensor_axis) + list(plan.zones)
    moving = [z for z in zones if z.body != "inertial"]
    note, sky = "", None
    if moving and (scenario is None or scenario.epoch is None):
        zones = [z for z in zones if z.body == "inertial"]
        note = (f"moving zones ({', '.join(z.name for z in moving)}) are not drawn: "
                + ("no scenario is known" if scenario is None else f"scenario '{scenario.name}' has no epoch, so the "
                   "simulator flew no real sky"))
    elif moving:
        sky = _Later(Ephemeris(scenario.epoch, scenario.orbit_model), run.t0)
        flown = scenario.epoch + timedelta(seconds=run.t0)
        if plan.epoch is not None and abs((flown - plan.epoch).total_seconds()) > 1.0:
            note = (f"the plan was made for {format_epoch(plan.epoch)} but flown from {format_epoch(flown)} "
                    f"({(flown - plan.epoch).total_seconds():+.1f} s): zones are shown where they were when flown")
    window = max(float(run.t[-1]), plan.duration, 1.0)
    return FittedZones(zones, sky, window), note


def summary_of(run: Run, spacecraft: Spacecraft | None = None, zone_sky: FittedZones | None = None,
               zones_note: str = "") -> dict:
    """The summary of a reviewed run; ``zone_sky`` (:func:`zone_sky_for`; None: the plan's cones)
    gives the margins."""
    sc = spacecraft
    out = {"kind": run.kind, "start_sim_time_s": run.t0, "executed_time_s": float(run.t[-1] - run.t[0]),
           "state_samples": int(len(run.t)), "command_timeouts": int(np.sum(run.command_timeout)),
           "wheels": int(run.wheel_speeds.shape[1]),
           "plan": None, "maneuver_time_s": None, "after_plan_s": None, "goal_end_s": None,
           "error_at_plan_end_deg": None}
    if run.plan is not None:
        p = run.plan
        out["plan"] = {k: str(getattr(p, k)) for k in ("plan_id", "method", "status", "spacecraft", "control_kind")}
        out["plan"]["verified_min_margin_deg"] = math.degrees(p.verification.min_cone_margin)
        if run.kind == "maneuver":
            out["maneuver_time_s"] = p.duration
            out["after_plan_s"] = max(0.0, out["executed_time_s"] - p.duration)
            out["goal_end_s"] = run.goal_end
            k = int(np.argmin(np.abs(run.t - p.duration)))
            out["error_at_plan_end_deg"] = float(np.degrees(rot.angle_between(run.q[k], run.goal)))
    out["goal"] = None if run.goal is None else {"maneuver": "the plan's final attitude", "magnetorquer": "identity",
                                                   "log": "the last plan's final attitude"}[run.kind]
    if run.goal is not None:
        out["final_attitude_error_deg"] = float(np.degrees(rot.angle_between(run.q[-1], run.goal)))
    else:
        out["final_attitude_error_deg"] = None
    out["final_rate_rad_s"] = float(np.linalg.norm(run.omega[-1]))
    if zone_sky is None and run.plan is not None:
        zone_sky = FittedZones(zones_from_cones(run.plan.cones, run.plan.sensor_axis))
    out["min_margin_deg"], out["closest_approach_s"], out["zones_note"] = {}, {}, zones_note
    if zone_sky is not None and zone_sky.zones:
        m = zone_sky.margins(run.t, run.q, true=True)
        for j, name in enumerate(zone_sky.names):
            k = int(np.argmin(m[:, j]))
            out["min_margin_deg"][name] = float(np.degrees(m[k, j]))
            out["closest_approach_s"][name] = float(run.t[k])
    out["min_cone_margin_deg"] = min(out["min_margin_deg"].values()) if out["min_margin_deg"] else None

    def peak(name, values, limit, t=None):
        v = peak_magnitude(values)
        lim = finite_limit(limit)
        out[f"peak_{name}"], out[f"{name}_limit"], out[f"{name}_ratio"] = v, lim, _ratio(v, lim)
        out[f"{name}_above_limit"] = lim is not None and v > lim * (1 + 1e-9)
        if t is not None and np.size(values):
            out[f"peak_{name}_t_s"] = float(t[int(np.argmax(np.abs(values).max(axis=1)))])

    planning, actuator = body_torque_limits(sc)
    peak("body_torque_Nm", run.body_torque, actuator, run.t)
    out["peak_body_torque_phase"] = _phase(run, out.get("peak_body_torque_Nm_t_s", 0.0))
    out["body_torque_Nm_planning_limit"] = planning
    out["body_torque_Nm_planning_ratio"] = _ratio(out["peak_body_torque_Nm"], planning)
    peak("wheel_torque_Nm", np.concatenate([run.wheel_torques.ravel(), run.cmd_wheel_torques.ravel()]),
         sc.wheel_torque_max if sc else None)
    peak("wheel_speed_rad_s", run.wheel_speeds, sc.wheel_speed_max if sc else None)
    peak("dipole_Am2", np.concatenate([run.dipole.ravel(), run.cmd_dipole.ravel()]), sc.dipole_max if sc else None)
    out["settling_time_s"] = settling_time(run.t, run.q) if run.kind == "magnetorquer" else None
    return out


def scenario_for(run: Run, scenario: str | None = None) -> scen.Scenario | None:
    """``scenario`` or the scenario the plan names (limits, epoch, orbit); None when it cannot be found."""
    name = scenario or (run.plan.spacecraft if run.plan is not None else None)
    if not name:
        return None
    try:
        return scen.load(name)
    except (KeyError, OSError, ValueError):
        return None


def spacecraft_for(run: Run, scenario: str | None = None) -> Spacecraft | None:
    """Limits from ``scenario`` or the scenario the plan names; None when it cannot be found."""
    found = scenario_for(run, scenario)
    return found.spacecraft if found is not None else None


def notes(s: dict) -> list[str]:
    """Plain sentences on what the figures cover: the executed segment, the two torque limits."""
    out = []
    if s["maneuver_time_s"] is not None:
        goal = f" (the execute goal, which includes the settle time, ended at t = {s['goal_end_s']:.2f} s)" \
            if s["goal_end_s"] is not None else ""
        out.append(f"\"executed\" is the whole reviewed segment, from the execute goal's first command to the next "
                   f"change of mode or plan: the maneuver (the plan, t = 0 to {s['maneuver_time_s']:.2f} s) and then "
                   f"{s['after_plan_s']:.2f} s of settle and hold on its final attitude{goal}; final figures are "
                   "taken at the end of the segment.")
    if s.get("zones_note"):
        out.append(s["zones_note"][0].upper() + s["zones_note"][1:] + ".")
    planning, actuator = s["body_torque_Nm_planning_limit"], s["body_torque_Nm_limit"]
    if planning is not None and actuator is not None and actuator > planning * (1 + 1e-9):
        out.append(f"Plans use at most the planning limit torque_max = {planning:.4g} N m per body axis, while the "
                   f"wheels can deliver {actuator:.4g} N m ({100 * (actuator / planning - 1):.0f}% headroom, left for "
                   "the tracking feedback), so a peak body torque above the planning limit but within the "
                   "actuator limit is by design, and only a peak above the actuator limit is flagged.")
    return out


def _above(s: dict, name: str, what: str) -> str:
    return f" ABOVE {what}" if s[f"{name}_above_limit"] else ""


def _body_torque(s: dict) -> str:
    """Peak body torque, when and in which phase, against the planning and the actuator limit."""
    text = (f"{s['peak_body_torque_Nm']:.4g} N m at t = {s.get('peak_body_torque_Nm_t_s', 0.0):.1f} s "
            f"({s['peak_body_torque_phase']})")
    actuator, planning = s["body_torque_Nm_limit"], s["body_torque_Nm_planning_limit"]
    if actuator is None:
        return text + " (no limit known)"
    against = [] if planning is None else [f"{s['body_torque_Nm_planning_ratio']:.3f} x the planning limit "
                                           f"{planning:.4g} N m (torque_max)"]
    against.append(f"{s['body_torque_Nm_ratio']:.3f} x the actuator limit {actuator:.4g} N m")
    return text + ": " + ", ".join(against) + _above(s, "body_torque_Nm", "THE ACTUATOR LIMIT")


def format_summary(s: dict, with_notes: bool = True) -> str:
    """The summary as aligned text lines (then the :func:`notes`, unless ``with_notes`` is False)."""
    def deg(v, digits=3):
        return "n/a" if v is None else f"{v:.{digits}f} deg"

    def ratio(name, unit):
        lim = s[f"{name}_limit"]
        text = f"{s[f'peak_{name}']:.4g} {unit}"
        if lim is None:
            return text + " (no limit known)"
        return text + f" / limit {lim:.4g} = {s[f'{name}_ratio']:.3f}" + _above(s, name, "THE LIMIT")

    lines = [f"kind                  {s['kind']} (segment from sim time {s['start_sim_time_s']:.2f} s, "
             f"{s['state_samples']} states)"]
    if s["plan"]:
        p = s["plan"]
        lines.append(f"plan                  {p['plan_id']} {p['method']} ({p['status']}, {p['spacecraft']})")
    if s["maneuver_time_s"] is not None:
        lines.append(f"executed              {s['executed_time_s']:.2f} s = {s['maneuver_time_s']:.2f} s maneuver "
                     f"(the plan) + {s['after_plan_s']:.2f} s settle/hold on its final attitude")
        lines.append(f"error at plan end     {deg(s['error_at_plan_end_deg'], 4)} (t = {s['maneuver_time_s']:.2f} s)")
    else:
        lines.append(f"segment length        {s['executed_time_s']:.2f} s")
    lines.append(f"final attitude error  {deg(s['final_attitude_error_deg'], 4)} (to {s['goal'] or 'no goal known'}, "
                 f"end of the segment), final rate {s['final_rate_rad_s']:.2e} rad/s")
    for name, v in s["min_margin_deg"].items():
        lines.append(f"min margin {name:<10} {deg(v, 2)} at t = {s['closest_approach_s'][name]:.1f} s")
    lines.append(f"peak body torque      {_body_torque(s)}")
    if s["wheels"]:
        lines.append(f"peak wheel torque     {ratio('wheel_torque_Nm', 'N m')}")
        lines.append(f"peak wheel speed      {ratio('wheel_speed_rad_s', 'rad/s')}")
    else:
        lines.append("wheels                none")
    lines.append(f"peak dipole           {ratio('dipole_Am2', 'A m^2')}")
    if s["kind"] == "magnetorquer":
        st = s["settling_time_s"]
        settled = "not settled" if st is None else f"{st:.1f} s"
        lines.append(f"settling time         {settled} (|q_i| <= {SETTLING_THRESHOLD})")
    if s["command_timeouts"]:
        lines.append(f"command timeouts      {s['command_timeouts']} state samples with inputs zeroed")
    e = s.get("estimation")
    if e:
        lines.append(f"estimation error      rms {e['attitude_error_rms_arcsec']:.2f} arcsec, max "
                     f"{e['attitude_error_max_arcsec']:.2f}, final {e['attitude_error_final_arcsec']:.2f}; NEES mean "
                     f"{e['nees_mean']:.2f} ({e['nees_dof']} dof)")
        lines.append(f"gyro bias error       {e['bias_error_final_deg_per_h']:.4f} deg/h at the end; tracker invalid "
                     f"{e['tracker_invalid_seconds']:.1f} s")
    pt = s.get("pointing")
    if pt:
        rms = "n/a" if pt["pointing_error_rms_deg"] is None else f"{pt['pointing_error_rms_deg']:.5f} deg"
        sat = "never" if pt["saturation_time_s"] is None else f"at t = {pt['saturation_time_s']:.0f} s"
        lines.append(f"pointing              {pt['pointing_seconds']:.0f} s, error rms {rms}; peak wheel speed "
                     f"{pt['peak_wheel_speed_ratio']:.3f} of its limit (saturated {sat}); dipole duty "
                     f"{pt['dipole_duty']:.2f}")
    lines += mission_lines(s.get("mission"))
    lines += fault_lines(s.get("faults"))
    if with_notes:
        lines += [f"note: {n}" for n in notes(s)]
    return "\n".join(lines)


def fault_lines(f: dict | None) -> list[str]:
    """The faults: each injection, each detection with its latency and response, the re-plans flown."""
    if not f:
        return []
    lines = [f"fault injected        {i['component']} {i['index']} {i['kind']} at t = {i['t']:.2f} s ({i['source']})"
             for i in f["injected"]]
    for d in f["detected"]:
        late = "" if d["latency_s"] is None else f", {d['latency_s']:.2f} s after the onset"
        lines.append(f"fault {'detected' if d['active'] else 'cleared '}        {d['fault_id']} on {d['component']} "
                     f"{d['index']} at t = {d['t']:.2f} s{late}: {d['evidence']}; response {d['response']}")
    if f["replans"]:
        lines.append(f"re-planned            flown: {', '.join(f['replans'])}")
    return lines


def mission_lines(m: dict | None) -> list[str]:
    """The mission's table: a line per target, observed (start, dwell, pointing error) or missed (why)."""
    if not m:
        return []
    lines = [f"mission               {m['observed']} targets observed, {m['missed']} missed; smallest zone margin "
             f"{m['min_zone_margin_deg']:.3f} deg; peak wheel momentum {m['peak_wheel_momentum_ratio']:.3f} "
             "of its limit"]
    for r in m["targets"]:
        if r["observed"]:
            lines.append(f"  {r['name']:14s} observed from {r['start']} for {r['end_s'] - r['start_s']:.0f} s, "
                         f"pointing error {r['pointing_error_deg']:.4f} deg")
        else:
            lines.append(f"  {r['name']:14s} missed: {r['why']}")
    return lines
