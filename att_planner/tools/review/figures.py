"""The review's figures (matplotlib, Agg): the sky plot, time histories and the overview. Zones
(the plan's cones and zones, :func:`.summary.zone_sky_for`) are drawn where the simulator flew
them: a moving zone at the plan's start and end with the track of its axis, margins at each
recorded time against the zones' true positions."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from att_msgs_py.types import ControlKind, Interpolation, Plan
from att_planner.cones import boresight
from att_planner.control import tracking
from att_planner.tools.review.run import MODE_NAMES, Run, reference_error
from att_planner.tools.review.summary import body_torque_limits, finite_limit
from att_planner.zones import FittedZones, same_axis
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft


def _basis(center: np.ndarray):
    """Projection axes about ``center``: e1 = z × c (east-like), e2 = c × e1 (north-like, +Z up)."""
    c = np.asarray(center, float) / np.linalg.norm(center)
    e1, e2 = rot.orthonormal_basis(c, references=((0.0, 0.0, -1.0), (-1.0, 0.0, 0.0)))
    return e1, e2, c


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


def _planned_path(plan: Plan, n: int = 400) -> np.ndarray:
    ts = np.linspace(plan.t[0], plan.t[-1], n)
    return np.array([tracking.plan_reference(plan, t).q_RN for t in ts])


CONE_COLORS = ["#d62728", "#1f77b4", "#7f7f7f", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf"]
TRACK_POINTS = 120          # samples of a moving zone's axis track over the maneuver
END_RING = (0, (7, 3))      # line style of a moving zone where it is at the plan's end (long dashes)


def _draw_cap(ax, direction, half_angle: float, center: np.ndarray, color: str, *, fill: bool, ls: str = "-",
              lw: float = 1.2) -> None:
    """The ring of a cap on the projection about ``center``, shaded inside when ``fill`` (a cap
    holding the projection's antipode is shaded between its ring and the rim)."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    ring = equal_area(small_circle(direction, half_angle), center)
    if fill and np.arccos(np.clip(-center @ direction, -1, 1)) < half_angle:
        rim = 2.0 * np.stack([np.cos(np.linspace(0, 2 * np.pi, 361)), np.sin(np.linspace(0, 2 * np.pi, 361))], 1)
        # the hole must wind against the rim (matplotlib fills by the non-zero winding rule)
        winding = np.sum(ring[:-1, 0] * ring[1:, 1] - ring[1:, 0] * ring[:-1, 1])
        verts = np.vstack([rim, ring[::-1] if winding > 0 else ring])
        codes = ([MplPath.MOVETO] + [MplPath.LINETO] * 360) * 2
        ax.add_patch(PathPatch(MplPath(verts, codes), facecolor=color, alpha=0.18, edgecolor="none"))
    elif fill:
        ax.fill(ring[:, 0], ring[:, 1], color=color, alpha=0.18, lw=0)
    ax.plot(ring[:, 0], ring[:, 1], color=color, lw=lw, ls=ls)


def _zone_end_time(run: Run) -> float:
    """Where a moving zone's second ring and its track end: the plan's end for a maneuver, else
    the segment's."""
    return float(run.plan.duration) if run.kind == "maneuver" else float(run.t[-1])


def _draw_zones(ax, run: Run, zones: FittedZones, sensor: np.ndarray, center: np.ndarray) -> None:
    """Every zone: a fixed one as its shaded cap; a moving one shaded where it is at the start, a
    long-dashed ring where it is at the end and the track of its axis in between. Keep-in zones are
    dash-dot rings (outside is forbidden); zones of another sensor than the plotted one are thin."""
    t_end = _zone_end_time(run)
    ts = np.linspace(0.0, t_end, TRACK_POINTS)
    axes, half = zones.true_axes(ts), zones.true_half_angles(ts)
    for j, zone in enumerate(zones.zones):
        color = CONE_COLORS[j % len(CONE_COLORS)]
        own = same_axis(zone.sensor_axis, sensor)
        ls, lw = ("-." if zone.keep_in else "-"), (1.2 if own else 0.7)
        a0 = axes[0, j] / np.linalg.norm(axes[0, j])
        _draw_cap(ax, a0, half[0, j], center, color, fill=own and not zone.keep_in, ls=ls, lw=lw)
        label = f"{zone.name}\n{math.degrees(half[0, j]):.0f}°" + (" keep-in" if zone.keep_in else "")
        if zone.body != "inertial":
            a1 = axes[-1, j] / np.linalg.norm(axes[-1, j])
            _draw_cap(ax, a1, half[-1, j], center, color, fill=False, ls=END_RING, lw=0.9)
            track = equal_area(axes[:, j] / np.linalg.norm(axes[:, j], axis=1, keepdims=True), center)
            ax.plot(track[:, 0], track[:, 1], color=color, lw=1.6, alpha=0.8)
            ax.annotate("", track[-1], track[-2], arrowprops=dict(arrowstyle="->", color=color, lw=1.4))
        if not own:
            label += f"\nsensor {np.round(zone.sensor_axis, 2).tolist()}"
        cx, cy = equal_area(a0, center)
        ax.text(cx, cy, label, color=color, fontsize=7 if not own else 8, ha="center", va="center", weight="bold")


def plot_sky(ax, run: Run, zones: FittedZones | None = None) -> None:
    """Boresight path on the celestial sphere with the zones (moving ones at start and end, with
    their track), start/goal and closest approaches (true zone positions at each recorded time).
    Other sensors' boresights are drawn thin and dotted."""
    from matplotlib.patches import Circle

    plan = run.plan
    sensor = plan.sensor_axis if plan is not None else np.array([1.0, 0.0, 0.0])
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
    has_zones = zones is not None and bool(zones.zones)
    if has_zones:
        _draw_zones(ax, run, zones, sensor, center)
    if plan is not None and run.kind == "maneuver":
        planned = equal_area(boresight(_planned_path(plan), sensor), center)
        ax.plot(planned[:, 0], planned[:, 1], "--", color="0.3", lw=1.0, label="planned")
    xy = equal_area(path, center)
    ax.plot(xy[:, 0], xy[:, 1], color="k", lw=1.8, label="recorded")
    others = {}
    if has_zones:
        for z in zones.zones:
            if not same_axis(z.sensor_axis, sensor):
                others.setdefault(np.round(z.sensor_axis / np.linalg.norm(z.sensor_axis), 9).tobytes(), z.sensor_axis)
    for s_other in others.values():
        other = boresight(run.q, s_other)
        oxy = equal_area(other / np.linalg.norm(other, axis=1, keepdims=True), center)
        ax.plot(oxy[:, 0], oxy[:, 1], ":", color="0.35", lw=1.0,
                label=f"sensor {np.round(s_other, 2).tolist()} (recorded)")
    ax.plot(*xy[0], "o", color="tab:green", ms=12, mfc="none", mew=2.5, label="start", zorder=7)
    gx, gy = equal_area(goal_dir, center)
    ax.plot(gx, gy, "*", color="tab:orange", ms=13, label="goal", zorder=7)
    if has_zones:
        m = zones.margins(run.t, run.q, true=True)
        for j, zone in enumerate(zones.zones):
            k = int(np.argmin(m[:, j]))
            color = CONE_COLORS[j % len(CONE_COLORS)]
            b = boresight(run.q[k], zone.sensor_axis)
            pk = equal_area(b / np.linalg.norm(b), center)
            ax.plot(*pk, "x", color=color, ms=9, mew=2, zorder=6,
                    label=f"closest to {zones.names[j]}: {math.degrees(m[k, j]):.2f}° at {run.t[k]:.0f} s")
            outward = pk / max(np.linalg.norm(pk), 1e-9)
            ax.annotate(f"{math.degrees(m[k, j]):.2f}°", pk, xytext=tuple(14 * outward + (0, -4 * j)),
                        textcoords="offset points", fontsize=8, color=color, weight="bold", ha="center")
    ax.set_xlim(-2.08, 2.08)
    ax.set_ylim(-2.08, 2.08)
    ax.set_aspect("equal")
    ax.axis("off")
    if has_zones and zones.moving:
        ax.plot([], [], color="0.4", ls=END_RING, lw=0.9, label="moving zone at the plan's end (shaded: start)")
        ax.plot([], [], color="0.4", lw=1.6, label="moving zone's axis track")
    ax.legend(loc="lower left", fontsize=7, frameon=False, bbox_to_anchor=(-0.02, -0.04))
    ax.set_title("Boresight on the sky (equal-area, closest approach ×)" if plan is not None
                 else "Body x axis on the sky (no plan in the log)", fontsize=10)


def _limits(ax, limit, label=None, color="r", ls="--"):
    if limit is not None:
        for sign in (1, -1):
            ax.axhline(sign * limit, color=color, ls=ls, lw=0.8, label=label if sign == 1 else None)


def draw_marks(ax, marks: list, labels: bool = False) -> None:
    """Events (t, label, colour) as vertical lines (``labels``: named in the axes' legend): the faults
    injected, detected and the re-plans flown (:func:`att_planner.tools.review.faults.marks`)."""
    for t, label, color in marks:
        ax.axvline(t, color=color, ls="-.", lw=1.0, label=f"t = {t:.1f} s: {label}" if labels else None)
    if labels and marks:
        ax.legend(loc="center right", fontsize=6)


def _maneuver_end(ax, run):
    if run.kind == "maneuver":
        ax.axvline(run.plan.duration, color="0.5", ls=":", lw=0.8)


AXES = ("x", "y", "z")


def plot_attitude_error(ax, run: Run) -> None:
    if run.goal is not None:
        ax.semilogy(run.t, np.maximum(np.degrees(rot.angle_between(run.q, run.goal)), 1e-6), label="to goal")
    if run.kind == "maneuver":
        ax.semilogy(run.t, np.maximum(np.degrees(reference_error(run)), 1e-6), label="to plan reference")
    ax.set_ylabel("attitude error [deg]")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper right", fontsize=7)
    else:
        ax.text(0.5, 0.5, "no goal and no plan in the reviewed segment", transform=ax.transAxes, ha="center",
                va="center", fontsize=8, color="0.4")


def plot_rates(ax, run: Run) -> None:
    for i in range(3):
        ax.plot(run.t, np.degrees(run.omega[:, i]), label=f"ω{AXES[i]}")
    if run.kind == "maneuver":
        ax.set_prop_cycle(None)
        for i in range(3):
            ax.plot(run.plan.t, np.degrees(run.plan.omega[:, i]), ls="--", lw=0.8)
    ax.set_ylabel("body rate [deg/s]")
    ax.legend(loc="upper right", fontsize=7, ncol=3)


def plot_body_torque(ax, run: Run, sc: Spacecraft | None) -> None:
    for i in range(3):
        ax.plot(run.t, run.body_torque[:, i], lw=1.0, label=f"applied {AXES[i]}")
    if run.kind == "maneuver" and run.plan.control_kind != ControlKind.WHEEL_TORQUE:
        ax.set_prop_cycle(None)
        step = "post" if run.plan.interpolation == Interpolation.ZOH else None
        for i in range(3):
            if step:
                ax.step(run.plan.t, run.plan.torque[:, i], where="post", ls="--", lw=0.8)
            else:
                ax.plot(run.plan.t, run.plan.torque[:, i], ls="--", lw=0.8)
    planning, actuator = body_torque_limits(sc)
    if planning != actuator:
        _limits(ax, planning, "planning limit", color="tab:orange", ls=":")
    _limits(ax, actuator, "actuator limit")
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
    _limits(ax, finite_limit(sc.wheel_torque_max) if sc else None, "limit")
    ax.set_ylabel("wheel torque [N m]\n(— applied, -- cmd)")
    _wheel_legend(ax, run)


def plot_wheel_speeds(ax, run: Run, sc: Spacecraft | None) -> None:
    for i in range(run.wheel_speeds.shape[1]):
        ax.plot(run.t, run.wheel_speeds[:, i], label=f"wheel {i + 1}")
    _limits(ax, finite_limit(sc.wheel_speed_max) if sc else None, "limit")
    ax.set_ylabel("wheel speed [rad/s]")
    _wheel_legend(ax, run)


def plot_dipole(ax, run: Run, sc: Spacecraft | None) -> None:
    for i in range(3):
        line, = ax.plot(run.t, run.dipole[:, i], lw=1.0, label=f"m{AXES[i]}")
        if len(run.cmd_t):
            ax.plot(run.cmd_t, run.cmd_dipole[:, i], ls="--", lw=0.8, color=line.get_color())
    _limits(ax, finite_limit(sc.dipole_max) if sc else None, "saturation")
    ax.set_ylabel("dipole [A m²]\n(— applied, -- cmd)")
    ax.legend(loc="upper right", fontsize=7, ncol=2)


def plot_margins(ax, run: Run, zones: FittedZones | None = None) -> None:
    """Margin to every cone and zone (moving zones at their true positions at each recorded time)."""
    if zones is not None and zones.zones:
        m = np.degrees(zones.margins(run.t, run.q, true=True))
        for j, name in enumerate(zones.names):
            ax.plot(run.t, m[:, j], color=CONE_COLORS[j % len(CONE_COLORS)], lw=1.0,
                    ls="-." if zones.keep_in[j] else "-", label=name + (" (in)" if zones.keep_in[j] else ""))
        ax.plot(run.t, m.min(axis=1), color="k", lw=0.9, ls="--", label="minimum")
        ax.axhline(0.0, color="k", lw=0.6)
        ax.legend(loc="upper right", fontsize=7, ncol=2)
    else:
        ax.text(0.5, 0.5, "no keep-out cones or zones in the log", ha="center", va="center", transform=ax.transAxes)
    ax.set_ylabel("zone margin [deg]" + ("\n(true positions)" if zones is not None and zones.moving else ""))


def plot_modes(ax, run: Run) -> None:
    if len(run.cmd_t):
        ax.step(run.cmd_t, run.cmd_mode, where="post", label="controller mode")
    if np.any(run.command_timeout):
        ax.plot(run.t[run.command_timeout], np.full(int(np.sum(run.command_timeout)), -0.5), "r|",
                label="command timeout")
    ax.set_yticks(list(MODE_NAMES), list(MODE_NAMES.values()), fontsize=7)
    ax.set_ylim(-1, max(MODE_NAMES) + 0.5)
    ax.legend(loc="upper right", fontsize=7)


def _figure(*args, **kwargs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt, plt.figure(*args, **kwargs)


def _save(plt, fig, path: Path, dpi: int = 90) -> Path:
    """Lay ``fig`` out, write it to ``path`` and close it."""
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def _time_label(run: Run) -> str:
    return f"t [s] from sim time {run.t0:.1f} s" + (" (dotted: plan end, then settle/hold)" if run.kind == "maneuver"
                                                    else "")


def figure_time_histories(run: Run, sc: Spacecraft | None, path: Path, zones: FittedZones | None = None) -> Path:
    plt, fig = _figure(figsize=(13, 12))
    axes = fig.subplots(4, 2, sharex=True)
    plot_attitude_error(axes[0, 0], run)
    plot_rates(axes[0, 1], run)
    plot_body_torque(axes[1, 0], run, sc)
    plot_wheel_torque(axes[1, 1], run, sc)
    plot_wheel_speeds(axes[2, 0], run, sc)
    plot_dipole(axes[2, 1], run, sc)
    plot_margins(axes[3, 0], run, zones)
    plot_modes(axes[3, 1], run)
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
        _maneuver_end(ax, run)
        draw_marks(ax, run.marks, labels=ax is axes[3, 1])
    for ax in axes[-1]:
        ax.set_xlabel(_time_label(run))
    fig.suptitle(_title(run))
    return _save(plt, fig, path)


def figure_sky(run: Run, path: Path, zones: FittedZones | None = None) -> Path:
    plt, fig = _figure(figsize=(7.5, 7.5))
    plot_sky(fig.add_subplot(1, 1, 1), run, zones)
    return _save(plt, fig, path, dpi=100)


def figure_overview(run: Run, sc: Spacecraft | None, path: Path, zones: FittedZones | None = None) -> Path:
    """Screenshot-sized digest: the sky on the left; margins, body torque, wheel speeds on the right."""
    plt, fig = _figure(figsize=(12, 6.2))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.0, 1.15])
    plot_sky(fig.add_subplot(grid[:, 0]), run, zones)
    right = [fig.add_subplot(grid[0, 1])]
    right += [fig.add_subplot(grid[i, 1], sharex=right[0]) for i in (1, 2)]
    plot_margins(right[0], run, zones)
    plot_body_torque(right[1], run, sc)
    plot_wheel_speeds(right[2], run, sc)
    for ax in right:
        ax.grid(alpha=0.3)
        _maneuver_end(ax, run)
    right[2].set_xlabel(_time_label(run))
    fig.suptitle(_title(run), fontsize=11)
    return _save(plt, fig, path, dpi=100)


def _title(run: Run) -> str:
    if run.kind == "maneuver":
        p = run.plan
        return f"{p.method} plan {p.plan_id} ({p.spacecraft}), {p.duration:.1f} s"
    return {"magnetorquer": "magnetorquer PD run", "log": "whole log"}[run.kind]
