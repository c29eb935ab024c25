"""Figures of merit of a reviewed run (pure): the summary dictionary and its text."""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.log import TopicLog
from att_planner.cones import margins
from att_planner.tools.review.run import SETTLING_THRESHOLD, Run, extract_run, settling_time
from att_planner.verification import peak_magnitude
from att_sim import rotations as rot
from att_sim import scenario as scen
from att_sim.dynamics import Spacecraft


def _ratio(peak: float, limit: float | None):
    return peak / limit if limit is not None and np.isfinite(limit) and limit > 0 else None


def finite_limit(value: float | None) -> float | None:
    """``value`` as a float, or None when it is missing or infinite (no limit to show)."""
    return float(value) if value is not None and np.isfinite(value) else None


def summarize(log: dict[str, TopicLog], spacecraft: Spacecraft | None = None, plan_id: str | None = None) -> dict:
    """Summary of the reviewed segment of a read log (see :func:`~.run.extract_run`).

    Keys: kind, plan (id, method, status, spacecraft), maneuver_time_s (planned duration),
    executed_time_s (segment length), final_attitude_error_deg (to ``goal``: the plan's final
    attitude, identity for magnetorquer runs) and final_rate_rad_s at the end of the segment,
    min_margin_deg and closest_approach_s per cone, peak body torque / wheel torque /
    wheel speed / dipole with their limits and ratios (limits None without ``spacecraft``),
    settling_time_s (magnetorquer runs: Bruni & Celani's ν = 0.05 criterion on q_v), command_timeouts.
    """
    run = extract_run(log, plan_id)
    return summary_of(run, spacecraft)


def summary_of(run: Run, spacecraft: Spacecraft | None = None) -> dict:
    sc = spacecraft
    out = {"kind": run.kind, "start_sim_time_s": run.t0, "executed_time_s": float(run.t[-1] - run.t[0]),
           "state_samples": int(len(run.t)), "command_timeouts": int(np.sum(run.command_timeout)),
           "wheels": int(run.wheel_speeds.shape[1]),
           "plan": None, "maneuver_time_s": None}
    if run.plan is not None:
        p = run.plan
        out["plan"] = {k: str(getattr(p, k)) for k in ("plan_id", "method", "status", "spacecraft", "control_kind")}
        out["plan"]["verified_min_margin_deg"] = math.degrees(p.verification.min_cone_margin)
        if run.kind == "maneuver":
            out["maneuver_time_s"] = p.duration
    out["goal"] = None if run.goal is None else {"maneuver": "the plan's final attitude", "magnetorquer": "identity",
                                                   "log": "the last plan's final attitude"}[run.kind]
    if run.goal is not None:
        out["final_attitude_error_deg"] = float(np.degrees(rot.angle_between(run.q[-1], run.goal)))
    else:
        out["final_attitude_error_deg"] = None
    out["final_rate_rad_s"] = float(np.linalg.norm(run.omega[-1]))
    cones = run.plan.cones if run.plan is not None else []
    out["min_margin_deg"], out["closest_approach_s"] = {}, {}
    if cones:
        m = margins(run.q, run.plan.sensor_axis, cones)
        for j, c in enumerate(cones):
            k = int(np.argmin(m[:, j]))
            out["min_margin_deg"][c.name or f"cone{j}"] = float(np.degrees(m[k, j]))
            out["closest_approach_s"][c.name or f"cone{j}"] = float(run.t[k])
    out["min_cone_margin_deg"] = min(out["min_margin_deg"].values()) if cones else None

    def peak(name, values, limit):
        v = peak_magnitude(values)
        lim = finite_limit(limit)
        out[f"peak_{name}"], out[f"{name}_limit"], out[f"{name}_ratio"] = v, lim, _ratio(v, lim)

    peak("body_torque_Nm", run.body_torque, sc.body_torque_max if sc else None)
    peak("wheel_torque_Nm", np.concatenate([run.wheel_torques.ravel(), run.cmd_wheel_torques.ravel()]),
         sc.wheel_torque_max if sc else None)
    peak("wheel_speed_rad_s", run.wheel_speeds, sc.wheel_speed_max if sc else None)
    peak("dipole_Am2", np.concatenate([run.dipole.ravel(), run.cmd_dipole.ravel()]), sc.dipole_max if sc else None)
    out["settling_time_s"] = settling_time(run.t, run.q) if run.kind == "magnetorquer" else None
    return out


def spacecraft_for(run: Run, scenario: str | None = None) -> Spacecraft | None:
    """Limits from ``scenario`` or the scenario the plan names; None when it cannot be found."""
    name = scenario or (run.plan.spacecraft if run.plan is not None else None)
    if not name:
        return None
    try:
        return scen.load(name).spacecraft
    except (KeyError, OSError, ValueError):
        return None


def format_summary(s: dict) -> str:
    """The summary as aligned text lines."""
    def deg(v, digits=3):
        return "n/a" if v is None else f"{v:.{digits}f} deg"

    def ratio(name, unit):
        lim = s[f"{name}_limit"]
        text = f"{s[f'peak_{name}']:.4g} {unit}"
        return text + (f" / limit {lim:.4g} = {s[f'{name}_ratio']:.3f}" if lim is not None else " (no limit known)")

    lines = [f"kind                  {s['kind']} (segment from sim time {s['start_sim_time_s']:.2f} s, "
             f"{s['state_samples']} states)"]
    if s["plan"]:
        p = s["plan"]
        lines.append(f"plan                  {p['plan_id']} {p['method']} ({p['status']}, {p['spacecraft']})")
    if s["maneuver_time_s"] is not None:
        lines.append(f"maneuver time         {s['maneuver_time_s']:.2f} s planned, "
                     f"{s['executed_time_s']:.2f} s executed "
                     "(with hold)")
    else:
        lines.append(f"segment length        {s['executed_time_s']:.2f} s")
    lines.append(f"final attitude error  {deg(s['final_attitude_error_deg'], 4)} (to {s['goal'] or 'no goal known'}), "
                 f"final rate {s['final_rate_rad_s']:.2e} rad/s")
    for name, v in s["min_margin_deg"].items():
        lines.append(f"min margin {name:<10} {deg(v, 2)} at t = {s['closest_approach_s'][name]:.1f} s")
    lines.append(f"peak body torque      {ratio('body_torque_Nm', 'N m')}")
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
    return "\n".join(lines)
