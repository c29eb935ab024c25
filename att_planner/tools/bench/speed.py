"""speed: anytime planning — the first verified plan, the best smooth plan, the time-optimal one.

``att-bench speed [--case ...] [--repeats 20] [--ros] --json PATH`` plans each case through the
planner service's pipeline in this process (:func:`att_planner.service.planning.plan_maneuver`:
the first plan, the default method seeded with it, the verification) and times it after warm-up
(wall time, and the CPU time of this process and its children: time_optimal solves every other
start in a forked child):

* ``first``: a request with a budget of :data:`FIRST_BUDGET` s — the verified first plan
  (graph_smooth); the median wall and CPU time of ``--repeats`` requests;
* ``best``: a request with a budget of :data:`BEST_BUDGET` s — the default method's plan (or the
  first plan, should it not verify in time); median of ``--best-repeats``;
* ``time_optimal``: a request for ``time_optimal`` with a budget of :data:`TIME_OPTIMAL_BUDGET` s,
  whose t_f is the physical limit the smooth plans are compared with; median of ``--best-repeats``.

Every plan is verified by the service (prediction model, every zone at its true position). Each
entry of the JSON is ``{"case", "first": P, "best": P, "time_optimal_tf", ...}`` with
``P = {"method", "tf", "t", "torque", "interpolation", "solve_seconds", "verification", ...}``,
the profile convention of the smooth and time-optimal benchmarks (``interpolation`` says how the
torque samples are applied), with the problem (inertia, torque limit, attitudes, sensor, cones,
and for the real sky its epoch, TLE and zones), so that the plans can be integrated independently
(test/att_planner/tools/test_bench_speed.py). ``--ros`` also times the quick and the best request
through the ``PlanManeuver`` service of a planner node started for the purpose (the service pads
the zones by the scenario's ``cone_padding_deg`` and validates the request; the round trip is
reported). The node warms its solver workers on the demo maneuvers of ``swift_demo`` and of the
case's spacecraft's scenario (``warm_up_scenarios``) before it serves.

Cases: ``swift`` and ``earth_obs`` (Celani & Bruni 2021, :mod:`att_planner.reference.celani_bruni`)
and ``leo_observatory`` (the real sky, :mod:`.sky`).
"""
from __future__ import annotations

import os
import platform
import resource
import statistics
import time
from dataclasses import asdict, replace

from att_msgs_py.types import Stage
from att_planner import methods
from att_planner.problem import ManeuverProblem
from att_planner.reference.celani_bruni import benchmark_problem
from att_planner.service.planning import PlanOutcome, plan_maneuver, prepare, run_method
from att_planner.service.requests import ValidRequest
from att_planner.tools.bench import sky
from att_planner.verification import rejection

CASES = ("swift", "earth_obs", "leo_observatory")
FIRST_BUDGET = 0.05           # s: the quick answer
BEST_BUDGET = 1.0             # s: the best smooth plan
TIME_OPTIMAL_BUDGET = 10.0    # s
ROS_SPACECRAFT = {"swift": "swift_demo", "earth_obs": "leo_observatory", "leo_observatory": "leo_observatory"}


def configure(parser) -> None:
    parser.add_argument("--case", choices=CASES, action="append", help="a case (repeatable; default: all)")
    parser.add_argument("--repeats", type=int, default=20, help="timed quick requests per case, after warm-up")
    parser.add_argument("--best-repeats", type=int, default=5, help="timed best and time-optimal requests per case")
    parser.add_argument("--ros", action="store_true", help="also time the requests through a planner node")


def case_problem(name: str) -> tuple[ManeuverProblem, dict]:
    """The case's problem and its description for the JSON (enough to integrate a plan without the suite)."""
    if name == "leo_observatory":
        case, problem = sky.case_problem(name)
        extra = {"epoch": sky.format_epoch(problem.epoch), "tle": list(case.tle),
                 "zones": sky.zone_entries(case, problem)}
    else:
        problem, extra = benchmark_problem(name), {"zones": []}
    return problem, {"J": problem.spacecraft.inertia, "torque_limit": problem.spacecraft.body_torque_max,
                     "q_initial": problem.q_initial, "q_final": problem.q_final, "sensor_axis": problem.sensor_axis,
                     "cones": [{"name": c.name, "direction": c.direction, "half_angle": c.half_angle}
                               for c in problem.cones], **extra}


def request(problem: ManeuverProblem, method: str, budget: float) -> PlanOutcome:
    """One request through the service's pipeline in this process, its deadline counted from now."""
    valid = ValidRequest(replace(problem, deadline=time.monotonic() + budget), methods.get(method), {}, "bench", budget)
    return plan_maneuver(valid, runner=run_method)


def cpu_seconds() -> float:
    """CPU time of this process and of its finished children (time_optimal's forked starts)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)          # microseconds (os.times: 10 ms ticks)
    return time.process_time() + children.ru_utime + children.ru_stime


def timed(problem: ManeuverProblem, method: str, budget: float, repeats: int) -> dict:
    """The JSON entry P (module docstring) of ``repeats`` requests after one untimed one: the last
    one's plan, the median wall and CPU times of the requests and of each stage."""
    request(problem, method, budget)
    walls, cpus, stages, outcome = [], [], [], None
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), cpu_seconds()
        outcome = request(problem, method, budget)
        walls.append(time.perf_counter() - wall)
        cpus.append(cpu_seconds() - cpu)
        stages.append({str(s.name): s.seconds for s in outcome.stages})
    plan, ver = outcome.plan, outcome.verification
    return {"method": plan.method, "tf": plan.duration, "t": plan.t, "torque": plan.torque,
            "interpolation": str(plan.interpolation), "solve_seconds": statistics.median(walls),
            "solve_cpu_seconds": statistics.median(cpus), "solve_seconds_all": walls,
            "stage_seconds": {name: statistics.median(s[name] for s in stages) for name in stages[-1]},
            "status": str(plan.status), "stage": str(outcome.stage), "stages": [asdict(s) for s in outcome.stages],
            "code": int(outcome.code),
            "verification": dict(asdict(ver), passes=rejection(ver) is None) if ver is not None else {"passes": False}}


def run_case(name: str, args) -> dict:
    problem, description = case_problem(name)
    default = methods.REGISTRY[0].name
    out = {"case": name, "first": timed(problem, default, FIRST_BUDGET, args.repeats),
           "best": timed(problem, default, BEST_BUDGET, args.best_repeats),
           "time_optimal": timed(problem, "time_optimal", TIME_OPTIMAL_BUDGET, args.best_repeats), **description}
    out["time_optimal_tf"] = out["time_optimal"]["tf"]
    out["time_optimal_seconds"] = out["time_optimal"]["stage_seconds"][Stage.METHOD]
    out["best_tf_ratio"] = out["best"]["tf"] / out["time_optimal_tf"]
    return out


def ros_times(name: str, problem: ManeuverProblem, repeats: int, best_repeats: int) -> dict:
    """Round trips (s) of quick and best requests through a planner node's PlanManeuver service."""
    import tempfile

    from att_planner.nodes.client import client_session, maneuver_request
    from att_planner.tools.launch import isolated_env, join_env, start_suite

    env = isolated_env()
    join_env(env)
    out: dict = {}
    with tempfile.TemporaryDirectory() as work:
        warm = ",".join(dict.fromkeys(("swift_demo", ROS_SPACECRAFT[name])))    # warm for the case's spacecraft
        suite = start_suite("swift_demo", os.path.join(work, "run.mcap"), work, env=env, nodes=("planner",),
                            params={"planner": {"warm_up_scenarios": warm}})
        try:
            with client_session("speed_bench") as client:
                client.plan_client.wait_for_service(timeout_sec=180)     # the node warms its workers first
                kwargs = dict(spacecraft=ROS_SPACECRAFT[name], frame_id="", zones=problem.zones, epoch=problem.epoch)
                if problem.sky is not None:
                    kwargs["tle"] = tuple(sky.CASES[name].tle)
                for key, budget, count in (("first", FIRST_BUDGET, repeats), ("best", BEST_BUDGET, best_repeats)):
                    req = maneuver_request(problem.q_initial, problem.q_final, problem.sensor_axis, problem.cones,
                                           time_budget=budget, **kwargs)
                    client.plan(req)                                   # warm-up
                    trips, responses = [], []
                    for _ in range(count):
                        start = time.perf_counter()
                        responses.append(client.plan(req))
                        trips.append(time.perf_counter() - start)
                    last = responses[-1]
                    out[key] = {"round_trip_seconds": statistics.median(trips), "round_trips": trips,
                                "success": all(r.success for r in responses), "stage": last.stage,
                                "method": last.plan.method, "tf": last.plan.duration,
                                "stage_seconds": [[s.name, s.seconds] for s in last.stages]}
        finally:
            suite.stop()
    return out


def _print(rows: list) -> None:
    print(f"speed: load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; medians, wall (CPU) s")
    head = (f"{'case':<16}{'first':>16}{'t_f':>10}{'best':>16}{'t_f':>10}{'method':>20}{'t_o':>10}"
            f"{'ratio':>7}{'t_o s':>8}")
    print(head)
    print("-" * len(head))
    for r in rows:
        f, b = r["first"], r["best"]
        print(f"{r['case']:<16}{f['solve_seconds']:8.4f} ({f['solve_cpu_seconds']:.4f}){f['tf']:10.4g}"
              f"{b['solve_seconds']:8.3f} ({b['solve_cpu_seconds']:.3f}){b['tf']:10.4g}{b['method']:>20}"
              f"{r['time_optimal_tf']:10.4g}{r['best_tf_ratio']:7.3f}{r['time_optimal_seconds']:8.3f}")
        if "ros" in r:
            print(f"{'':<16}through ROS: first {r['ros']['first']['round_trip_seconds']:.4f} s, "
                  f"best {r['ros']['best']['round_trip_seconds']:.3f} s (round trips)")


def run(args) -> dict:
    started = time.perf_counter()
    names = args.case or list(CASES)
    prepare(benchmark_problem("swift").spacecraft)
    rows = []
    for name in names:
        row = run_case(name, args)
        if args.ros:
            row["ros"] = ros_times(name, case_problem(name)[0], args.repeats, args.best_repeats)
        rows.append(row)
    _print(rows)
    return {"cases": rows, "budgets": {"first": FIRST_BUDGET, "best": BEST_BUDGET, "time_optimal": TIME_OPTIMAL_BUDGET},
            "machine": {"cores": os.cpu_count(), "load_1min": os.getloadavg()[0], "python": platform.python_version(),
                        "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
                        "wall_seconds": time.perf_counter() - started},
            "targets": {"first_seconds": FIRST_BUDGET, "best_seconds": BEST_BUDGET, "best_tf_ratio": 1.25,
                        "time_optimal_seconds": 0.3}}
