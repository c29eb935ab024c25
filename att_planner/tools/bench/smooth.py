"""smooth: Slepian-basis keep-out-cone maneuvers — ours vs MSSA vs DFSP vs published.

``att-bench smooth --case {earth_obs,swift} [--method ...] --json PATH`` plans the case with each
method through :func:`att_planner.methods.slepian.plan_slepian`, verifies every plan with the
suite's verification (:mod:`att_planner.verification`: prediction model, ZOH torque from rest, dense
grid, the named tolerances), adds the figures of Celani & Bruni (3 − tr(R_fᵀR(t_f)), end torques) and prints
t_f and compute time next to the published figures (Celani & Bruni 2021). The JSON holds the
selected method's plan (``case, method, N, W, M, alpha, tf, solve_seconds, verification``) and
every method run under ``runs``.
"""
from __future__ import annotations

import os
import platform
from dataclasses import asdict

import numpy as np

from att_planner.methods import slepian as S
from att_planner.reference.celani_bruni import CASES, PUBLISHED, benchmark_problem
from att_planner.verification import measure, predict, rejection
from att_sim.models import rotations as rot

UNITS = {"earth_obs": "s", "swift": "TU"}
PUBLISHED_KEY = {"slepian_minimum_time": None, "mssa": "mssa", "dfsp": "dfsp"}


def configure(parser):
    parser.add_argument("--case", choices=CASES, default="earth_obs")
    parser.add_argument("--method", choices=S.METHODS, default=S.DEFAULT_METHOD,
                        help="method whose plan is the JSON's top level (default: ours)")
    parser.add_argument("--only", action="store_true", help="run only --method (default: all three)")
    parser.add_argument("--M", type=int, default=None, help="basis size of --method (default per method)")
    parser.add_argument("--N", type=int, default=S.PAPER_N)
    parser.add_argument("--W", type=float, default=S.PAPER_W)
    parser.add_argument("--also-M", default="4,12",
                        help="comma-separated extra basis sizes for ours (rows of the table and 'runs')")
    parser.add_argument("--dfsp-budget", type=float, default=60.0,
                        help="DFSP time budget in seconds (the published run took ~1 h)")
    parser.add_argument("--dfsp-paper", action="store_true",
                        help="DFSP with the full published schedule and no time budget (about an hour)")


def verification(problem, plan) -> dict:
    """The suite's verification of the plan (prediction of its ZOH torque from rest) and the figures
    of Celani & Bruni: 3 − tr(R_fᵀ R(t_f)) and the torque at the first and last applied samples."""
    if not plan.success:
        return {"passes": False, "reason": plan.message}
    traj = predict(problem, plan)
    ver = measure(problem, plan, traj)
    why = rejection(ver)
    applied = np.abs(plan.torque[:-1]).max(axis=1)
    tmax = problem.spacecraft.body_torque_max
    residual = float(3.0 - np.trace(rot.dcm_BN(problem.q_final) @ rot.dcm_NB(traj.q_BN[-1])))
    return dict(asdict(ver), trace_residual=residual,
                start_torque_ratio=float(applied[0] / tmax), end_torque_ratio=float(applied[-1] / tmax),
                passes=why is None, rejection=why)


def run_method(case: str, method: str, args, M: int | None = None) -> dict:
    problem = benchmark_problem(case)
    M = args.M if M is None and method == args.method else M
    options = {}
    if method == "dfsp":
        options = {"time_budget": None} if args.dfsp_paper else {"time_budget": args.dfsp_budget}
    plan = S.plan_slepian(problem, method=method, M=M, N=args.N, W=args.W, **options)
    st = plan.stats
    return {"case": case, "method": method, "N": st["N"], "W": st["W"], "M": st["M"],
            "alpha": st.get("alpha"), "tf": st.get("tf") if st.get("feasible") else None,
            "solve_seconds": plan.wall_time, "status": plan.status, "message": plan.message,
            "verification": verification(problem, plan),
            "solver": {k: v for k, v in st.items() if k not in ("alpha", "tf", "N", "W", "M")}}


def run(args) -> dict:
    case = args.case
    methods = [args.method] if args.only else [args.method] + [m for m in S.METHODS if m != args.method]
    runs = [run_method(case, m, args) for m in methods]
    if S.DEFAULT_METHOD in methods and not args.only:
        runs += [run_method(case, S.DEFAULT_METHOD, args, M=int(m)) for m in args.also_M.split(",") if m.strip()]
    pub = PUBLISHED[case]
    unit = UNITS[case]
    print(f"smooth / {case}: t_f in {unit} (conventions of Celani & Bruni 2021: N={args.N}, W={args.W}); "
          f"load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'method':24s} {'M':>3s} {'t_f':>10s} {'compute s':>10s} {'published':>10s} {'pub. compute':>13s} "
          f"{'verified':>8s} {'3-tr':>9s} {'margin deg':>10s}")
    for r in runs:
        key = PUBLISHED_KEY[r["method"]]
        pub_tf = f"{pub[key]:.4g}" if key else "-"
        pub_time = f"{pub['dfsp_minutes']:.0f} min" if key == "dfsp" else "-"
        v = r["verification"]
        tf = f"{r['tf']:.4g}" if r["tf"] is not None else "failed"
        print(f"{r['method']:24s} {r['M']:>3d} {tf:>10s} {r['solve_seconds']:>10.2f} {pub_tf:>10s} {pub_time:>13s} "
              f"{str(v['passes']):>8s} {v.get('trace_residual', float('nan')):>9.2e} "
              f"{np.degrees(v.get('min_cone_margin', float('nan'))):>10.3f}")
    print(f"{'time-optimal (non-smooth)':24s} {'':>3s} {'':>10s} {'':>10s} {pub['time_optimal_nonsmooth']:>10.4g}")
    top = dict(runs[0])
    top["runs"] = runs
    top["published"] = pub
    top["machine"] = {"cores": os.cpu_count(), "load_1min": os.getloadavg()[0], "python": platform.python_version()}
    return top
