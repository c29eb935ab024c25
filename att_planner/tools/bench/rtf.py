"""rtf: the real-time factor of one closed-loop run alone, in process, with its profile.

``att-bench rtf --in-process [--scenario leo_observatory] [--profile-rows 20] --json PATH`` flies the
scenario's ``demo:`` maneuver as ``att-demo`` flies it, but on the cores in this process
(:class:`~att_planner.tools.closed_loop.ClosedLoop`: the truth simulation with every model of the
scenario, the estimator, the controller): from the epoch the loop runs until
``start_time − start_lead`` (the spacecraft uncontrolled, the estimator converging), the truth is
reset to the initial attitude at rest, the maneuver is planned for its start epoch
(:func:`~att_planner.tools.closed_loop.plan_in_process`), the loop runs to ``start_time`` and flies
the plan until the controller ends it. A scenario without a start time flies after
:data:`LEAD_S` s. The flight loop is every tick of the loop; its wall time excludes the one-time
set-up (scenario, cores, first environment) and the planning, each reported apart.

The JSON holds the scenario, the sim seconds, the wall seconds of the flight loop and their ratio
(``rtf``; ``rtf_cpu``: over the CPU time of this process in the loop, which other work on the machine
slows less), the set-up and planning seconds, the maneuver's result (``success``, its code and
message) and the final pointing error (truth against the goal), the 1-min load before and after,
and the top rows of a profile (cProfile) of a second, separate run of the same flight (``profile``: by
``tottime`` and by ``cumtime``, rows of function, calls, tottime, cumtime). The
target is :data:`TARGET_RTF` × real time with a successful maneuver (``met``, ``passed``).

A scenario that is not shipped, or a file that is not a valid scenario (its line and what is
expected), is refused in one sentence before any flight, as ``att-bench soak`` refuses it.
"""
from __future__ import annotations

import cProfile
import math
import os
import pstats
import time
from datetime import timedelta

import numpy as np

from att_msgs_py.errors import RequestError
from att_planner.service.warm import maneuver_from_scenario
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

TARGET_RTF = 365.0          # × real time, one run alone in process (Basilisk's stated design goal)
LEAD_S = 10.0               # s of sim time before the flight when the scenario sets no start time
PROFILE_ROWS = 20


def configure(parser) -> None:
    parser.add_argument("--in-process", action="store_true", required=True,
                        help="fly the cores in this process (the one mode of this study)")
    parser.add_argument("--scenario", default="leo_observatory", help="a scenario with a demo: maneuver")
    parser.add_argument("--profile-rows", type=int, default=PROFILE_ROWS, help="profile rows kept per ordering")
    parser.add_argument("--no-profile", action="store_true", help="skip the profiled run")


def fly(name: str, profiler: cProfile.Profile | None = None) -> dict:
    """The scenario's demo maneuver flown in process (module docstring); its timings and result.
    ``profiler``: enabled over the flight loop only."""
    started = time.perf_counter()
    s = scen.load(name)
    m = maneuver_from_scenario(s)
    loop = ClosedLoop(s, q0=m["q0"])
    setup = time.perf_counter() - started
    sky = s.epoch is not None
    start = float(m["start_time"]) if sky and m["start_time"] is not None else LEAD_S
    flight = cpu = 0.0

    def ticking(call, *args):
        nonlocal flight, cpu
        t0, c0 = time.perf_counter(), time.process_time()
        if profiler is not None:
            profiler.enable()
        try:
            return call(*args)
        finally:
            if profiler is not None:
                profiler.disable()
            flight += time.perf_counter() - t0
            cpu += time.process_time() - c0

    if sky and m["start_time"] is not None:
        ticking(loop.run, start - m["start_lead"])
        refused = loop.sim.reset(m["q0"], np.zeros(3), [], 0.0)
        if refused is not None:
            raise RuntimeError(f"the simulation refused the reset to the initial attitude: {refused.message}")
    t0 = time.perf_counter()
    epoch = (0, 0)
    if sky:
        at = (s.epoch + timedelta(seconds=start)).timestamp()
        epoch = (math.floor(at), round((at - math.floor(at)) * 1e9))
    plan = plan_in_process(s, m["q0"], m["qf"], m["sensor"], m["cones"], m["zones"], m["method"], m["time_budget"],
                           epoch=epoch)
    planning = time.perf_counter() - t0
    ticking(loop.run, start - loop.sim.t)
    result = ticking(loop.fly, plan)
    sim = loop.sim.t
    return {"scenario": name, "sim_seconds": sim, "wall_seconds": flight, "rtf": sim / flight,
            "cpu_seconds": cpu, "rtf_cpu": sim / cpu,
            "setup_seconds": setup, "planning_seconds": planning, "maneuver_seconds": plan.duration,
            "method": plan.method, "steps": round(sim / loop.step), "step_s": loop.step,
            "success": bool(result.success), "code": int(result.error_code), "message": result.message,
            "final_error_deg": math.degrees(rot.angle_between(loop.sim.x[:4], m["qf"])),
            "estimator": loop.estimator is not None, "refusals": len(loop.refusals)}


def profile_rows(profiler: cProfile.Profile, rows: int) -> dict[str, list[dict]]:
    """The top ``rows`` functions of a profile by tottime and by cumtime."""
    stats = pstats.Stats(profiler)
    out = {}
    for key in ("tottime", "cumtime"):
        table = sorted(stats.stats.items(), key=lambda kv: kv[1][2 if key == "tottime" else 3], reverse=True)
        out[key] = [{"function": f"{os.path.relpath(f) if f.startswith('/') else f}:{line}({func})",
                     "calls": int(nc), "tottime": tt, "cumtime": ct}
                    for (f, line, func), (_, nc, tt, ct, _) in table[:rows]]
    return out


def _refuse(args) -> str | None:
    """Why the arguments cannot be flown (None when they can): fewer than one profile row, a scenario
    not shipped or a file that is not a valid one (the file's line and what is expected)."""
    if args.profile_rows < 1:
        return f"--profile-rows must be at least 1, found {args.profile_rows}"
    return scen.refusal(args.scenario)


def run(args) -> dict:
    refused = _refuse(args)
    if refused:
        raise SystemExit(f"att-bench rtf: {refused}")
    load_before = os.getloadavg()[0]
    try:
        figures = fly(args.scenario)
    except RequestError as err:         # the planner's refusal (a ValueError too)
        raise SystemExit(f"att-bench rtf: the demo maneuver of '{args.scenario}' was not planned: "
                         f"code {int(err.code)}: {err.message}") from None
    except ValueError as err:
        raise SystemExit(f"att-bench rtf: {err}") from None
    load_after = os.getloadavg()[0]
    profile: dict = {}
    if not args.no_profile:
        profiler = cProfile.Profile()
        profiled = fly(args.scenario, profiler)
        profile = profile_rows(profiler, args.profile_rows)
        figures["profiled_wall_seconds"] = profiled["wall_seconds"]
    met = figures["rtf"] >= TARGET_RTF and figures["success"]
    print(f"rtf --in-process {figures['scenario']}: load {load_before:.2f} -> {load_after:.2f} on "
          f"{os.cpu_count()} cores, OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS')}")
    print(f"  {'sim s':>9}{'flight wall s':>15}{'RTF':>9}{'RTF (CPU)':>11}{'set-up s':>10}{'planning s':>12}"
          f"{'final error deg':>17}{'success':>9}")
    print(f"  {figures['sim_seconds']:9.1f}{figures['wall_seconds']:15.2f}{figures['rtf']:9.1f}"
          f"{figures['rtf_cpu']:11.1f}"
          f"{figures['setup_seconds']:10.2f}{figures['planning_seconds']:12.2f}{figures['final_error_deg']:17.5f}"
          f"{str(figures['success']):>9}")
    print(f"  target RTF >= {TARGET_RTF:g} with a successful maneuver: {'met' if met else 'NOT met'}")
    for key, rows in profile.items():
        print(f"  profile by {key} (a separate run, {figures['profiled_wall_seconds']:.1f} s under cProfile):")
        for r in rows:
            print(f"    {r['calls']:9d}{r['tottime']:9.3f}{r['cumtime']:9.3f}  {r['function']}")
    return {**figures, "in_process": True, "target_rtf": TARGET_RTF, "met": met, "passed": met,
            "load_before": load_before, "load_after": load_after,
            "profile": profile}
