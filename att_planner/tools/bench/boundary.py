"""Melton's (2012) boundary cases for ``att-bench time-optimal --case {ba1,ba2,bp1,bp2}``.

For the case: ``time_optimal`` (multi-start, the plan of the JSON whatever ``--method``; the others'
figures under ``plans``), ``time_optimal`` with Melton's
first stage (``global_stage``: the particle swarm seeds the collocation; compute and IPOPT
iterations with and without it), ``constrained_axis`` on the case, and the λ-rotation about the
cone axis (``constrained_axis`` with the forced arc: the BA twin of a BP case). Every plan is
re-verified (:func:`att_planner.verification.verify`). ``--sweep`` adds BA, BP and the λ-rotation
of this cone over :data:`SWEEP_AXES` × :data:`SWEEP_ROLLS` orientations of the scene relative to the
body axes (the torque box makes them differ; J = I). Where BP comes out slower than BA, BP is solved
once more with a collocation zone margin of :data:`SMALL_MARGIN_DEG` instead of 0.05° (BA rides the
boundary itself; with no margin at all the truth dips into the cone between the points).
"""
from __future__ import annotations

import time
from dataclasses import asdict, replace

import numpy as np

from att_planner.methods.constrained_axis import plan_constrained_axis
from att_planner.methods.time_optimal import plan_time_optimal
from att_planner.reference.time_optimal_cases import BOUNDARY_CASES, PUBLISHED, boundary_problem
from att_planner.verification import rejection, verify
from att_sim.models import rotations as rot

# Cone axes (body) spanning the torque box's fundamental triangle (z, the xz diagonal, the cube
# diagonal) and its centre; the sensor turned about each by SWEEP_ROLLS.
SWEEP_AXES = {"z": [0.0, 0.0, 1.0], "xz": [1.0, 0.0, 1.0], "xyz": [1.0, 1.0, 1.0], "centre": [0.3106, 0.1237, 0.9425]}
SWEEP_ROLLS = (0.0, 60.0, 120.0, 180.0, 240.0, 300.0)       # deg about the cone axis
SMALL_MARGIN_DEG = 0.001      # BP's collocation margin where BP came out slower than BA (default 0.05°)


def twin(case: str, arc: bool) -> str:
    """The case of the same cone with (BA) or without (BP) the forced arc."""
    return ("ba" if arc else "bp") + case[2:]


def orientation(axis, roll_deg: float) -> np.ndarray:
    """The rotation taking body z to ``axis`` (shortest), then turning by ``roll_deg`` about it."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    z = np.array([0.0, 0.0, 1.0])
    n = np.cross(z, a)
    tilt = rot.IDENTITY if np.linalg.norm(n) < 1e-12 else rot.from_axis_angle(n, np.arccos(np.clip(a @ z, -1, 1)))
    return rot.multiply(rot.from_axis_angle(a, np.deg2rad(roll_deg)), tilt)


def _checked(problem, plan) -> dict:
    """The plan's figures and the suite's verification of it."""
    ver = verify(problem, plan) if len(plan.t) > 1 else None
    why = rejection(ver) if ver is not None else plan.message
    return {"tf": plan.duration, "status": str(plan.status), "nit": plan.nit, "solve_seconds": plan.wall_time,
            "passes": why is None, "rejection": why, "verification": {} if ver is None else asdict(ver)}


def _solve(problem, method, budget: float, **options):
    plan = method(replace(problem, deadline=time.monotonic() + budget), **options)
    return plan, _checked(problem, plan)


def sweep(case: str, budget: float) -> list[dict]:
    """BA, BP and λ-rotation t_f of ``case``'s cone over the sweep's orientations."""
    rows = []
    for name, axis in SWEEP_AXES.items():
        for roll in SWEEP_ROLLS:
            q = orientation(axis, roll)
            ba, bp = boundary_problem(twin(case, True), q), boundary_problem(twin(case, False), q)
            row = {"axis": name, "cone_axis_body": ba.cones[0].direction, "sensor_axis_body": ba.sensor_axis,
                   "roll_deg": roll}
            for key, problem, method in (("ba", ba, plan_time_optimal), ("bp", bp, plan_time_optimal),
                                         ("lambda", ba, plan_constrained_axis)):
                _, figures = _solve(problem, method, budget)
                row[key] = figures["tf"] if figures["passes"] else None
            if None not in (row["ba"], row["bp"]) and row["bp"] > row["ba"]:
                # BP keeps the collocation's 0.05° off the cone between its ends, BA rides it: BP with 0.001°
                _, figures = _solve(bp, plan_time_optimal, budget, cone_margin_deg=SMALL_MARGIN_DEG)
                row["bp_small_margin"] = figures["tf"] if figures["passes"] else None
            rows.append(row)
            print(f"  cone axis {name:<7} roll {roll:5.0f}°: BA {row['ba'] or float('nan'):.4f}  "
                  f"BP {row['bp'] or float('nan'):.4f}  λ {row['lambda'] or float('nan'):.4f}"
                  + (f"  (BP with a {SMALL_MARGIN_DEG}° margin: {row['bp_small_margin'] or float('nan'):.4f})"
                     if "bp_small_margin" in row else ""), flush=True)
    return rows


def _sweep_summary(rows: list[dict]) -> dict:
    out = {}
    for key in ("ba", "bp", "lambda"):
        done = [r for r in rows if r[key] is not None]
        best, worst = min(done, key=lambda r: r[key]), max(done, key=lambda r: r[key])
        out[key] = {"best": best[key], "best_at": (best["axis"], best["roll_deg"]), "worst": worst[key],
                    "worst_at": (worst["axis"], worst["roll_deg"]), "failed": len(rows) - len(done)}
    complete = [r for r in rows if None not in (r["ba"], r["bp"], r["lambda"])]
    out["order_violations"] = [(r["axis"], r["roll_deg"]) for r in complete
                               if not r["bp"] <= r["ba"] + 1e-6 <= r["lambda"] + 2e-6]
    return out


def run(args) -> dict:
    case = args.case
    problem = boundary_problem(case)
    arc = BOUNDARY_CASES[case][2]
    plans = {}
    plan, plans["time_optimal"] = _solve(problem, plan_time_optimal, args.budget, starts=args.starts)
    two_stage, plans["time_optimal_two_stage"] = _solve(problem, plan_time_optimal, args.budget, global_stage=True)
    _, plans["constrained_axis"] = _solve(problem, plan_constrained_axis, args.budget)
    _, plans["lambda_rotation"] = _solve(boundary_problem(twin(case, True)), plan_constrained_axis, args.budget)
    print(f"boundary case {case} ({'forced arc' if arc else 'boundary points'}; times in TU); published: "
          f"{PUBLISHED[case]}")
    print(f"{'plan':<24}{'t_f':>8}{'solve s':>9}{'IPOPT it':>10}  {'status':<10} ok")
    for name, p in plans.items():
        print(f"{name:<24}{p['tf']:8.4f}{p['solve_seconds']:9.2f}{p['nit']:10d}  {p['status']:<10} "
              f"{'yes' if p['passes'] else 'NO: ' + str(p['rejection'])}")
    payload = {"case": case, "method": "time_optimal", "tf": plan.duration, "t": plan.t,
               "torque": plan.torque, "interpolation": plan.interpolation, "solve_seconds": plan.wall_time,
               "verification": plans["time_optimal"]["verification"] | {"passes": plans["time_optimal"]["passes"]},
               "J": problem.spacecraft.inertia, "torque_limit": problem.spacecraft.body_torque_max,
               "q_initial": problem.q_initial, "sensor_axis": problem.sensor_axis,
               "cones": [{"direction": c.direction, "half_angle": c.half_angle, "name": c.name} for c in problem.cones],
               "semi_free": True, "sensor_target": problem.sensor_target, "boundary_arc": arc,
               "geometry": "cone axis body z, sensor (sin θ, 0, cos θ), from rest at identity; target R(z, −φ) sensor",
               "plans": {k: {key: v[key] for key in ("tf", "status", "nit", "solve_seconds", "passes")}
                         for k, v in plans.items()}}
    swarm = two_stage.stats.get("global_stage", {})
    payload["plans"]["time_optimal_two_stage"].update(
        swarm_iterations=swarm.get("iterations"), swarm_tf=swarm.get("tf"),
        swarm_seconds=two_stage.stats.get("seconds", {}).get("global_stage"),
        starts=[s["route"] for s in two_stage.stats.get("starts", [])])
    print(f"two stages: the swarm ({swarm.get('iterations')} iterations, "
          f"{payload['plans']['time_optimal_two_stage']['swarm_seconds'] or 0:.2f} s, t_f {swarm.get('tf') or 0:.4f}) "
          f"seeds {', '.join(payload['plans']['time_optimal_two_stage']['starts'])}")
    if args.sweep:
        print(f"orientation sweep of the {case[2:]} cone (BA, BP, λ-rotation):")
        rows = sweep(case, args.budget)
        payload["sweep"] = {"rows": rows, "summary": _sweep_summary(rows)}
        for key, s in payload["sweep"]["summary"].items():
            print(f"  {key}: {s}")
    return payload
