"""Time-optimal keep-out slews: eigenaxis, constrained axis and collocation compared.

``att-bench time-optimal --case {ba1,ba2,bp1,bp2} [--sweep]`` runs Melton's (2012) boundary cases instead
(:mod:`.boundary`).

``att-bench time-optimal --case {bilimoria_wie,swift} [--method M] [--budget S] --json PATH`` runs
every method on the case, re-verifies each plan from rest at identity through the prediction model
(:func:`att_planner.verification.verify`, the suite's one verification and tolerances), prints a
table next to the published figures and writes the JSON of ``--method`` (default
``time_optimal``). Times are in TU (J = I, T̄ = 1).
"""
from __future__ import annotations

import time
from dataclasses import asdict, replace

import numpy as np

from att_planner.methods.constrained_axis import plan_constrained_axis
from att_planner.methods.eigenaxis import plan_eigenaxis
from att_planner.methods.time_optimal import plan_time_optimal
from att_planner.reference.time_optimal_cases import BOUNDARY_CASES, CASES, PUBLISHED, case_problem
from att_planner.tools.bench import boundary
from att_planner.verification import rejection, verify
from att_sim.models import rotations as rot

METHODS = {"eigenaxis": plan_eigenaxis, "constrained_axis": plan_constrained_axis,
           "time_optimal": plan_time_optimal}
TUNABLE = {"time_optimal": ("starts",)}


def configure(parser):
    parser.add_argument("--case", choices=CASES, required=True)
    parser.add_argument("--method", choices=list(METHODS), default="time_optimal",
                        help="method whose plan goes to the JSON (all are run and tabulated; the boundary "
                             "cases write time_optimal's)")
    parser.add_argument("--budget", type=float, default=10.0,
                        help="time budget per method, seconds (problem.deadline)")
    parser.add_argument("--starts", type=int, default=6,
                        help="number of cheap routes time_optimal solves (all are listed)")
    parser.add_argument("--sweep", action="store_true",
                        help="boundary cases: BA, BP and the lambda-rotation over orientations of the cone axis")


def _verification(problem, plan) -> dict:
    ver = verify(problem, plan)
    why = rejection(ver)
    return dict(asdict(ver), passes=why is None, rejection=why)


def _semi_free_row(args) -> dict:
    """time_optimal with only the sensor direction imposed (Melton's semi-free final attitude)."""
    problem = case_problem(args.case)
    problem = replace(problem, sensor_target=rot.dcm_NB(problem.q_final) @ problem.sensor_axis,
                      deadline=time.monotonic() + args.budget)
    plan = plan_time_optimal(problem, starts=args.starts)
    ver = _verification(problem, plan)       # semi-free: the attitude error is the boresight's
    return {"tf": plan.duration, "solve_seconds": plan.wall_time, "status": plan.status,
            "pointing_error": ver["final_attitude_error"], "final_rate": ver["final_rate"],
            "min_cone_margin": ver["min_cone_margin"], "torque_ratio": ver["torque_ratio"], "passes": ver["passes"]}


def _print_table(args, rows, semi) -> None:
    print(f"time-optimal slew, case {args.case} (times in TU); published: {PUBLISHED[args.case]}")
    head = (f"{'method':<17}{'t_f':>8}{'solve s':>9}  {'status':<15}{'att err°':>9}{'rate':>9}{'margin°':>9}"
            f"{'|T|/T̄':>7}  ok")
    print(head)
    print("-" * len(head))
    for name, plan, ver in rows:
        if not ver:
            print(f"{name:<17}{'—':>8}{plan.wall_time:9.2f}  {plan.status:<15}  {plan.message}")
            continue
        print(f"{name:<17}{plan.duration:8.4f}{plan.wall_time:9.2f}  {plan.status:<15}"
              f"{np.rad2deg(ver['final_attitude_error']):9.4f}{ver['final_rate']:9.1e}"
              f"{np.rad2deg(ver['min_cone_margin']):9.3f}{ver['torque_ratio']:7.3f}  "
              f"{'yes' if ver['passes'] else 'NO'}")
    print(f"{'semi-free (t_o)':<17}{semi['tf']:8.4f}{semi['solve_seconds']:9.2f}  {semi['status']:<15}"
          f"{np.rad2deg(semi['pointing_error']):9.4f}{semi['final_rate']:9.1e}"
          f"{np.rad2deg(semi['min_cone_margin']):9.3f}{semi['torque_ratio']:7.3f}  "
          f"{'yes' if semi['passes'] else 'NO'}   (sensor pointing error in the att err column)")


def run(args) -> dict:
    if args.case in BOUNDARY_CASES:
        return boundary.run(args)
    if args.sweep:
        raise SystemExit(f"att-bench time-optimal: --sweep is for the boundary cases ({', '.join(BOUNDARY_CASES)})")
    rows, payloads = [], {}
    for name, method in METHODS.items():
        problem = replace(case_problem(args.case), deadline=time.monotonic() + args.budget)
        plan = method(problem, **{k: getattr(args, k) for k in TUNABLE.get(name, ())})
        ver = _verification(problem, plan) if len(plan.t) > 1 else {}
        payloads[name] = {"case": args.case, "method": name, "tf": plan.duration, "t": plan.t,
                          "torque": plan.torque, "interpolation": plan.interpolation,
                          "solve_seconds": plan.wall_time, "verification": ver}
        rows.append((name, plan, ver))
    _print_table(args, rows, _semi_free_row(args))
    best = rows[-1][1]
    if "starts" in best.stats:
        print("time_optimal starts (coarse mesh): " + "; ".join(
            f"{s['route']} → {s['tf']:.4f} ({s['status']})" for s in best.stats["starts"]))
        minima = sorted({round(s["tf"], 2) for s in best.stats["starts"] if s["status"] == "Solve_Succeeded"})
        print("distinct local minima reached (coarse mesh, TU): " + ", ".join(f"{m:.2f}" for m in minima))
        print("time_optimal refinement of the best start: " + " → ".join(
            f"{m['intervals']} intervals {m['tf']:.4f}" for m in best.stats["mesh"]))
    return payloads[args.method]
