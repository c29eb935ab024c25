"""faults: each hardware fault of the truth flown through in process, and the false alarms without one.

``att-bench faults [--scenario leo_pyramid] [--runs 1000] [--workers 1] --json PATH``. On the
scenario's demo slew, prepared as :mod:`.rtf` flies it (the loop runs from the epoch to the start
lead, the truth is reset to the initial attitude at rest, the plan made for its start epoch), with
the shipped fault table on (:class:`~att_planner.tools.closed_loop.ClosedLoop` ``fault_table=``),
each fault type of the truth (:data:`FAULTS`) is injected at three instants (:data:`SLEW_FRACTIONS`
of the slew; :data:`HOLD_AT_S` into a nadir hold) and flown on the estimate, with the re-planning
recovery (:func:`att_planner.tools.fault_flight.fly`) during the slew. The nadir hold is the
controller's ``nadir`` pointing mode (:data:`NADIR`, commanded as soon as the estimate allows) from
the slew's start epoch, in a loop of its own flown from the epoch on nadir: at the start lead the
truth is reset onto the nadir law's attitude and rate (the wheels' spin rates kept), so that the hold
is steady by the time the faults start.
Per case: whether the fault was detected and its latency (s of sim time from the onset to the first
report), the component the first report isolated and whether it is the faulty one, the response
taken, and the outcome: final pointing error (truth to the goal, or to the nadir law's attitude), the
worst zone margin from the start (truth, the zones as they are in the sky), the time lost on the
slew (its end against the nominal plan's), the slew completed, safe mode reached and held, and in
safe mode (flown ``--safe-hold-s`` once reached) the worst zone margin at its entry and from then
on, the Sun-pointing error and the body rate at the end.

A star tracker's bias jump is *observable* only if the tracker gave a valid measurement from the
onset on (:func:`readings_after`); a case without one (the tracker blinded to the end) is counted apart and
must be harmless (no zone entered, the slew completed, no safe mode); the others must be detected in
time and isolated right.

The false-alarm campaign flies ``--runs`` dispersed fault-free runs of a Monte Carlo campaign
(``--campaign``; :func:`att_planner.tools.monte_carlo.run.fly_batch`, the campaign's own draws) with
the fault table on, and counts the runs with any fault report (target 0); the fault-free slew and
nadir hold (the cases' baselines) report their fault ids too (``baseline_reports``, target none).
"""
from __future__ import annotations

import copy
import math
import os
import sys
import time
from dataclasses import dataclass
from datetime import timedelta
from pathlib import Path

import numpy as np

from att_msgs_py.types import ControlMode, FaultSource, Plan, PointingMode
from att_planner.fdir import table as fault_tables
from att_planner.guidance import reference
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.service.warm import maneuver_from_scenario
from att_planner.tools import fault_flight
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process
from att_planner.tools.demo import zone_margins
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world
from att_sim.models.config_faults import spec

JSON_INDENT = 1
SLEW_FRACTIONS = (0.2, 0.5, 0.8)        # of the nominal slew's duration
HOLD_AT_S = (20.0, 60.0, 100.0)         # s into the hold
HOLD_AFTER_S = 90.0                     # s flown after the onset in a hold
SLEW_AFTER_S = 900.0                    # s past the nominal end the recovery may take
LATENCY_S = {"wheel": 5.0, "gyro": 5.0}  # the issue's latency targets; the others 30 s
OTHER_LATENCY_S = 30.0
ZONE_TOLERANCE = math.radians(0.01)     # rad: a margin this much below the fault-free flight's is the fault's
DEG_S = math.radians(0.01)              # rad/s: the gyro bias step
CAMPAIGN = Path(__file__).resolve().parents[3] / "campaigns" / "swift_demo.yaml"
NADIR = PointingMode("nadir")           # the hold's pointing mode (its default axes: +z on nadir, +x along track)

# name: (component, index, kind, parameters), the components (component, index) a right isolation names
FAULTS = {
    "wheel seized": (("wheel", 1, "seized", {}), {("wheel", 1)}),
    "wheel off": (("wheel", 1, "off", {}), {("wheel", 1)}),
    "wheel friction x5": (("wheel", 1, "friction", {"factor": 5.0}), {("wheel", 1)}),
    "tachometer stuck": (("wheel", 1, "tachometer_stuck", {}), {("wheel", 1), ("wheel_tachometer", 1)}),
    "star tracker outage": (("star_tracker", 0, "outage", {}), {("star_tracker", 0)}),
    "star tracker bias jump": (("star_tracker", 0, "bias_jump", {"bias_rad": (2e-4, -2e-4, 0.0)}),
                               {("star_tracker", 0)}),
    "star tracker 1 bias jump": (("star_tracker", 1, "bias_jump", {"bias_rad": (2e-4, -2e-4, 0.0)}),
                                 {("star_tracker", 1)}),
    "gyro axis stuck": (("gyro", 0, "axis_stuck", {}), {("gyro", 0)}),
    "gyro bias step": (("gyro", 0, "bias_step", {"bias_rad_s": DEG_S}), {("gyro", 0)}),
    "magnetometer stuck": (("magnetometer", 0, "stuck", {}), {("magnetometer", 0)}),
    "magnetorquer coil open": (("magnetorquer", 0, "coil_open", {}), {("magnetorquer", 0)}),
}


def configure(parser) -> None:
    parser.add_argument("--scenario", default="leo_pyramid", help="a four-wheel scenario with a demo: maneuver")
    parser.add_argument("--runs", type=int, default=1000, help="fault-free dispersed runs of the false-alarm campaign")
    parser.add_argument("--campaign", default=str(CAMPAIGN), help="the Monte Carlo campaign the runs are drawn from")
    parser.add_argument("--batch", type=int, default=20, help="runs flown as one batch")
    parser.add_argument("--faults", default="", help="comma-separated fault names (default every one)")
    parser.add_argument("--instants", type=int, default=3, help="instants per fault and phase (1 to 3)")
    parser.add_argument("--workers", type=int, default=1, help="processes flying the cases")
    parser.add_argument("--safe-hold-s", type=float, default=fault_flight.SAFE_HOLD_S,
                        help="s of sim time safe mode is flown once reached (a hold: at least 90 s after the onset)")


@dataclass
class Setup:
    """The scenario, its demo maneuver, the plan and a loop at the slew's start (the estimate converged);
    ``hold``: a loop at the same epoch holding nadir (its truth on the nadir law since the start lead)."""

    scenario: scen.Scenario
    maneuver: dict
    plan: Plan
    start: float
    loop: ClosedLoop
    hold: ClosedLoop


def prepare(s: scen.Scenario, fault_table=fault_tables.DEFAULT_TABLE) -> Setup:
    """The demo maneuver planned for its start epoch and a loop run to its start (module docstring)."""
    m = maneuver_from_scenario(s)
    loop = ClosedLoop(s, q0=m["q0"], fault_table=fault_table)
    sky = s.epoch is not None and m["start_time"] is not None
    start = float(m["start_time"]) if sky else 10.0
    epoch = (0, 0)
    if sky:
        loop.run(start - m["start_lead"])
        refused = loop.sim.reset(m["q0"], np.zeros(3), [], 0.0)
        if refused is not None:
            raise RuntimeError(f"the simulation refused the reset to the initial attitude: {refused.message}")
        at = (s.epoch + timedelta(seconds=start)).timestamp()
        epoch = (math.floor(at), round((at - math.floor(at)) * 1e9))
    plan = plan_in_process(s, m["q0"], m["qf"], m["sensor"], m["cones"], m["zones"], m["method"], m["time_budget"],
                           epoch=epoch)
    loop.run(start - loop.sim.t)
    return Setup(s, m, plan, start, loop, nadir_hold(s, start, m["start_lead"] if sky else 0.0, fault_table))


def nadir_hold(s: scen.Scenario, start: float, lead: float, fault_table=fault_tables.DEFAULT_TABLE) -> ClosedLoop:
    """A loop holding nadir at ``start`` (module docstring): started on the nadir law's attitude and
    rate (the truth's geometry, the wheels at rest relative to the body), pointing ``nadir`` as soon as
    the estimate allows, the truth reset onto the controller's law's attitude and rate ``lead`` s before
    ``start`` (the wheels' spin rates kept: no step the wheel and momentum detectors would take for a
    fault)."""
    law = law_of(NADIR, PointingGeometry.of(world.Environment.from_scenario(s)), 0.0, rot.IDENTITY)
    ref = reference(law.attitude, 0.0)
    omega = np.asarray(ref.omega_RN_R, float)              # the body on R: its rate in body axes
    loop = ClosedLoop(s, q0=ref.q_RN, omega0=omega, wheel_speed0=s.spacecraft.wheel_axes.T @ omega,
                      fault_table=fault_table)
    while loop.controller.pointing is None and loop.sim.t < start - lead:
        loop.tick()
        if loop.controller.state is not None:
            loop.controller.set_mode(ControlMode.POINTING, NADIR)
    if loop.controller.pointing is None:
        raise RuntimeError(f"the controller refused nadir pointing until {loop.sim.t:g} s")
    loop.run(start - lead - loop.sim.t)
    ref = reference(loop.controller.pointing.attitude, loop.sim.t)
    omega = np.asarray(ref.omega_RN_R, float)              # the body on R: its rate in body axes
    refused = loop.sim.reset(ref.q_RN, omega, loop.sim.x[7:].copy(), 0.0)
    if refused is not None:
        raise RuntimeError(f"the simulation refused the reset onto nadir: {refused.message}")
    loop.run(start - loop.sim.t)
    return loop


def loop_at_start(setup: Setup, phase: str = "slew") -> ClosedLoop:
    """A copy of the setup's loop of ``phase`` (``slew``, ``hold``) at the slew's start (its own truth,
    estimator, controller, monitor)."""
    loop = setup.loop if phase == "slew" else setup.hold
    return copy.deepcopy(loop, {id(loop.key): loop.key})


def flown(setup: Setup, fault, phase: str, instant: float,
          safe_hold_s: float = fault_flight.SAFE_HOLD_S) -> tuple[ClosedLoop, float, dict]:
    """The loop flown with the truth fault ``fault`` ((component, index, kind, parameters); None: none)
    from ``instant`` into ``phase`` (``slew``: a fraction of it; ``hold``: s of the nadir hold): the loop,
    the onset and the slew's figures (completed, time lost, re-plans) and the attitude aimed at (the
    goal; in the hold the nadir law's at the end); safe mode, once reached, flown ``safe_hold_s`` (in
    a hold: to at least :data:`HOLD_AFTER_S` after the onset)."""
    loop = loop_at_start(setup, phase)
    t0, plan = setup.start, setup.plan
    onset = t0 + (instant * plan.duration if phase == "slew" else instant)
    if fault is not None:
        component, index, kind, parameters = fault
        refused = loop.sim.inject(spec(component, index, kind, t_s=onset, **parameters), FaultSource.SERVICE)
        if refused is not None:
            raise RuntimeError(f"fault {fault}: the simulation refused it: {refused.message}")
    figures = {"completed": False, "time_lost_s": math.nan, "replans": [], "goal": setup.maneuver["qf"]}
    if phase == "slew":
        flight = fault_flight.fly(loop, plan, setup.maneuver, t0 + plan.duration + SLEW_AFTER_S + safe_hold_s,
                                  safe_hold_s)
        figures["completed"] = completed = flight.result is not None and flight.result.success
        end = t0 + plan.duration + loop.controller.config.settle_time
        figures["time_lost_s"] = loop.sim.t - end if completed else math.nan
        figures["replans"] = flight.replanner.replans
    else:
        law = loop.controller.pointing
        loop.run(onset + HOLD_AFTER_S - loop.sim.t)
        safe = loop.trace.arrays("t", "mode")
        entered = safe["t"][safe["mode"] == int(ControlMode.SAFE)]
        if entered.size and loop.sim.t < entered[0] + safe_hold_s:
            loop.run(entered[0] + safe_hold_s - loop.sim.t)
        figures["goal"] = law.attitude(loop.sim.t)
    return loop, onset, figures


def baseline(setup: Setup, phase: str) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """The fault-free flight of ``phase`` (the hold to its last case's end): sim times, the worst
    zone margin (rad) up to each, and the fault ids it reported (false alarms: none expected)."""
    loop, _, _ = flown(setup, None, phase, 0.0 if phase == "slew" else HOLD_AT_S[-1])
    a = loop.trace.arrays("t", "q_true")
    _, margins = zone_margins(setup.scenario, setup.maneuver, a["t"], a["q_true"])
    worst = margins.min(axis=1) if margins.size else np.full(len(a["t"]), math.inf)
    return a["t"], np.minimum.accumulate(worst), [r.fault_id for r in loop.monitor.history]


def readings_after(loop: ClosedLoop, scenario: scen.Scenario, fault, onset: float) -> int | None:
    """The valid measurements a star tracker whose measured attitude is faulty (a bias jump) gave from
    the onset on (None: another fault; an outage is seen through the messages that stop coming). A
    tracker blinded (the Earth, the Sun or the Moon in its exclusion) from the onset to the end gives
    none: its fault changes nothing the flight side reads, so nothing can detect it there."""
    component, index, kind = fault[0], fault[1], fault[2]
    if component != "star_tracker" or kind == "outage":
        return None
    name = scenario.sensors.star_trackers[index].name
    return sum(t >= onset for t in loop.tracker_valid.get(name, []))


def case(setup: Setup, name: str, phase: str, instant: float, reference=None,
         safe_hold_s: float = fault_flight.SAFE_HOLD_S) -> dict:
    """Fault ``name`` injected ``instant`` into ``phase``, flown and judged (module docstring);
    ``reference``: the phase's :func:`baseline`, a zone margin the fault-free flight has too is not the fault's."""
    fault, right = FAULTS[name]
    component = fault[0]
    wall = time.perf_counter()
    loop, onset, figures = flown(setup, fault, phase, instant, safe_hold_s)
    t0 = setup.start
    a = loop.trace.arrays("t", "q_true", "mode")
    history = loop.monitor.history
    first = history[0] if history else None
    latency = first.detected_at - onset if first is not None else math.nan
    _, margins = zone_margins(setup.scenario, setup.maneuver, a["t"], a["q_true"])
    worst = float(margins.min()) if margins.size else math.inf
    base = math.inf
    if reference is not None and len(reference[0]):
        base = float(reference[1][min(np.searchsorted(reference[0], a["t"][-1]), len(reference[0]) - 1)])
    safe = np.flatnonzero(a["mode"] == int(ControlMode.SAFE))
    target = LATENCY_S.get(component, OTHER_LATENCY_S)
    in_safe = safe_figures(loop, a, margins, safe)
    seen = readings_after(loop, setup.scenario, fault, onset)
    return {"fault": name, "phase": phase, "instant": instant, "onset_s": onset - t0,
            "truth": {"component": component, "index": fault[1], "kind": fault[2]},
            "readings_after_onset": seen, "observable": seen is None or seen > 0,
            "detected": first is not None, "latency_s": latency, "latency_target_s": target,
            "in_time": first is not None and 0.0 <= latency <= target,
            "isolated": None if first is None else [first.component, int(first.index)],
            "right": first is not None and (first.component, int(first.index)) in right,
            "response": first.response if first is not None else "",
            "reports": [{"t_s": r.t - t0, "fault_id": r.fault_id, "component": r.component, "index": int(r.index),
                         "response": r.response, "active": bool(r.active), "detected_at_s": r.detected_at - t0,
                         "evidence": r.evidence} for r in history],
            "report_before_onset": any(r.detected_at < onset for r in history),
            "final_error_deg": math.degrees(rot.angle_between(loop.sim.x[:4], figures["goal"])),
            "worst_zone_margin_deg": math.degrees(worst), "baseline_zone_margin_deg": math.degrees(base),
            "zone_entered": worst < 0.0, "zone_entered_by_fault": worst < 0.0 and worst < base - ZONE_TOLERANCE,
            "completed": figures["completed"], "time_lost_s": figures["time_lost_s"], "replans": figures["replans"],
            "safe_mode": safe.size > 0,
            "safe_mode_held": bool(safe.size and np.all(a["mode"][safe[0]:] == int(ControlMode.SAFE))), **in_safe,
            "healthy_wheels": list(loop.controller.healthy or ()), "excluded": sorted(loop.estimator.excluded),
            "sim_end_s": loop.sim.t - t0, "wall_s": time.perf_counter() - wall}


def safe_figures(loop: ClosedLoop, a: dict, margins: np.ndarray, safe: np.ndarray) -> dict:
    """Safe mode's figures (NaN without it): the worst zone margin (deg, truth) at its entry and from
    then on, its time flown, and at the end the angle of the controller's ``safe_sun_axis`` (truth) from
    the Sun of its guidance and the body rate."""
    out = {"safe_entry_zone_margin_deg": math.nan, "safe_worst_zone_margin_deg": math.nan, "safe_flown_s": 0.0,
           "safe_sun_error_deg": math.nan, "safe_final_rate_deg_s": math.nan}
    if not safe.size:
        return out
    if margins.size:
        out["safe_entry_zone_margin_deg"] = math.degrees(float(margins[safe[0]].min()))
        out["safe_worst_zone_margin_deg"] = math.degrees(float(margins[safe[0]:].min()))
    out["safe_flown_s"] = float(a["t"][-1] - a["t"][safe[0]])
    sky = loop.controller.guidance_sky
    if sky is not None and sky.sun_N is not None:
        axis_N = rot.dcm_NB(loop.sim.x[:4]) @ np.asarray(loop.controller.config.safe_sun_axis, float)
        sun_N = np.asarray(sky.sun_N(loop.sim.t), float)
        out["safe_sun_error_deg"] = math.degrees(math.acos(float(np.clip(axis_N @ sun_N / np.linalg.norm(axis_N)
                                                                        / np.linalg.norm(sun_N), -1.0, 1.0))))
    out["safe_final_rate_deg_s"] = math.degrees(float(np.linalg.norm(loop.sim.x[4:7])))
    return out


_SETUP: Setup | None = None
_REFERENCES: dict = {}
_MC = None                  # the false-alarm campaign's Monte Carlo setup (shared with forked workers)


def _baseline(phase: str):
    return baseline(_SETUP, phase)


def _case(args) -> dict:
    name, phase, instant, safe_hold_s = args
    return case(_SETUP, name, phase, instant, _REFERENCES.get(phase), safe_hold_s)


def _false_alarm_batch(args) -> list[dict]:
    from att_planner.tools.monte_carlo import run as mc

    seeds, fault_table = args
    rows = mc.fly_batch(_MC, seeds, fault_table=fault_table)
    print(f"fault-free runs {seeds[0][0]}-{seeds[-1][0]}: {sum(bool(r.get('fault_reports')) for r in rows)} with a "
          "report", file=sys.stderr, flush=True)
    return rows


def _pool(workers: int):
    import multiprocessing
    return multiprocessing.get_context("fork").Pool(workers)


def cases(setup: Setup, names, instants: int, workers: int = 1,
          safe_hold_s: float = fault_flight.SAFE_HOLD_S) -> tuple[list[dict], dict]:
    """Every case of ``names`` (slew and hold, ``instants`` each), in ``workers`` processes, and the
    fault-free baselines' worst margins (deg) and reports (``{phase: [fault id]}``)."""
    global _SETUP
    jobs = [(n, "slew", f, safe_hold_s) for n in names for f in SLEW_FRACTIONS[:instants]] + \
           [(n, "hold", h, safe_hold_s) for n in names for h in HOLD_AT_S[:instants]]
    _SETUP = setup
    if workers <= 1:
        _REFERENCES.update({phase: baseline(setup, phase) for phase in ("slew", "hold")})
        rows = [_case(j) for j in jobs]
    else:
        with _pool(workers) as pool:
            refs = pool.map(_baseline, ["slew", "hold"])
            _REFERENCES.update(zip(("slew", "hold"), refs))
        with _pool(workers) as pool:
            rows = pool.map(_case, jobs, chunksize=1)
    base = {phase: math.degrees(float(r[1][-1])) if len(r[1]) else math.inf for phase, r in _REFERENCES.items()}
    return rows, base, {phase: list(r[2]) for phase, r in _REFERENCES.items()}


def false_alarms(campaign_path, runs: int, batch: int, workers: int = 1,
                 fault_table=fault_tables.DEFAULT_TABLE) -> dict:
    """``runs`` dispersed fault-free runs of the campaign with the fault table on: the runs with a report."""
    from att_planner.tools.monte_carlo import run as mc
    from att_sim.truth import dispersions as disp

    global _MC
    campaign = disp.load_campaign(campaign_path)
    _MC = mc.planned(mc.checked(campaign))
    wall = time.perf_counter()
    seeds = [(i, campaign.seed + i) for i in range(runs)]
    jobs = [(seeds[k:k + batch], fault_table) for k in range(0, runs, batch)]
    if workers <= 1:
        rows = [row for job in jobs for row in _false_alarm_batch(job)]
    else:
        with _pool(workers) as pool:
            rows = [row for part in pool.map(_false_alarm_batch, jobs, chunksize=1) for row in part]
    alarmed = [r for r in rows if r.get("fault_reports")]
    return {"campaign": str(campaign_path), "scenario": campaign.scenario, "runs": len(rows),
            "runs_with_a_report": len(alarmed), "maneuvers_successful": sum(bool(r["success"]) for r in rows),
            "alarms": [{"run": r["run"], "seed": r["seed"], "faults": r["fault_ids"]} for r in alarmed],
            "wall_s": time.perf_counter() - wall}


def summary(rows: list[dict]) -> list[dict]:
    """Per fault type and phase: detected, in time, isolated right, the responses and outcomes."""
    out = []
    for name in dict.fromkeys(r["fault"] for r in rows):
        for phase in ("slew", "hold"):
            rs = [r for r in rows if r["fault"] == name and r["phase"] == phase]
            if not rs:
                continue
            lat = [r["latency_s"] for r in rs if r["detected"]]
            out.append({"fault": name, "phase": phase, "cases": len(rs), "detected": sum(r["detected"] for r in rs),
                        "in_time": sum(r["in_time"] for r in rs), "right": sum(r["right"] for r in rs),
                        "latency_max_s": max(lat) if lat else math.nan,
                        "responses": sorted({r["response"] for r in rs if r["response"]}),
                        "completed": sum(r["completed"] for r in rs), "safe_mode": sum(r["safe_mode"] for r in rs),
                        "zone_entered": sum(r["zone_entered_by_fault"] for r in rs),
                        "safe_mode_held": sum(r["safe_mode_held"] for r in rs),
                        "worst_margin_deg": min(r["worst_zone_margin_deg"] for r in rs),
                        "safe_worst_margin_deg": min((r["safe_worst_zone_margin_deg"] for r in rs if r["safe_mode"]),
                                                     default=math.nan),
                        "safe_sun_error_max_deg": max((r["safe_sun_error_deg"] for r in rs if r["safe_mode"]),
                                                      default=math.nan),
                        "final_error_max_deg": max(r["final_error_deg"] for r in rs),
                        "time_lost_max_s": max((r["time_lost_s"] for r in rs if r["completed"]), default=math.nan)})
    return out


def run(args) -> dict:
    names = [n.strip() for n in args.faults.split(",") if n.strip()] or list(FAULTS)
    unknown = [n for n in names if n not in FAULTS]
    if unknown:
        raise SystemExit(f"att-bench faults: --faults: unknown {unknown}; known: {', '.join(FAULTS)}")
    if not 1 <= args.instants <= 3:
        raise SystemExit(f"att-bench faults: --instants must be 1 to 3, found {args.instants}")
    if not (math.isfinite(args.safe_hold_s) and args.safe_hold_s >= 0.0):
        raise SystemExit(f"att-bench faults: --safe-hold-s must be a finite number >= 0, found {args.safe_hold_s}")
    if args.runs < 0 or args.workers < 1 or args.batch < 1:
        raise SystemExit("att-bench faults: --runs must be >= 0, --workers and --batch >= 1; found "
                         f"{args.runs}, {args.workers}, {args.batch}")
    load_before, wall = os.getloadavg()[0], time.perf_counter()
    try:
        s = scen.load(args.scenario)
        setup = prepare(s)
    except (KeyError, ValueError) as err:
        raise SystemExit(f"att-bench faults: {err.args[0] if err.args else err}") from None
    rows, base, base_reports = cases(setup, names, args.instants, args.workers, args.safe_hold_s)
    alarms = (false_alarms(args.campaign, args.runs, args.batch, args.workers) if args.runs
              else {"runs": 0, "runs_with_a_report": 0})
    table = summary(rows)
    print(f"{'fault':24} {'phase':5} {'det':>4} {'<=T':>4} {'right':>5} {'lat max s':>9} {'done':>4} {'safe':>4} "
          f"{'zone':>4} {'margin deg':>10} {'err deg':>8} {'lost s':>7} {'safe margin':>11} {'sun deg':>7}  response")
    for r in table:
        print(f"{r['fault']:24} {r['phase']:5} {r['detected']:>2}/{r['cases']} {r['in_time']:>4} {r['right']:>5} "
              f"{r['latency_max_s']:9.2f} {r['completed']:>4} {r['safe_mode']:>4} {r['zone_entered']:>4} "
              f"{r['worst_margin_deg']:10.2f} {r['final_error_max_deg']:8.3f} {r['time_lost_max_s']:7.0f} "
              f"{r['safe_worst_margin_deg']:11.2f} {r['safe_sun_error_max_deg']:7.2f}  "
              f"{','.join(r['responses'])}")
    print(f"false alarms: {alarms['runs_with_a_report']} of {alarms['runs']} fault-free dispersed runs; "
          f"fault-free slew and nadir hold: {base_reports}")
    unseen = [r for r in rows if not r["observable"]]
    met = {"detected_in_time_right": sum(r["in_time"] and r["right"] for r in rows if r["observable"]),
           "cases": len(rows), "unobservable": len(unseen),
           "unobservable_harmless": sum(not r["zone_entered_by_fault"] and not r["safe_mode"]
                                        and (r["phase"] == "hold" or r["completed"]) for r in unseen),
           "zone_entered": sum(r["zone_entered_by_fault"] for r in rows), "false_alarms": alarms["runs_with_a_report"],
           "baseline_reports": sum(len(v) for v in base_reports.values())}
    return {"study": "faults", "scenario": args.scenario, "table": str(fault_tables.DEFAULT_TABLE),
            "maneuver_seconds": setup.plan.duration, "method": setup.plan.method,
            "slew_fractions": list(SLEW_FRACTIONS[:args.instants]), "hold_at_s": list(HOLD_AT_S[:args.instants]),
            "safe_hold_s": args.safe_hold_s,
            "baseline_zone_margin_deg": base, "baseline_reports": base_reports, "cases": rows, "summary": table,
            "false_alarm_campaign": alarms,
            "met": met,
            "passed": met["detected_in_time_right"] == met["cases"] - met["unobservable"]
            and met["unobservable_harmless"] == met["unobservable"] and not met["zone_entered"]
            and not met["false_alarms"] and not met["baseline_reports"],
            "runs": args.runs, "workers": args.workers, "wall_seconds": time.perf_counter() - wall,
            "load_before": load_before, "load_after": os.getloadavg()[0]}
