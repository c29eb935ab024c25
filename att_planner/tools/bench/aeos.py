"""aeos: the agile imaging setup's accessible bound and greedy baseline, planned (not flown).

``att-bench aeos [--targets uniform:N|FILE] [--seed S] [--orbits K] [--scenario NAME] [--dwell-s D]
[--lookahead L] --json PATH`` takes the sites (:mod:`att_planner.imaging.sites`: ``uniform:N`` drawn
from ``--seed``, or a CSV file), computes every access window over K orbits of the scenario
(:mod:`att_planner.imaging.access`: the spacecraft at least 58.0° above the site's horizon, edges
within 0.1 s), and reports:

* the **accessible bound**: the sites with at least one window and their total priority;
* the **greedy baseline** (:mod:`att_planner.imaging.baseline`, bsk-rl's policy): the images it
  plans, their total priority and their fraction of the accessible sites, **planned, not flown**
  (rest-to-rest slew estimates, no verified slew, no flight, no image check);
* the number of windows of each site, and the compute time of each part.

The imager is the scenario's sensor (its demo's ``sensor_axis``), the slews' rate bound the planner's
``schedule_rate_max_rad_s`` and their momentum bound each wheel's ``wheel_inertia × wheel_speed_max``.
The JSON lists every window and every planned image (site, time, slew) so that anyone can recheck them.
The study states no criterion.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from att_msgs_py.errors import ConfigError
from att_planner.imaging import access, baseline, sites
from att_sim.models import scenario as scen
from att_sim.models import world

STATUS = "planned, not flown"
MAX_ORBITS = 100.0


def configure(parser):
    parser.add_argument("--targets", default="uniform:3000", help="'uniform:N' (seeded) or a CSV file of sites")
    parser.add_argument("--seed", type=int, default=0, help="seed of a uniform target set")
    parser.add_argument("--orbits", type=float, default=5.0, help="horizon in orbital periods from the epoch")
    parser.add_argument("--scenario", default="aeos", help="the scenario flown (spacecraft, orbit, epoch)")
    parser.add_argument("--dwell-s", type=float, default=0.0, help="s held on each site before the next slew")
    parser.add_argument("--lookahead", type=int, default=baseline.LOOKAHEAD, help="windows the greedy policy weighs")


def _refuse(message: str):
    print(f"att-bench aeos: {message}", file=sys.stderr)
    raise SystemExit(2)


def run(args) -> dict:
    if not (math.isfinite(args.orbits) and 0.0 < args.orbits <= MAX_ORBITS):
        _refuse(f"--orbits: expected a number of orbits in (0, {MAX_ORBITS:g}]; found {args.orbits}")
    if not (math.isfinite(args.dwell_s) and args.dwell_s >= 0.0):
        _refuse(f"--dwell-s: expected a finite time >= 0 s; found {args.dwell_s}")
    if args.lookahead < 1:
        _refuse(f"--lookahead: expected an integer >= 1; found {args.lookahead}")
    try:
        scenario = scen.load(args.scenario)
        targets = sites.from_spec(args.targets, args.seed)
    except ConfigError as err:
        _refuse(err.message)
    except KeyError as err:                    # an unknown scenario name
        _refuse(str(err.args[0]))
    demo = scenario.node_params.get("demo", {})
    if not isinstance(demo, dict) or "sensor_axis" not in demo:
        _refuse(f"scenario {args.scenario} names no sensor (its demo's sensor_axis): the imager's boresight")
    boresight = np.asarray(demo["sensor_axis"], float)
    sc = scenario.spacecraft
    rate_max = float(scenario.node_params.get("planner", {}).get("schedule_rate_max_rad_s", math.inf))
    momentum_max = float(sc.wheel_inertia * sc.wheel_speed_max)
    environment = world.Environment.from_scenario(scenario)
    horizon = args.orbits * scenario.orbit_model.period

    start = time.perf_counter()
    windows = access.access_windows(environment, targets, 0.0, horizon)
    access_s = time.perf_counter() - start
    bound = baseline.accessible_bound(windows, targets)
    start = time.perf_counter()
    plan = baseline.greedy(environment, sc, targets, windows, boresight, rate_max=rate_max,
                           wheel_momentum_max=momentum_max, lookahead=args.lookahead, dwell_s=args.dwell_s)
    greedy_s = time.perf_counter() - start

    names = targets.names
    fraction = len(plan) / bound.sites if bound.sites else 0.0
    print(f"aeos: {len(targets)} sites ({targets.source}, seed {args.seed}), {args.orbits:g} orbits "
          f"({horizon:.0f} s) of {args.scenario}, minimum elevation {access.MIN_ELEVATION_DEG:.2f} deg")
    print(f"  access windows      {len(windows):6d}   ({access_s:.2f} s)")
    print(f"  accessible bound    {bound.sites:6d} sites, priority {bound.priority:.2f}")
    print(f"  greedy baseline     {len(plan):6d} images, priority {plan.priority:.2f}, {100 * fraction:.1f} % of "
          f"the accessible ({STATUS}; {greedy_s:.2f} s)")
    return {
        "study": "aeos", "scenario": args.scenario, "targets": targets.source if args.targets.startswith(
            sites.UNIFORM) else args.targets, "seed": args.seed, "orbits": args.orbits, "horizon_s": horizon,
        "sites": len(targets), "min_elevation_deg": access.MIN_ELEVATION_DEG, "edge_tolerance_s": access.TOLERANCE_S,
        "boresight_B": boresight.tolist(), "rate_max_deg_per_s": math.degrees(rate_max),
        "wheel_momentum_max_Nms": momentum_max, "torque_max_Nm": sc.body_torque_max,
        "accessible": {"sites": bound.sites, "priority": bound.priority},
        "access_windows": {"total": len(windows), "per_site": dict(zip(names, windows.per_site().tolist())),
                           "windows": [{"site": names[i], "open_s": round(float(a), 3), "close_s": round(float(b), 3)}
                                       for i, a, b in zip(windows.site, windows.open_s, windows.close_s)]},
        "greedy": {"status": STATUS, "images": len(plan), "priority": plan.priority,
                   "fraction_of_accessible": fraction, "lookahead": args.lookahead, "dwell_s": args.dwell_s,
                   "plan": [{"site": names[i.site], "time_s": round(i.time_s, 3), "slew_s": round(i.slew_s, 3),
                             "slew_angle_deg": round(math.degrees(i.slew_angle_rad), 4)} for i in plan.images]},
        "compute_s": {"access": access_s, "greedy": greedy_s},
    }
