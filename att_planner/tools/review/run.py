"""The reviewed run, extracted from a read log (numpy only)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from att_msgs_py import convert
from att_msgs_py.log import TopicLog
from att_msgs_py.topics import COMMAND, PLANS, STATE
from att_msgs_py.types import ControlMode, Plan
from att_planner.control import tracking
from att_sim.models import rotations as rot

MODE_NAMES = {ControlMode.IDLE: "idle", ControlMode.MAGNETORQUER_PD: "magnetorquer PD",
              ControlMode.PLAN_TRACKING: "plan tracking", ControlMode.SAFE: "safe", ControlMode.POINTING: "pointing"}
SETTLING_THRESHOLD = 0.05        # ν of Bruni & Celani: settled when every |q_i| (vector part) stays ≤ ν


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
    plan: Plan | None = None       # the executed (or last recorded) plan
    goal_end: float | None = None  # maneuvers: t of the last command carrying the plan id (the execute goal's end)
    marks: list = field(default_factory=list)   # (t, label, colour): events drawn on the time histories


def plans_of(log: dict[str, TopicLog]) -> list[Plan]:
    """Every recorded plan, from the decoded messages :func:`~att_msgs_py.log.read_log` keeps."""
    topic = log.get(PLANS)
    if topic is None:
        return []
    if len(topic.messages) != len(topic):
        raise ValueError(f"read the log keeping the decoded {PLANS} messages (read_log's default)")
    return [convert.plan_from_msg(m) for m in topic.messages]


def _segment(cmd_t, cmd_mode, cmd_plan, plan_id):
    """[start, end) command indices of the execution of ``plan_id`` and the hold after it: from the
    execute goal's first command (the first carrying the plan id) through the plan, the settle time
    (still carrying it) and the hold of the final attitude after the goal ended (plan tracking, no
    plan id), up to the next change of mode or plan."""
    idx = np.flatnonzero(cmd_plan == plan_id)
    start, last = idx[0], idx[-1]
    after = np.flatnonzero((np.arange(len(cmd_t)) > last)
                           & ((cmd_mode != ControlMode.PLAN_TRACKING) | ((cmd_plan != "") & (cmd_plan != plan_id))))
    return start, (after[0] if after.size else len(cmd_t))


def extract_run(log: dict[str, TopicLog], plan_id: str | None = None, through: str | None = None) -> Run:
    """The reviewed segment: plan ``plan_id`` (default: the last executed plan) from its first
    command to the next change of mode or plan (``through``: a plan executed after it, up to the change
    after that one: a maneuver and its re-plans); else the last magnetorquer-PD run; else the log."""
    if STATE not in log or len(log[STATE]) == 0:
        raise ValueError(f"the log has no {STATE} messages to review")
    state, cmd = log[STATE], log.get(COMMAND)
    plans = plans_of(log)
    t_state = np.asarray(state["header.stamp"], float)
    if cmd is not None and len(cmd):
        cmd_t, cmd_mode = np.asarray(cmd["header.stamp"], float), np.asarray(cmd["mode"], int)
        cmd_plan = np.asarray(cmd["plan_id"], dtype=str)
        cmd_wheels, cmd_dipole = np.asarray(cmd["wheel_torques"], float), np.asarray(cmd["dipole"], float)
    else:
        cmd_t, cmd_mode, cmd_plan = np.zeros(0), np.zeros(0, int), np.zeros(0, dtype=str)
        cmd_wheels, cmd_dipole = np.zeros((0, state["wheel_speeds"].shape[1])), np.zeros((0, 3))
    executed = list(dict.fromkeys(p for p in cmd_plan if p))
    by_id = {p.plan_id: p for p in plans}
    if plan_id is not None and plan_id not in executed:
        raise ValueError(f"plan_id '{plan_id}' was not executed in this log "
                         f"(executed: {', '.join(executed) or 'none'})")
    plan_id = plan_id or next((p for p in reversed(executed) if p in by_id), None)
    plan, goal, goal_end = None, None, None
    if plan_id is not None:
        kind, plan = "maneuver", by_id[plan_id]
        i0, i1 = _segment(cmd_t, cmd_mode, cmd_plan, plan_id)
        if through is not None and through in executed:
            i1 = max(i1, _segment(cmd_t, cmd_mode, cmd_plan, through)[1])
        goal, goal_end = plan.q[-1], float(cmd_t[np.flatnonzero(cmd_plan == plan_id)[-1]] - cmd_t[i0])
    elif np.any(cmd_mode == ControlMode.MAGNETORQUER_PD):
        kind, goal = "magnetorquer", rot.IDENTITY.copy()
        on = np.flatnonzero(cmd_mode == ControlMode.MAGNETORQUER_PD)
        i1 = on[-1] + 1
        breaks = np.flatnonzero(cmd_mode[:i1] != ControlMode.MAGNETORQUER_PD)
        i0 = breaks[-1] + 1 if breaks.size else 0
        plan = plans[-1] if plans else None
    else:
        kind, i0, i1 = "log", 0, len(cmd_t)
        plan = plans[-1] if plans else None
        goal = plan.q[-1] if plan else None
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
        cmd_dipole=cmd_dipole[ckeep], goal=goal, plan=plan, goal_end=goal_end)


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
    return np.array([rot.angle_between(q, tracking.plan_reference(run.plan, t).q_RN) for t, q in zip(run.t, run.q)])
