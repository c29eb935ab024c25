"""observe: what the zones cost a schedule of observations, on the real sky.

``att-bench observe [--sources a,b,...] [--dwell S] [--substeps K] --json PATH`` plans a tour of
observatory sources (``config/targets/observatory.yaml``, each held ``--dwell`` s) with
:func:`att_planner.methods.schedule.plan_schedule` for ``leo_observatory``'s spacecraft (its wheels)
from the real-sky case's start (:mod:`.sky`), twice: without any zone, and among the scenario's
Sun, Moon and Earth-limb zones at their true positions (each observation kept out of them too).
Both plans are verified by the prediction model; the JSON gives, per run, the order, t_f, the
passages and observation ends, the verification, the compute time and the wheel-torque profile
(``t``, ``torque``, ZOH) so that the plans can be integrated independently, and the zones' cost:
the ratio of the two tours' t_f.
"""
from __future__ import annotations

import time
from dataclasses import asdict, replace

from att_planner.methods import schedule as sch
from att_planner.mission import targets as tl
from att_planner.tools.bench import sky
from att_planner.verification import rejection
from att_sim.models import scenario as scen

DEFAULT_SOURCES = ("crab_nebula", "m87", "vega", "andromeda")


def configure(parser) -> None:
    parser.add_argument("--sources", default=",".join(DEFAULT_SOURCES),
                        help="observatory sources, comma-separated (config/targets/observatory.yaml)")
    parser.add_argument("--dwell", type=float, default=60.0, help="s each source is held")
    parser.add_argument("--intervals", type=int, default=12, help="ZOH intervals per phase of the final plan")
    parser.add_argument("--search-intervals", type=int, default=6, help="intervals per phase in the order search")
    parser.add_argument("--substeps", type=int, default=4,
                        help="RK4 steps per ZOH interval (legs that wait for visibility last minutes)")
    parser.add_argument("--cone-margin-deg", type=float, default=0.2,
                        help="every zone tightened by this at the NLP's points (the Earth limb moves 0.06 deg/s)")


def tour_problems(names: list[str], dwell: float):
    """The tour among the zones and the same tour without any zone."""
    case, problem = sky.case_problem("leo_observatory")
    sources = {s.name: s for s in tl.load("observatory").targets}
    unknown = [n for n in names if n not in sources]
    if unknown:
        raise ValueError(f"unknown source(s) {', '.join(unknown)} (known: {', '.join(sources)})")
    targets = {n: tl.pointing_attitude(problem.sensor_axis, sources[n].direction) for n in names}
    zoned = replace(problem, spacecraft=scen.load("leo_observatory").spacecraft, targets=targets,
                    q_final=problem.q_initial, target_dwell=dict.fromkeys(names, dwell))
    return case, zoned, replace(zoned, zones=[], cones=[], sky=None)


def _entry(plan, seconds: float) -> dict:
    ver = plan.verification
    return {"status": str(plan.status), "message": plan.message, "order": plan.order, "tf": plan.duration,
            "passages": [{"name": p.name, "arrival": p.time, "observation_end": p.time + p.dwell}
                         for p in plan.passages],
            "verified": ver is not None and rejection(ver) is None,
            "verification": asdict(ver) if ver is not None else None, "solve_seconds": seconds,
            "t": plan.t, "torque": plan.torque, "interpolation": str(plan.interpolation),
            "control_kind": str(plan.control_kind), "zone_refinements": plan.stats.get("zone_refinements")}


def run(args) -> dict:
    names = [n for n in args.sources.split(",") if n]
    case, zoned, free = tour_problems(names, args.dwell)
    out = {"sources": names, "dwell": args.dwell, "cone_margin_deg": args.cone_margin_deg,
           "epoch": sky.format_epoch(zoned.epoch), "tle": list(case.tle),
           "q_start": zoned.q_initial, "sensor_axis": zoned.sensor_axis, "zones": sky.zone_entries(case, zoned),
           "spacecraft": {"inertia": zoned.spacecraft.inertia, "wheel_axes": zoned.spacecraft.wheel_axes,
                          "wheel_inertia": zoned.spacecraft.wheel_inertia,
                          "wheel_torque_max": zoned.spacecraft.wheel_torque_max,
                          "wheel_speed_max": zoned.spacecraft.wheel_speed_max}}
    for label, problem in (("without_zones", free), ("with_zones", zoned)):
        start = time.perf_counter()
        plan = sch.plan_schedule(problem, search_intervals=args.search_intervals, intervals=args.intervals,
                                 substeps=args.substeps, cone_margin_deg=args.cone_margin_deg)
        out[label] = _entry(plan, time.perf_counter() - start)
    out["zone_cost_ratio"] = out["with_zones"]["tf"] / out["without_zones"]["tf"]
    print(f"observe: {len(names)} sources, dwell {args.dwell:g} s, leo_observatory's sky from {out['epoch']}")
    for label in ("without_zones", "with_zones"):
        e = out[label]
        print(f"  {label:<14} t_f {e['tf']:8.1f} s  order {' '.join(e['order'])}  verified {e['verified']}  "
              f"{e['solve_seconds']:.1f} s of compute")
    print(f"  the zones cost {out['zone_cost_ratio']:.3f} x the tour without them")
    return out
