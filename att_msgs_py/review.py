"""``att-review LOG.mcap [--out DIR]``: look at a recorded run without ROS running.

Reads the log with :func:`att_msgs_py.mcap_log.read_log`, picks the reviewed segment (the last
executed plan, else the last magnetorquer-PD run, else the whole log), and writes into ``DIR``
(default: ``review/`` next to the log):

* ``sky.png`` — the sensor boresight on the celestial sphere (Lambert azimuthal equal-area
  projection centred on the path), every keep-out cone of the recorded ``ManeuverPlan`` drawn and
  shaded, start and goal marked, the closest approach to each cone annotated;
* ``time_histories.png`` — attitude error to goal and to the plan reference, body rates, body
  torque (applied vs planned) and wheel torques (commanded vs applied) with their limits, wheel
  speeds with their limit, magnetorquer dipoles (commanded vs applied) with saturation, cone
  margins, controller mode;
* ``overview.png`` — a screenshot-sized digest (sky, margins, torque, wheel speeds);
* ``summary.txt``, ``summary.json`` and ``index.html`` (summary table, figures embedded).

Limits come from the scenario named by the plan (``att_sim.scenario.load(plan.spacecraft)``) or
``--scenario``. :func:`summarize` is the pure function computing the summary from a read log;
plotting (matplotlib, Agg) happens only in the ``plot_*`` functions.
"""
from __future__ import annotations

import argparse
import base64
import html
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from att_msgs_py.mcap_log import TopicLog, read_log
from att_planner import tracking
from att_planner.cones import Cone, boresight, margins
from att_sim import rotations as rot
from att_sim.dynamics import Spacecraft
from att_sim.simulation import MODE_IDLE, MODE_MAGNETORQUER_PD, MODE_PLAN_TRACKING, MODE_SAFE

STATE, COMMAND, PLANS = "/spacecraft/state", "/actuator/command", "/planner/plans"
MODE_NAMES = {MODE_IDLE: "idle", MODE_MAGNETORQUER_PD: "magnetorquer PD", MODE_PLAN_TRACKING: "plan tracking",
              MODE_SAFE: "safe"}
SETTLING_THRESHOLD = 0.05        # ν of Bruni & Celani: settled when every |q_i| (vector part) stays ≤ ν


# ---------------------------------------------------------------------------------------------
# The reviewed run, extracted from a read log (numpy only)
# ---------------------------------------------------------------------------------------------

@dataclass
class Run:
    """One reviewed segment of a log, times in s of sim time relative to the segment start ``t0``."""

    kind: str                      # "maneuver" (plan executed), "magnetorquer" (PD run) or "log" (whole log)
    t0: float
    t: np.ndarray                  # (n,) state times
    q: np.ndarray                  # (n, 4)
    omega: np.ndarray              # (n, 3)
    wheel_speeds: np.ndarray       # (n, W)
    wheel_torques: np.ndarray      # (n, W) applied motor torques
    dipole: np.ndarray             # (n, 3) applied dipole
    body_torque: np.ndarray        # (n, 3) applied body torque
    command_timeout: np.ndarray    # (n,) bool
    cmd_t: np.ndarray              # (m,) command times
    cmd_mode: np.ndarray           # (m,)
    cmd_wheel_torques: np.ndarray  # (m, W)
    cmd_dipole: np.ndarray         # (m, 3)
    goal: np.ndarray | None        # (4,) goal attitude (plan end; identity for magnetorquer runs)
    plan: dict | None = None       # plan_id, method, status, spacecraft, duration, t, q, omega, torque,
    #                                interpolation, sensor_axis, cones, verification


def _rows(array_or_list, i):
    return np.asarray(array_or_list[i], float)


def plans_from_log(plans: TopicLog) -> list[dict]:
    """Every recorded ManeuverPlan as a dict of numpy arrays and Cone objects."""
    out = []
    for i in range(len(plans)):
        cones = [Cone(c["direction"], float(c["half_angle"]), str(c["name"])) for c in plans["cones"][i]]
        out.append({
            "plan_id": str(plans["plan_id"][i]), "method": str(plans["method"][i]), "status": str(plans["status"][i]),
            "spacecraft": str(plans["spacecraft"][i]), "duration": float(plans["duration"][i]),
            "interpolation": str(plans["interpolation"][i]), "control_kind": str(plans["control_kind"][i]),
            "t": _rows(plans["times"], i), "q": _rows(plans["attitudes"], i).reshape(-1, 4),
            "omega": _rows(plans["rates"], i).reshape(-1, 3), "torque": _rows(plans["torques"], i).reshape(-1, 3),
            "sensor_axis": _rows(plans["sensor_axis"], i), "cones": cones,
            "verified_min_margin": float(plans["verification.min_cone_margin"][i]),
        })
    return out


def _segment(cmd_t, cmd_mode, cmd_plan, plan_id):
    """[start, end) command indices of the execution of ``plan_id`` and the hold after it."""
    idx = np.flatnonzero(cmd_plan == plan_id)
    start, last = idx[0], idx[-1]
    after = np.flatnonzero((np.arange(len(cmd_t)) > last)
                           & ((cmd_mode != MODE_PLAN_TRACKING) | ((cmd_plan != "") & (cmd_plan != plan_id))))
    return start, (after[0] if after.size else len(cmd_t))


def extract_run(log: dict[str, TopicLog], plan_id: str | None = None) -> Run:
    """The reviewed segment: plan ``plan_id`` (default: the last executed plan) from its first
    command to the next change of mode or plan; else the last magnetorquer-PD run; else the log."""
    if STATE not in log or len(log[STATE]) == 0:
        raise ValueError(f"the log has no {STATE} messages to review")
    state, cmd = log[STATE], log.get(COMMAND)
    plans = plans_from_log(log[PLANS]) if PLANS in log else []
    t_state = np.asarray(state["header.stamp"], float)
    if cmd is not None and len(cmd):
        cmd_t, cmd_mode = np.asarray(cmd["header.stamp"], float), np.asarray(cmd["mode"], int)
        cmd_plan = np.asarray(cmd["plan_id"], dtype=str)
        cmd_wheels, cmd_dipole = np.asarray(cmd["wheel_torques"], float), np.asarray(cmd["dipole"], float)
    else:
        cmd_t, cmd_mode, cmd_plan = np.zeros(0), np.zeros(0, int), np.zeros(0, dtype=str)
        cmd_wheels, cmd_dipole = np.zeros((0, state["wheel_speeds"].shape[1])), np.zeros((0, 3))
    executed = list(dict.fromkeys(p for p in cmd_plan if p))
    by_id = {p["plan_id"]: p for p in plans}
    if plan_id is not None and plan_id not in executed:
        raise ValueError(f"plan_id '{plan_id}' was not executed in this log (executed: {', '.join(executed) or 'none'})")
    plan_id = plan_id or next((p for p in reversed(executed) if p in by_id), None)
    plan, goal = None, None
    if plan_id is not None:
        kind, plan = "maneuver", by_id[plan_id]
        i0, i1 = _segment(cmd_t, cmd_mode, cmd_plan, plan_id)
        goal = plan["q"][-1]
    elif np.any(cmd_mode == MODE_MAGNETORQUER_PD):
        kind, goal = "magnetorquer", rot.IDENTITY.copy()
        on = np.flatnonzero(cmd_mode == MODE_MAGNETORQUER_PD)
        i1 = on[-1] + 1
        breaks = np.flatnonzero(cmd_mode[:i1] != MODE_MAGNETORQUER_PD)
        i0 = breaks[-1] + 1 if breaks.size else 0
        plan = plans[-1] if plans else None
    else:
        kind, i0, i1 = "log", 0, len(cmd_t)
        plan = plans[-1] if plans else None
        goal = plan["q"][-1] if plan else None
    t0 = cmd_t[i0] if len(cmd_t) else t_state[0]
    t1 = cmd_t[i1] if i1 < len(cmd_t) else np.inf
    keep = (t_state >= t0) & (t_state < t1)
    if not np.any(keep):
        raise ValueError(f"no state messages between sim times {t0:.2f} s and {t1:.2f} s")
    ckeep = slice(i0, i1)
    return Run(
        kind=kind, t0=float(t0), t=t_state[keep] - t0, q=np.asarray(state["attitude"], float)[keep],
        omega=np.asarray(state["body_rate"], float)[keep], wheel_speeds=np.asarray(state["wheel_speeds"], float)[keep],
        wheel_torques=np.asarray(state["wheel_torques"], float)[keep], dipole=np.asarray(state["dipole"], float)[keep],
        body_torque=np.asarray(state["applied_torque"], float)[keep],
        command_timeout=np.asarray(state["command_timeout"], bool)[keep],
        cmd_t=cmd_t[ckeep] - t0, cmd_mode=cmd_mode[ckeep], cmd_wheel_torques=cmd_wheels[ckeep],
        cmd_dipole=cmd_dipole[ckeep], goal=goal, plan=plan)


# ---------------------------------------------------------------------------------------------
# Figures of merit (pure)
# ---------------------------------------------------------------------------------------------

def settling_time(t: np.ndarray, q: np.ndarray, threshold: float = SETTLING_THRESHOLD) -> float | None:
    """First time after which every vector component of ``q`` (sign with w ≥ 0) stays within
    ``threshold`` up to the end (Bruni & Celani's settling criterion); None if the last sample is
    outside it."""
    qv = np.where(q[:, 3:] < 0, -q, q)[:, :3]
    outside = np.flatnonzero(np.max(np.abs(qv), axis=1) > threshold)
    if outside.size == 0:
        return float(t[0])
    if outside[-1] == len(t) - 1:
        return None
    return float(t[outside[-1] + 1])


def reference_error(run: Run) -> np.ndarray:
    """Angle (rad) between the recorded attitude and the plan reference the controller tracked."""
    p = run.plan
    return np.array([rot.angle_between(q, tracking.reference(p["t"], p["q"], p["omega"], p["torque"],
                                                              p["interpolation"], t).q)
                     for t, q in zip(run.t, run.q)])


def _ratio(peak: float, limit: float | None):
    return peak / limit if limit is not None and np.isfinite(limit) and limit > 0 else None


def _limit(value: float | None):
    return float(value) if value is not None and np.isfinite(value) else None


def summarize(log: dict[str, TopicLog], spacecraft: Spacecraft | None = None, plan_id: str | None = None) -> dict:
    """Summary of the reviewed segment of a read log (see :func:`extract_run`).

    Keys: kind, plan (id, method, status, spacecraft), maneuver_time_s (planned duration),
    executed_time_s (segment length), final_attitude_error_deg (to ``goal``: the plan's final
    attitude, identity for magnetorquer runs) and final_rate_rad_s at the end of the segment, min_margin_deg and closest_approach_s per cone, peak body torque / wheel torque /
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
        out["plan"] = {k: p[k] for k in ("plan_id", "method", "status", "spacecraft", "control_kind")}
        out["plan"]["verified_min_margin_deg"] = math.degrees(p["verified_min_margin"])
        if run.kind == "maneuver":
            out["maneuver_time_s"] = p["duration"]
    out["goal"] = None if run.goal is None else {"maneuver": "the plan's final attitude", "magnetorquer": "identity",
                                                   "log": "the last plan's final attitude"}[run.kind]
    if run.goal is not None:
        out["final_attitude_error_deg"] = float(np.degrees(rot.angle_between(run.q[-1], run.goal)))
    else:
        out["final_attitude_error_deg"] = None
    out["final_rate_rad_s"] = float(np.linalg.norm(run.omega[-1]))
    cones = run.plan["cones"] if run.plan is not None else []
    out["min_margin_deg"], out["closest_approach_s"] = {}, {}
    if cones:
        m = margins(run.q, run.plan["sensor_axis"], cones)
        for j, c in enumerate(cones):
            k = int(np.argmin(m[:, j]))
            out["min_margin_deg"][c.name or f"cone{j}"] = float(np.degrees(m[k, j]))
            out["closest_approach_s"][c.name or f"cone{j}"] = float(run.t[k])
    out["min_cone_margin_deg"] = min(out["min_margin_deg"].values()) if cones else None

    def peak(name, values, limit):
        v = float(np.max(np.abs(values))) if np.size(values) else 0.0
        out[f"peak_{name}"], out[f"{name}_limit"], out[f"{name}_ratio"] = v, _limit(limit), _ratio(v, _limit(limit))

    peak("body_torque_Nm", run.body_torque, sc.body_torque_max if sc else None)
    peak("wheel_torque_Nm", np.concatenate([run.wheel_torques.ravel(), run.cmd_wheel_torques.ravel()]),
         sc.wheel_torque_max if sc else None)
    peak("wheel_speed_rad_s", run.wheel_speeds, sc.wheel_speed_max if sc else None)
    peak("dipole_Am2", np.concatenate([run.dipole.ravel(), run.cmd_dipole.ravel()]), sc.dipole_max if sc else None)
    out["settling_time_s"] = settling_time(run.t, run.q) if run.kind == "magnetorquer" else None
    return out


def spacecraft_for(run: Run, scenario: str | None = None) -> Spacecraft | None:
    """Limits from ``scenario`` or the scenario the plan names; None when it cannot be found."""
    from att_sim import scenario as scen
    name = scenario or (run.plan["spacecraft"] if run.plan is not None else None)
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
        lines.append(f"maneuver time         {s['maneuver_time_s']:.2f} s planned, {s['executed_time_s']:.2f} s executed "
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
        lines.append(f"settling time         {'not settled' if st is None else f'{st:.1f} s'} (|q_i| <= {SETTLING_THRESHOLD})")
    if s["command_timeouts"]:
        lines.append(f"command timeouts      {s['command_timeouts']} state samples with inputs zeroed")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# Plotting (matplotlib, Agg)
# ---------------------------------------------------------------------------------------------

def _basis(center: np.ndarray):
    c = center / np.linalg.norm(center)
    helper = np.array([0.0, 0.0, 1.0]) if abs(c[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(helper, c)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(c, e1), c


def equal_area(v: np.ndarray, center: np.ndarray) -> np.ndarray:
    """Lambert azimuthal equal-area projection of unit vectors ``v`` (..., 3) about ``center``:
    radius 2 sin(angle/2), so the whole sphere fits in a disc of radius 2."""
    e1, e2, c = _basis(center)
    v = np.asarray(v, float)
    z = np.clip(v @ c, -1.0 + 1e-12, 1.0)
    k = np.sqrt(2.0 / (1.0 + z))
    return np.stack([k * (v @ e1), k * (v @ e2)], axis=-1)


def small_circle(direction: np.ndarray, half_angle: float, n: int = 361) -> np.ndarray:
    """Points (n, 3) of the circle at ``half_angle`` from ``direction``."""
    e1, e2, d = _basis(direction)
    a = np.linspace(0.0, 2 * np.pi, n)
    return (np.cos(half_angle) * d[None, :]
            + np.sin(half_angle) * (np.cos(a)[:, None] * e1[None, :] + np.sin(a)[:, None] * e2[None, :]))


def _planned_path(plan: dict, n: int = 400) -> np.ndarray:
    ts = np.linspace(plan["t"][0], plan["t"][-1], n)
    return np.array([tracking.reference(plan["t"], plan["q"], plan["omega"], plan["torque"], plan["interpolation"],
                                        t).q for t in ts])


CONE_COLORS = ["#d62728", "#1f77b4", "#7f7f7f", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf"]


def plot_sky(ax, run: Run) -> None:
    """Boresight path on the celestial sphere with cones, start/goal and closest approaches."""
    from matplotlib.patches import Circle, PathPatch
    from matplotlib.path import Path as MplPath

    plan = run.plan
    sensor = plan["sensor_axis"] if plan is not None else np.array([1.0, 0.0, 0.0])
    path = boresight(run.q, sensor)
    path /= np.linalg.norm(path, axis=1, keepdims=True)
    goal_dir = boresight(run.goal, sensor) if run.goal is not None else path[-1]
    center = path[0] + goal_dir + path.mean(axis=0)
    center = center if np.linalg.norm(center) > 1e-6 else path[0]
    center = center / np.linalg.norm(center)
    ax.add_patch(Circle((0, 0), 2.0, fill=False, lw=0.8, color="0.6"))
    for ang in (30, 60, 90, 120, 150):
        r = 2 * math.sin(math.radians(ang) / 2)
        ax.add_patch(Circle((0, 0), r, fill=False, lw=0.4, ls=":", color="0.75"))
        ax.text(r * math.cos(math.radians(80)), r * math.sin(math.radians(80)), f"{ang}°", fontsize=6, color="0.6")
    for vec, label in zip(np.vstack([np.eye(3), -np.eye(3)]), ["+X", "+Y", "+Z", "−X", "−Y", "−Z"]):
        if vec @ center > -0.98:
            x, y = equal_area(vec, center)
            ax.plot(x, y, "+", color="0.55", ms=5)
            ax.text(x + 0.03, y + 0.03, label, fontsize=7, color="0.45")
    cones = plan["cones"] if plan is not None else []
    for j, cone in enumerate(cones):
        color = CONE_COLORS[j % len(CONE_COLORS)]
        ring = equal_area(small_circle(cone.direction, cone.half_angle), center)
        if np.arccos(np.clip(-center @ cone.direction, -1, 1)) < cone.half_angle:
            # the cone holds the projection's antipode: its inside is the band between ring and rim
            rim = 2.0 * np.stack([np.cos(np.linspace(0, 2 * np.pi, 361)), np.sin(np.linspace(0, 2 * np.pi, 361))], 1)
            verts = np.vstack([rim, ring[::-1]])
            codes = ([MplPath.MOVETO] + [MplPath.LINETO] * 360) * 2
            ax.add_patch(PathPatch(MplPath(verts, codes), facecolor=color, alpha=0.18, edgecolor="none"))
        else:
            ax.fill(ring[:, 0], ring[:, 1], color=color, alpha=0.18, lw=0)
        ax.plot(ring[:, 0], ring[:, 1], color=color, lw=1.2)
        cx, cy = equal_area(cone.direction, center)
        ax.text(cx, cy, f"{cone.name}\n{math.degrees(cone.half_angle):.0f}°", color=color, fontsize=8,
                ha="center", va="center", weight="bold")
    if plan is not None and run.kind == "maneuver":
        planned = equal_area(boresight(_planned_path(plan), sensor), center)
        ax.plot(planned[:, 0], planned[:, 1], "--", color="0.3", lw=1.0, label="planned")
    xy = equal_area(path, center)
    ax.plot(xy[:, 0], xy[:, 1], color="k", lw=1.8, label="recorded")
    ax.plot(*xy[0], "o", color="tab:green", ms=12, mfc="none", mew=2.5, label="start", zorder=7)
    gx, gy = equal_area(goal_dir, center)
    ax.plot(gx, gy, "*", color="tab:orange", ms=13, label="goal", zorder=7)
    if cones:
        m = margins(run.q, sensor, cones)
        for j, cone in enumerate(cones):
            k = int(np.argmin(m[:, j]))
            color = CONE_COLORS[j % len(CONE_COLORS)]
            ax.plot(*xy[k], "x", color=color, ms=9, mew=2, zorder=6,
                    label=f"closest to {cone.name}: {math.degrees(m[k, j]):.2f}° at {run.t[k]:.0f} s")
            outward = xy[k] / max(np.linalg.norm(xy[k]), 1e-9)
            ax.annotate(f"{math.degrees(m[k, j]):.2f}°", xy[k], xytext=tuple(14 * outward + (0, -4 * j)),
                        textcoords="offset points", fontsize=8, color=color, weight="bold", ha="center")
    ax.set_xlim(-2.08, 2.08)
    ax.set_ylim(-2.08, 2.08)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.legend(loc="lower left", fontsize=7, frameon=False, bbox_to_anchor=(-0.02, -0.04))
    ax.set_title("Boresight on the sky (equal-area, closest approach ×)" if plan is not None
                 else "Body x axis on the sky (no plan in the log)", fontsize=10)


def _limits(ax, limit, label=None):
    if limit is not None:
        for sign in (1, -1):
            ax.axhline(sign * limit, color="r", ls="--", lw=0.8, label=label if sign == 1 else None)


def _maneuver_end(ax, run):
    if run.kind == "maneuver":
        ax.axvline(run.plan["duration"], color="0.5", ls=":", lw=0.8)


AXES = ("x", "y", "z")


def plot_attitude_error(ax, run: Run) -> None:
    if run.goal is not None:
        ax.semilogy(run.t, np.maximum(np.degrees(rot.angle_between(run.q, run.goal)), 1e-6), label="to goal")
    if run.kind == "maneuver":
        ax.semilogy(run.t, np.maximum(np.degrees(reference_error(run)), 1e-6), label="to plan reference")
    ax.set_ylabel("attitude error [deg]")
    ax.legend(loc="upper right", fontsize=7)


def plot_rates(ax, run: Run) -> None:
    for i in range(3):
        ax.plot(run.t, np.degrees(run.omega[:, i]), label=f"ω{AXES[i]}")
    if run.kind == "maneuver":
        ax.set_prop_cycle(None)
        for i in range(3):
            ax.plot(run.plan["t"], np.degrees(run.plan["omega"][:, i]), ls="--", lw=0.8)
    ax.set_ylabel("body rate [deg/s]")
    ax.legend(loc="upper right", fontsize=7, ncol=3)


def plot_body_torque(ax, run: Run, sc: Spacecraft | None) -> None:
    for i in range(3):
        ax.plot(run.t, run.body_torque[:, i], lw=1.0, label=f"applied {AXES[i]}")
    if run.kind == "maneuver" and run.plan["control_kind"] != "wheel_torque":
        ax.set_prop_cycle(None)
        step = "post" if run.plan["interpolation"] == "zoh" else None
        for i in range(3):
            if step:
                ax.step(run.plan["t"], run.plan["torque"][:, i], where="post", ls="--", lw=0.8)
            else:
                ax.plot(run.plan["t"], run.plan["torque"][:, i], ls="--", lw=0.8)
    _limits(ax, _limit(sc.body_torque_max) if sc else None, "limit")
    ax.set_ylabel("body torque [N m]\n(-- planned)")
    ax.legend(loc="upper right", fontsize=7, ncol=2)


def _wheel_legend(ax, run: Run) -> None:
    """Legend of the per-wheel lines, or a note that the spacecraft has no wheels."""
    if run.wheel_speeds.shape[1] == 0:
        ax.text(0.5, 0.5, "no reaction wheels", ha="center", va="center", transform=ax.transAxes)
    else:
        ax.legend(loc="upper right", fontsize=7, ncol=2)


def plot_wheel_torque(ax, run: Run, sc: Spacecraft | None) -> None:
    for i in range(run.wheel_torques.shape[1]):
        line, = ax.plot(run.t, run.wheel_torques[:, i], lw=1.0, label=f"wheel {i + 1}")
        if len(run.cmd_t):
            ax.plot(run.cmd_t, run.cmd_wheel_torques[:, i], ls="--", lw=0.8, color=line.get_color())
    _limits(ax, _limit(sc.wheel_torque_max) if sc else None, "limit")
    ax.set_ylabel("wheel torque [N m]\n(— applied, -- cmd)")
    _wheel_legend(ax, run)


def plot_wheel_speeds(ax, run: Run, sc: Spacecraft | None) -> None:
    for i in range(run.wheel_speeds.shape[1]):
        ax.plot(run.t, run.wheel_speeds[:, i], label=f"wheel {i + 1}")
    _limits(ax, _limit(sc.wheel_speed_max) if sc else None, "limit")
    ax.set_ylabel("wheel speed [rad/s]")
    _wheel_legend(ax, run)


def plot_dipole(ax, run: Run, sc: Spacecraft | None) -> None:
    for i in range(3):
        line, = ax.plot(run.t, run.dipole[:, i], lw=1.0, label=f"m{AXES[i]}")
        if len(run.cmd_t):
            ax.plot(run.cmd_t, run.cmd_dipole[:, i], ls="--", lw=0.8, color=line.get_color())
    _limits(ax, _limit(sc.dipole_max) if sc else None, "saturation")
    ax.set_ylabel("dipole [A m²]\n(— applied, -- cmd)")
    ax.legend(loc="upper right", fontsize=7, ncol=2)


def plot_margins(ax, run: Run) -> None:
    cones = run.plan["cones"] if run.plan is not None else []
    if cones:
        m = np.degrees(margins(run.q, run.plan["sensor_axis"], cones))
        for j, cone in enumerate(cones):
            ax.plot(run.t, m[:, j], color=CONE_COLORS[j % len(CONE_COLORS)], lw=1.0, label=cone.name)
        ax.plot(run.t, m.min(axis=1), color="k", lw=0.9, ls="--", label="minimum")
        ax.axhline(0.0, color="k", lw=0.6)
        ax.legend(loc="upper right", fontsize=7, ncol=2)
    else:
        ax.text(0.5, 0.5, "no keep-out cones in the log", ha="center", va="center", transform=ax.transAxes)
    ax.set_ylabel("cone margin [deg]")


def plot_modes(ax, run: Run) -> None:
    if len(run.cmd_t):
        ax.step(run.cmd_t, run.cmd_mode, where="post", label="controller mode")
    if np.any(run.command_timeout):
        ax.plot(run.t[run.command_timeout], np.full(int(np.sum(run.command_timeout)), -0.5), "r|", label="command timeout")
    ax.set_yticks(list(MODE_NAMES), list(MODE_NAMES.values()), fontsize=7)
    ax.set_ylim(-1, 3.5)
    ax.legend(loc="upper right", fontsize=7)


def _figure(*args, **kwargs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt, plt.figure(*args, **kwargs)


def _time_label(run: Run) -> str:
    return f"t [s] from sim time {run.t0:.1f} s" + (" (dotted: plan end)" if run.kind == "maneuver" else "")


def figure_time_histories(run: Run, sc: Spacecraft | None, path: Path) -> Path:
    plt, fig = _figure(figsize=(13, 12))
    axes = fig.subplots(4, 2, sharex=True)
    plot_attitude_error(axes[0, 0], run)
    plot_rates(axes[0, 1], run)
    plot_body_torque(axes[1, 0], run, sc)
    plot_wheel_torque(axes[1, 1], run, sc)
    plot_wheel_speeds(axes[2, 0], run, sc)
    plot_dipole(axes[2, 1], run, sc)
    plot_margins(axes[3, 0], run)
    plot_modes(axes[3, 1], run)
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
        _maneuver_end(ax, run)
    for ax in axes[-1]:
        ax.set_xlabel(_time_label(run))
    fig.suptitle(_title(run))
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def figure_sky(run: Run, path: Path) -> Path:
    plt, fig = _figure(figsize=(7.5, 7.5))
    plot_sky(fig.add_subplot(1, 1, 1), run)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def figure_overview(run: Run, sc: Spacecraft | None, path: Path) -> Path:
    """Screenshot-sized digest: the sky on the left; margins, body torque, wheel speeds on the right."""
    plt, fig = _figure(figsize=(12, 6.2))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.0, 1.15])
    plot_sky(fig.add_subplot(grid[:, 0]), run)
    right = [fig.add_subplot(grid[0, 1])]
    right += [fig.add_subplot(grid[i, 1], sharex=right[0]) for i in (1, 2)]
    plot_margins(right[0], run)
    plot_body_torque(right[1], run, sc)
    plot_wheel_speeds(right[2], run, sc)
    for ax in right:
        ax.grid(alpha=0.3)
        _maneuver_end(ax, run)
    right[2].set_xlabel(_time_label(run))
    fig.suptitle(_title(run), fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _title(run: Run) -> str:
    if run.kind == "maneuver":
        p = run.plan
        return f"{p['method']} plan {p['plan_id']} ({p['spacecraft']}), {p['duration']:.1f} s"
    return {"magnetorquer": "magnetorquer PD run", "log": "whole log"}[run.kind]


# ---------------------------------------------------------------------------------------------
# Report
# ---------------------------------------------------------------------------------------------

@dataclass
class Review:
    out_dir: Path
    summary: dict
    text: str
    figures: dict          # name -> png path
    html: Path


def _html(log_path: Path, text: str, figures: dict) -> str:
    imgs = "\n".join(
        f'<h2>{html.escape(name)}</h2>\n<img alt="{html.escape(name)}" style="max-width:100%" '
        f'src="data:image/png;base64,{base64.b64encode(Path(p).read_bytes()).decode()}">'
        for name, p in figures.items())
    return (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Review of {html.escape(log_path.name)}</title>"
            "<style>body{font-family:sans-serif;margin:2em}pre{background:#f4f4f4;padding:1em}</style></head><body>\n"
            f"<h1>Review of {html.escape(str(log_path))}</h1>\n<pre>{html.escape(text)}</pre>\n{imgs}\n</body></html>\n")


def review(log_path: str | Path, out_dir: str | Path | None = None, *, plan_id: str | None = None,
           scenario: str | None = None) -> Review:
    """Read ``log_path`` and write figures, summary and HTML page into ``out_dir``."""
    log_path = Path(log_path)
    out = Path(out_dir) if out_dir is not None else log_path.parent / "review"
    out.mkdir(parents=True, exist_ok=True)
    log = read_log(log_path, topics=[STATE, COMMAND, PLANS])
    run = extract_run(log, plan_id)
    sc = spacecraft_for(run, scenario)
    summary = summary_of(run, sc)
    text = format_summary(summary)
    figures = {"overview": figure_overview(run, sc, out / "overview.png"),
               "sky": figure_sky(run, out / "sky.png"),
               "time histories": figure_time_histories(run, sc, out / "time_histories.png")}
    (out / "summary.txt").write_text(text + "\n")
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    page = out / "index.html"
    page.write_text(_html(log_path, text, figures))
    return Review(out, summary, text, figures, page)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-review", description=__doc__.splitlines()[0])
    parser.add_argument("log", help="MCAP file written by the suite's recorder")
    parser.add_argument("--out", default=None, help="output directory (default: review/ next to the log)")
    parser.add_argument("--plan-id", default=None, help="review this executed plan (default: the last one)")
    parser.add_argument("--scenario", default=None,
                        help="scenario for the limits (default: the one the plan names)")
    args = parser.parse_args(argv)
    if not Path(args.log).is_file():
        parser.error(f"log file '{args.log}' does not exist")
    try:
        result = review(args.log, args.out, plan_id=args.plan_id, scenario=args.scenario)
    except ValueError as err:
        print(f"att-review: {err}", file=sys.stderr)
        return 1
    print(result.text)
    for name, p in result.figures.items():
        print(f"figure ({name}): {p}")
    print(f"HTML: {result.html}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
