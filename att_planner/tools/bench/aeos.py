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

With ``--fly``, the day of images: for each policy of :mod:`att_planner.imaging.timeline` (``greedy``,
bsk-rl's rule, ``ours`` and ``rollout``, a rollout of ours) the timeline planned with verified track-to-track slews
(:mod:`att_planner.imaging.slews`), flown in process on the estimate with every sensor and imperfect
actuator and each image checked at levels (a) and (b) on the flown truth
(:mod:`att_planner.tools.bench.aeos_flight`): images at each level, their priority and fraction of the
accessible sites, images lost (planned, failed on the truth), planner CPU per orbit, the worst zone
margin and the zone entries on the truth, and every image (site, time, flown attitude and rate,
errors, pass or fail per level). ``--plan-only`` plans the timelines without flying them.
With ``--bound``, the relaxed bound of :mod:`att_planner.imaging.bound` on the images.

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
from att_planner.imaging import access, baseline, sites, slews, timeline
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
    parser.add_argument("--fly", action="store_true", help="plan both policies' timelines and fly them in process")
    parser.add_argument("--plan-only", action="store_true", help="with --fly: plan the timelines, do not fly them")
    parser.add_argument("--policies", default=",".join(timeline.POLICIES), help="the timelines' policies, by comma")
    parser.add_argument("--bound", action="store_true", help="the relaxed (LP) bound on the images")


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
        **({"flown": _day(args, scenario, environment, targets, windows, boresight, rate_max, momentum_max, bound)}
           if args.fly else {}),
        **({"bound": _bound(args, scenario, environment, targets, windows, boresight, rate_max, momentum_max)}
           if args.bound else {}),
    }


def _planner(args, scenario, environment, targets, windows, boresight, rate_max, momentum_max):
    from att_planner.zones import FittedZones

    limits = slews.Limits.of(scenario.spacecraft, rate_max, momentum_max)
    zones = FittedZones(scenario.zones, environment.sky, windows.t1_s) if scenario.zones else None
    return timeline.Planner(environment, scenario.spacecraft, targets, windows, boresight, limits, zones,
                            lookahead=args.lookahead)


def _day(args, scenario, environment, targets, windows, boresight, rate_max, momentum_max, bound) -> dict:
    """Each policy's timeline planned, flown and checked on the truth (module docstring)."""
    from att_planner.tools.bench import aeos_flight

    policies = [p for p in args.policies.split(",") if p]
    unknown = sorted(set(policies) - set(timeline.POLICIES))
    if unknown or not policies:
        _refuse(f"--policies: expected names among {', '.join(timeline.POLICIES)}; found {args.policies!r}")
    planner = _planner(args, scenario, environment, targets, windows, boresight, rate_max, momentum_max)
    names, out = targets.names, {}
    for policy in policies:
        plan = planner.plan(policy)
        entry = {"policy": policy, "planned_images": len(plan.images), "planned_priority": plan.priority(targets),
                 "planner_cpu_s": plan.cpu_s, "planner_cpu_s_per_orbit": plan.cpu_s / args.orbits,
                 "legs": len(plan.legs), "attempts": plan.attempts, "failed_attempts": plan.failures,
                 "planned_worst_zone_margin_deg": math.degrees(plan.worst_zone_margin),
                 "settle_s": planner.settle_s, "dwell_s": planner.dwell_s}
        print(f"  {policy:6s} planned     {len(plan.images):6d} images, priority {entry['planned_priority']:.2f}, "
              f"{100 * len(plan.images) / max(bound.sites, 1):.1f} % of the accessible, planner CPU "
              f"{entry['planner_cpu_s_per_orbit']:.2f} s per orbit")
        if not args.plan_only:
            start = time.perf_counter()
            flight = aeos_flight.fly(scenario, planner, plan, seed=args.seed)
            checks = aeos_flight.check(planner, plan, flight)
            margin, entries = aeos_flight.zone_margins(planner, flight)
            for level in ("a", "b"):
                ok = [c for c in checks if getattr(c, f"level_{level}")]
                entry[f"level_{level}"] = {
                    "images": len(ok), "priority": float(sum(targets.priority[c.site] for c in ok)),
                    "fraction_of_accessible": len(ok) / bound.sites if bound.sites else 0.0,
                    "lost": len(checks) - len(ok)}
            entry.update({
                "status": "flown", "flight_wall_s": time.perf_counter() - start, "flight_cpu_s": flight.cpu_s,
                "sim_s": flight.sim_s, "legs_refused": {str(k): v for k, v in flight.refused.items()},
                "flown_worst_zone_margin_deg": math.degrees(margin), "zone_entries": entries,
                "images": [{"site": names[c.site], "time_s": round(c.time_s, 3),
                            "q_BN": [round(float(v), 9) for v in c.q_BN],
                            "omega_BN_B_rad_s": [round(float(v), 9) for v in c.omega_BN_B],
                            "a_pointing_deg": c.a_pointing_deg, "a_rate_deg_s": c.a_rate_deg_s,
                            "b_pointing_deg": c.b_pointing_deg, "b_rate_deg_s": c.b_rate_deg_s,
                            "b_samples": c.samples, "level_a": c.level_a, "level_b": c.level_b} for c in checks]})
            print(f"  {policy:6s} flown       level (a) {entry['level_a']['images']:5d}, level (b) "
                  f"{entry['level_b']['images']:5d} images ({entry['level_b']['lost']} lost at (b)), "
                  f"worst zone margin {entry['flown_worst_zone_margin_deg']:.2f} deg, {entries} zone entries")
        else:
            entry["status"] = "planned, verified slews, not flown"
        out[policy] = entry
    return out


def _bound(args, scenario, environment, targets, windows, boresight, rate_max, momentum_max) -> dict:
    from att_planner.imaging import bound as relaxed

    start = time.perf_counter()
    result = relaxed.relaxed_bound(windows, targets, _planner(args, scenario, environment, targets, windows,
                                                              boresight, rate_max, momentum_max))
    result["compute_s"] = time.perf_counter() - start
    print(f"  relaxed bound       {result['images']:.1f} images ({result['method']}; {result['compute_s']:.1f} s)")
    return result
