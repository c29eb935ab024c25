"""The faults of a recorded run (numpy only): what the truth injected, what the flight software detected
and how it responded, marked on the time histories.

:func:`faults_of` reads ``/simulator/faults`` (each fault the truth started: onset, component, index,
kind; evaluation only), ``/controller/faults`` and ``/estimator/faults`` (each fault the controller's
or the estimator's monitor declared or cleared: detection time, detector, evidence, response), and
the plans the controller flew after the first detection (the re-plans on the healthy wheels: their
first command). Each detection is paired
with the injection it isolated (same component and index, the latest onset before it) for its
latency. :func:`marks` gives the vertical lines the time histories draw
(:func:`att_planner.tools.review.figures.draw_marks`: injected red, detected orange, re-plan flown
green), :func:`faults_summary` the summary's ``faults`` entry; :func:`interrupted_plan` the maneuver
the recovery re-planned, which the review covers with its re-plans.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.log import TopicLog
from att_msgs_py.topics import CONTROLLER_FAULTS, ESTIMATOR_FAULTS, SIM_FAULTS

TOPICS = (SIM_FAULTS, CONTROLLER_FAULTS, ESTIMATOR_FAULTS)
COLORS = {"injected": "tab:red", "detected": "tab:orange", "cleared": "tab:cyan", "replan": "tab:green"}


@dataclass
class FaultLog:
    """Injections, detections and re-plans (times in s of sim time)."""

    injected: list[dict] = field(default_factory=list)    # t, component, index, kind, source
    detected: list[dict] = field(default_factory=list)    # t, fault_id, component, index, detector, evidence,
    #                                                       response, active, latency_s (None: no injection paired)
    replans: list[dict] = field(default_factory=list)     # t, plan_id: plans first flown after the first detection


def _column(topic: TopicLog, name: str) -> list:
    return list(np.asarray(topic[name]).tolist())


def faults_of(log: dict[str, TopicLog], cmd_t: np.ndarray | None = None, cmd_plan: np.ndarray | None = None
              ) -> FaultLog | None:
    """The faults of ``log`` (None when it has neither topic); ``cmd_t``/``cmd_plan``: the commands'
    times and plan ids, for the re-plans flown after the first detection."""
    sim = log.get(SIM_FAULTS)
    flights = [log[t] for t in (CONTROLLER_FAULTS, ESTIMATOR_FAULTS) if t in log and len(log[t])]
    if not (sim is not None and len(sim)) and not flights:
        return None
    out = FaultLog()
    if sim is not None and len(sim):
        for t, c, i, k, s in zip(*(_column(sim, n) for n in ("header.stamp", "component", "index", "kind", "source"))):
            out.injected.append({"t": float(t), "component": str(c), "index": int(i), "kind": str(k), "source": str(s)})
    for flight in flights:
        names = ("detected_at", "fault_id", "component", "index", "detector", "evidence", "response", "active",
                 "header.stamp")
        for at, fid, c, i, d, e, r, a, stamp in zip(*(_column(flight, n) for n in names)):
            onsets = [f["t"] for f in out.injected if (f["component"], f["index"]) == (c, i) and f["t"] <= at]
            t = float(at) if a else float(stamp)
            out.detected.append({"t": t, "fault_id": str(fid), "component": str(c), "index": int(i),
                                 "detector": str(d), "evidence": str(e), "response": str(r), "active": bool(a),
                                 "latency_s": float(at - max(onsets)) if onsets and a else None})
    out.detected.sort(key=lambda d: d["t"])
    first = min((d["t"] for d in out.detected if d["active"]), default=None)
    if first is not None and cmd_t is not None and len(cmd_t):
        seen = set(np.asarray(cmd_plan)[np.asarray(cmd_t) <= first].tolist())
        for t, p in zip(np.asarray(cmd_t).tolist(), np.asarray(cmd_plan).tolist()):
            if p and p not in seen:
                seen.add(p)
                out.replans.append({"t": float(t), "plan_id": str(p)})
    return out


def marks(faults: FaultLog | None, t0: float) -> list[tuple[float, str, str]]:
    """(t from ``t0``, label, colour) of each injection, detection (or clearing) and re-plan flown."""
    if faults is None:
        return []
    out = [(f["t"] - t0, f"fault injected: {f['component']} {f['index']} {f['kind']}", COLORS["injected"])
           for f in faults.injected]
    out += [(d["t"] - t0, f"{'detected' if d['active'] else 'cleared'}: {d['fault_id']} on {d['component']} "
                          f"{d['index']} -> {d['response']}", COLORS["detected" if d["active"] else "cleared"])
            for d in faults.detected]
    out += [(r["t"] - t0, f"re-plan {r['plan_id']} flown", COLORS["replan"]) for r in faults.replans]
    return out


def faults_summary(faults: FaultLog) -> dict:
    """The summary's ``faults``: every injection, detection (with its latency) and re-plan flown."""
    return {"injected": faults.injected, "detected": faults.detected,
            "replans": [r["plan_id"] for r in faults.replans]}


def interrupted_plan(faults: FaultLog | None, cmd_t: np.ndarray, cmd_plan: np.ndarray) -> str | None:
    """The plan in flight at the first detection, when plans were flown after it (the maneuver the
    recovery re-planned: the review covers it and its re-plans); else None."""
    if faults is None or not faults.replans:
        return None
    first = min(d["t"] for d in faults.detected if d["active"])
    before = [p for t, p in zip(np.asarray(cmd_t).tolist(), np.asarray(cmd_plan).tolist()) if p and t <= first]
    return before[-1] if before else None
