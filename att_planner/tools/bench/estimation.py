"""estimation: the demo maneuver flown closed loop on the attitude estimate, and on the truth.

``att-bench estimation [--scenario swift_demo] [--out DIR] --json PATH`` runs the scenario's demo
maneuver twice through the ROS nodes (recorder, simulator, estimator, controller, planner, as
``att-demo`` does): once with the controller on the estimator's attitude (``state_source:
estimate``) and once on the simulator's truth (``state_source: truth``; the estimator still runs,
open loop). Every figure is computed from the recorded MCAP alone
(:mod:`att_planner.tools.review.estimation`: the estimate ``/estimator/attitude`` against the truth
``/spacecraft/state`` and ``/simulator/sensor_truth``), over the executed segment (maneuver plus
settle), so anyone can recompute them from the log:

``{"mcap", "estimate_topic", "truth_topic", "state_source", "attitude_error_rms_arcsec",
"attitude_error_max_arcsec", "bias_error_final_deg_per_h", "nees_mean", "nees_dof",
"final_pointing_error_deg", "min_cone_margin_deg", "tracker_invalid_seconds", "tracker_sigma_arcsec",
"success", "message", "truth_loop": {the same for the run on the truth}}``.

``final_pointing_error_deg`` is the true attitude's angle to the goal at the end of the segment, and
``final_pointing_sigmas`` that error against the star tracker's noise in body axes (``√(eᵀ R_B⁻¹ e)``,
``R_B = C R_S Cᵀ`` through its mounting: "within 3σ" is ≤ 3); ``pointing_bound_deg`` is 3× the
tracker's 1σ attitude error (root sum square of its three axes); ``min_cone_margin_deg`` the
smallest margin of the true attitude to the demo's cones and zones.
"""
from __future__ import annotations

import math
import platform
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from att_msgs_py.log import read_log
from att_msgs_py.topics import ESTIMATE, STATE
from att_planner.nodes.client import client_session
from att_planner.tools.demo import maneuver_from_scenario, request_and_execute, zone_margins
from att_planner.tools.launch import isolated_env, join_env, start_suite
from att_planner.tools.review.estimation import TOPICS, estimation_of, estimation_summary
from att_planner.tools.review.run import extract_run
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

FIGURES = ("attitude_error_rms_arcsec", "attitude_error_max_arcsec", "bias_error_final_deg_per_h", "nees_mean",
           "final_pointing_error_deg", "final_pointing_sigmas", "pointing_bound_deg", "min_cone_margin_deg",
           "tracker_invalid_seconds")


def configure(parser):
    parser.add_argument("--scenario", default="swift_demo", help="a scenario with sensors and a demo section")
    parser.add_argument("--out", default="bench_out/estimation", help="directory for the runs' logs")
    parser.add_argument("--rtf", type=float, default=0.0, help="simulator real-time factor (0: as fast as possible)")


def fly(scenario: scen.Scenario, maneuver: dict, source: str, out: Path, rtf: float) -> dict:
    """One run of the demo maneuver with the controller on ``source``; its figures from the log."""
    run_dir = out / f"{scenario.name}_{source}_{datetime.now(UTC).strftime('%Y%m%d_%H%M%S')}"
    mcap = run_dir / "run.mcap"
    env = isolated_env()
    join_env(env)
    suite = start_suite(scenario.name, mcap, run_dir, env=env,
                        params={"simulator": {"real_time_factor": rtf}, "controller": {"state_source": source}})
    try:
        with client_session(f"bench_estimation_{source}") as client:
            ok, _ = request_and_execute(client, scenario, maneuver)
    finally:
        suite.stop()
    return figures(mcap, scenario, maneuver) | {"success": bool(ok), "state_source": source}


def figures(mcap: Path, scenario: scen.Scenario, maneuver: dict) -> dict:
    """The bench's figures of a recorded run (the executed segment of its last plan)."""
    log = read_log(mcap, topics=sorted({*TOPICS, "/actuator/command", "/planner/plans"}))
    run = extract_run(log)
    t0, t1 = run.t0 + run.t[0], run.t0 + run.t[-1]
    estimation = estimation_of(log, t0, t1)
    if estimation is None:
        raise ValueError(f"{mcap}: no estimate recorded with the truth in the executed segment")
    summary = estimation_summary(estimation)
    _, margins = zone_margins(scenario, maneuver, run.t0 + run.t, run.q)
    tracker = scenario.sensors.star_trackers[0] if scenario.sensors.star_trackers else None
    error = 2 * rot.error_vector(run.q[-1], maneuver["qf"])            # goal -> truth, body axes
    pointing = {}
    if tracker is not None:
        C = rot.dcm_NB(tracker.mounting)
        pointing = {"final_pointing_sigmas": float(np.sqrt(error @ np.linalg.solve(C @ tracker.covariance @ C.T,
                                                                                    error))),
                    "pointing_bound_deg": float(np.degrees(3 * np.sqrt(np.trace(tracker.covariance))))}
    return {"mcap": str(mcap), "estimate_topic": ESTIMATE, "truth_topic": STATE,
            **{k: summary[k] for k in FIGURES if k in summary}, "nees_dof": summary["nees_dof"], **pointing,
            "final_pointing_error_deg": float(np.degrees(rot.angle_between(run.q[-1], maneuver["qf"]))),
            "min_cone_margin_deg": float(np.degrees(margins.min())) if margins.size else math.inf,
            "segment_s": [t0, t1], "health_seconds": summary["health_seconds"],
            "tracker_sigma_arcsec": None if tracker is None else
            [math.degrees(tracker.cross_boresight) * 3600, math.degrees(tracker.about_boresight) * 3600]}


def run(args) -> dict:
    scenario = scen.load(args.scenario)
    maneuver = maneuver_from_scenario(scenario)
    out = Path(args.out)
    estimate = fly(scenario, maneuver, "estimate", out, args.rtf)
    truth = fly(scenario, maneuver, "truth", out, args.rtf)
    print(f"\nestimation: {scenario.name} demo maneuver, closed loop ({platform.node()}, {platform.processor() or ''})")
    print(f"{'figure':<32} {'on the estimate':>16} {'on the truth':>14}")
    for key in FIGURES:
        print(f"{key:<32} {estimate.get(key, math.nan):>16.4g} {truth.get(key, math.nan):>14.4g}")
    print(f"{'success':<32} {estimate['success']!s:>16} {truth['success']!s:>14}")
    return {**estimate, "truth_loop": truth}
