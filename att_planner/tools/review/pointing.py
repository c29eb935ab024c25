"""Pointing and momentum of a recorded run: numpy, and one figure.

:func:`pointing_of` reads the controller's status (mode, guidance, attitude error from its
reference, momentum dumping), the truth state (wheel speeds relative to the body, as their limit
counts them) and the commands (dipoles), and :func:`pointing_summary` gives the figures of
``att-bench momentum``: pointing error rms and maximum while pointing, peak wheel speed against
the limit, the fraction of commands with a dipole, the time a wheel first reached its limit.
:func:`figure_pointing` draws the review's ``pointing.png``: the mode timeline with the guidance,
the pointing error, each wheel's momentum against its limit, the dipoles.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from att_msgs_py.log import TopicLog
from att_msgs_py.topics import COMMAND, CONTROLLER_STATUS, STATE
from att_msgs_py.types import ControlMode
from att_planner.tools.review.run import MODE_NAMES
from att_sim.models.dynamics import Spacecraft

TOPICS = [STATE, COMMAND, CONTROLLER_STATUS]
SATURATED = 0.999                  # of the wheel speed limit: a wheel at its limit


@dataclass
class PointingRun:
    t: np.ndarray                  # (n,) s of sim time, status instants
    mode: np.ndarray               # (n,)
    guidance: list                 # (n,) the pointing mode's kind ('' when not pointing)
    error: np.ndarray              # (n,) rad from the reference (NaN without one)
    dumping: np.ndarray            # (n,) bool
    state_t: np.ndarray            # (k,)
    wheel_momentum: np.ndarray     # (k, N) N m s, relative speeds × I_w
    cmd_t: np.ndarray              # (m,)
    dipole: np.ndarray             # (m, 3) A m², commanded
    limit: float                   # N m s per wheel (I_w × wheel_speed_max)


def pointing_of(log: dict[str, TopicLog], sc: Spacecraft) -> PointingRun | None:
    """The pointing figures of a log with a pointing mode in its controller status (else None)."""
    status = log.get(CONTROLLER_STATUS)
    if status is None or not np.any(np.asarray(status["mode"]) == ControlMode.POINTING):
        return None
    state, cmd = log[STATE], log[COMMAND]
    relative = np.asarray(state["wheel_speeds"]) - np.asarray(state["body_rate"]) @ sc.wheel_axes
    return PointingRun(np.asarray(status["header.stamp"]), np.asarray(status["mode"]), list(status["guidance"]),
                       np.asarray(status["attitude_error"], float), np.asarray(status["dumping"], bool),
                       np.asarray(state["header.stamp"]), relative * sc.wheel_inertia,
                       np.asarray(cmd["header.stamp"]), np.asarray(cmd["dipole"]),
                       sc.wheel_inertia * sc.wheel_speed_max)


def pointing_summary(run: PointingRun, settle: float = 0.0) -> dict:
    """Pointing error while pointing (deg; from ``settle`` s after the first pointing instant on),
    peak wheel momentum against the limit, dipole duty, and the sim time a wheel first reached its
    limit (None: never)."""
    pointing = run.mode == ControlMode.POINTING
    start = run.t[pointing][0] if np.any(pointing) else math.inf
    error = run.error[pointing & np.isfinite(run.error) & (run.t >= start + settle)]
    ratio = np.max(np.abs(run.wheel_momentum), axis=1) / run.limit
    saturated = np.flatnonzero(ratio >= SATURATED)
    return {"pointing_seconds": float(np.sum(pointing) * np.median(np.diff(run.t))) if len(run.t) > 1 else 0.0,
            "pointing_error_rms_deg": float(np.degrees(np.sqrt(np.mean(error**2)))) if error.size else None,
            "pointing_error_max_deg": float(np.degrees(error.max())) if error.size else None,
            "peak_wheel_speed_ratio": float(ratio.max()),
            "dipole_duty": float(np.mean(np.any(run.dipole != 0.0, axis=1))) if len(run.dipole) else 0.0,
            "saturation_time_s": float(run.state_t[saturated[0]]) if saturated.size else None}


def figure_pointing(run: PointingRun, path: Path, t0: float = 0.0) -> Path:
    """``pointing.png``: mode timeline, pointing error, wheel momentum against its limit, dipoles."""
    from att_planner.tools.review.figures import _figure, _save

    plt, fig = _figure(figsize=(11, 11))
    axes = fig.subplots(4, 1, sharex=True)
    hours = 3600.0 if run.t[-1] - run.t[0] > 3 * 3600 else 1.0
    unit = "h" if hours > 1 else "s"
    axes[0].step((run.t - t0) / hours, run.mode, where="post", color="k", lw=1.0)
    axes[0].set_yticks(list(MODE_NAMES), list(MODE_NAMES.values()), fontsize=7)
    kinds = sorted({g for g in run.guidance if g})
    axes[0].set_title(f"guidance: {', '.join(kinds) or 'none'}; momentum dumping "
                      f"{'on' if np.any(run.dumping) else 'off'}", fontsize=9)
    axes[1].plot((run.t - t0) / hours, np.degrees(run.error) * 3600, lw=0.7)
    axes[1].set_ylabel("pointing error\n(arcsec)")
    for i in range(run.wheel_momentum.shape[1]):
        axes[2].plot((run.state_t - t0) / hours, run.wheel_momentum[:, i], lw=0.8, label=f"wheel {i}")
    for sign in (1, -1):
        axes[2].axhline(sign * run.limit, color="r", ls="--", lw=0.8)
    axes[2].set_ylabel("wheel momentum\n(N m s; dashed: limit)")
    axes[2].legend(ncol=4, fontsize=7, loc="upper right")
    for i, axis in enumerate("xyz"):
        axes[3].plot((run.cmd_t - t0) / hours, run.dipole[:, i], lw=0.6, label=axis)
    axes[3].set_ylabel("dipole commanded\n(A m²)")
    axes[3].legend(ncol=3, fontsize=7, loc="upper right")
    axes[-1].set_xlabel(f"time ({unit})")
    for ax in axes:
        ax.grid(alpha=0.3)
    return _save(plt, fig, path)
