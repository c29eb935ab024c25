"""sky: plans against the real, moving sky — the zones frozen at the start vs their motion.

``att-bench sky [--case NAME] --json PATH`` plans a case twice with the planner's default method
(the first of :data:`att_planner.methods.REGISTRY`, ``smooth_collocation``; ``--method`` picks another)
through the planner service's pipeline (:func:`att_planner.service.planning.plan_maneuver`: the
first plan, the method seeded with it, the suite's one verification):

* ``frozen``: every stage sees every zone as it is at the start epoch
  (:meth:`att_planner.zones.FittedZones.frozen_zones`, inertial cones — what planners that read the
  zone directions once do), and the plan is verified against those frozen zones;
* ``moving``: every stage sees the zones' motion (:meth:`ManeuverProblem.zone_sky`, Chebyshev fits),
  and the plan is verified against the zones at their true positions.

Then both are measured on the true sky: the prediction of the plan's torque from rest at
``q_initial``, every zone at its true position (orbit by SGP4, Sun and Moon by DE421) at every
dense-grid time. The table gives t_f, compute, whether each plan verified against the zones it was
planned with, the minimum margin of each zone on the true sky and the zone a plan enters (by how
much). The JSON holds everything to redo it (case, epoch, TLE, spacecraft, attitudes, zones, both
plans with their torques, both verifications, and per knot the predicted attitude with every
zone's true and planned margin), so that the plans can be re-checked without the suite
(test/att_planner/tools/test_bench_sky.py does so with its own RK4 and skyfield).

Cases (:data:`CASES`), the earth_obs spacecraft of the smooth benchmark (J = diag(3000, 4500, 6000)
kg m², 0.25 N m) with sensor +y and keep-out zones Sun 47°, Moon 23°, Earth limb + 10°:

* ``rising_limb`` (:data:`HEADLINE`, the default) — a 157° slew in the 580 km / 20.56° orbit of
  ``leo_observatory``, 2020 s after 2026-12-21T00:00:00Z, from just above the limb on one side of
  the wake (−v) to just above it on the other. The limb's axis, the nadir, turns at the orbit rate
  (0.062°/s) towards the wake, so the limb rises there. Found by ``benchmarks/sky_search.py``
  (seeded, its output in ``benchmarks/sky_search.json``): the frozen plan rides the frozen limb
  (+0.04°) about 220 s into the slew, where the true limb has risen over it by 10.3°; the moving plan
  goes the other way round (39 s longer; it clears the frozen limb by 9.3° too, a route the frozen
  planner has no reason to take) and clears every true zone by 9.07°.
* ``leo_observatory`` — the 135° slew about body x from identity in the same orbit, 460 s after
  2026-12-21T00:00:00Z, where the Earth limb lies 3.5° from the start direction and rises over the
  first part of the path. Chosen for ``slepian_minimum_time`` (``benchmarks/sky_offset_search.py``):
  that method's frozen plan, whose M = 8 basis barely moves near τ = 0, is overtaken by the limb
  from a start 458 s after the epoch on; ``smooth_collocation`` leaves fast enough and both its
  plans clear the true limb by 2.1°.
* ``moon_parallax`` — slow motion that still matters: a 120° slew about body axis (1, 0, 0.4)
  in a 700 km sun-synchronous orbit (TLE below), starting 2027-03-20T01:15:00Z with the Moon near
  the zenith, placed 6° from the unconstrained path's midpoint on the side the Moon appears to
  move to. The Moon's direction from the spacecraft moves by lunar parallax (the spacecraft flies
  ≈ 3400 km across the line of sight during the slew, ≈ 0.3° at the Moon's distance), so a plan
  that grazes the frozen Moon zone enters the moving one (by 0.18° with ``smooth_collocation``).
"""
from __future__ import annotations

import math
import os
import platform
import time
from dataclasses import asdict, dataclass, replace
from datetime import timedelta

import numpy as np

from att_msgs_py.types import Zone
from att_planner import methods
from att_planner.problem import ManeuverProblem
from att_planner.service.planning import plan_maneuver, run_method
from att_planner.service.requests import ValidRequest
from att_planner.verification import measure, predict, rejection
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft
from att_sim.models.ephemeris import Ephemeris
from att_sim.models.epoch import format_epoch, parse_epoch
from att_sim.models.orbit import TLEOrbit

EARTH_OBS_J = (3000.0, 4500.0, 6000.0)      # kg m², principal (smooth benchmark, Celani & Bruni 2021)
EARTH_OBS_TORQUE = 0.25                     # N m per body axis
SENSOR = (0.0, 1.0, 0.0)
ZONES_DEG = (("sun", "sun", 47.0), ("moon", "moon", 23.0), ("earth", "earth_limb", 10.0))  # name, body, deg


@dataclass(frozen=True)
class SkyCase:
    """A maneuver in the real sky: TLE (its epoch = ``epoch``), start ``offset`` s after ``epoch``,
    rest-to-rest ``q_initial`` → ``q_final`` (x, y, z, w body to GCRS) of the earth_obs spacecraft."""

    description: str
    tle: tuple[str, str]
    epoch: str
    offset: float
    q_initial: tuple
    q_final: tuple
    sensor_axis: tuple = SENSOR
    zones: tuple = ZONES_DEG


LEO_TLE = ("1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    07",
           "2 28485  20.5600  60.0000 0005000  90.0000  10.0000 14.95764766    08")
# 700 km sun-synchronous (98.19°), written with sgp4.exporter.export_tle (checksums valid)
SSO_TLE = ("1 90001U          27079.00000000  .00000000  00000-0  20000-4 0    04",
           "2 90001  98.1900 150.0000 0010000  90.0000   0.0000 14.57889173    08")

CASES = {
    "rising_limb": SkyCase(
        "earth_obs 157 deg slew past the wake side of the Earth limb, which rises over the frozen plan's route",
        LEO_TLE, "2026-12-21T00:00:00Z", 2020.0,
        (-0.668573834485, 0.490816930038, -0.030458871757, 0.557835124532),
        (-0.207180289286, 0.568053186492, 0.717854207476, -0.345075704529)),
    "leo_observatory": SkyCase(
        "earth_obs 135 deg about body x, the Earth limb rising over the first part of the path",
        LEO_TLE, "2026-12-21T00:00:00Z", 460.0, tuple(rot.IDENTITY),
        tuple(rot.from_axis_angle(np.array([1.0, 0.0, 0.0]), 0.75 * math.pi))),
    "moon_parallax": SkyCase(
        "120 deg about body (1, 0, 0.4) past the Moon near the zenith, moving by lunar parallax",
        SSO_TLE, "2027-03-20T00:00:00Z", 4500.0,
        (-0.685715496021, 0.448618820923, 0.529528392248, 0.219397114458),
        (-0.022152992239, 0.870644184208, -0.025397680877, 0.490757483127)),
}

HEADLINE = "rising_limb"      # found by benchmarks/sky_search.py


def configure(parser) -> None:
    parser.add_argument("--case", choices=list(CASES), default=HEADLINE)
    parser.add_argument("--offset", type=float, default=None,
                        help="start, seconds after the case's epoch (default: the case's)")
    parser.add_argument("--method", choices=[m.name for m in methods.REGISTRY], default=methods.REGISTRY[0].name,
                        help="planning method (default: the planner's default)")
    parser.add_argument("--options", default="", metavar="K=V,...",
                        help="method options, checked by the registry (e.g. M=4,N=60)")


def case_problem(name: str, offset: float | None = None) -> tuple[SkyCase, ManeuverProblem]:
    """The case ``name`` of :data:`CASES` as a :class:`ManeuverProblem` whose zones move (epoch = the
    maneuver start, ``offset`` s after the case's epoch; default: the case's)."""
    case = CASES[name]
    return case, sky_problem(case, case.offset if offset is None else offset)


def sky_problem(case: SkyCase, offset: float) -> ManeuverProblem:
    """``case`` starting ``offset`` s after its epoch, as a :class:`ManeuverProblem` whose zones move."""
    start = parse_epoch(case.epoch) + timedelta(seconds=float(offset))
    orbit = TLEOrbit(case.epoch, *case.tle)
    sensor = np.array(case.sensor_axis, float)
    zones = [Zone(n, body, sensor, math.radians(deg)) for n, body, deg in case.zones]
    sc = Spacecraft(inertia=np.diag(EARTH_OBS_J), body_torque_max=EARTH_OBS_TORQUE)
    return ManeuverProblem(sc, rot.normalize(np.array(case.q_initial)), rot.normalize(np.array(case.q_final)),
                           sensor_axis=sensor, zones=zones, epoch=start, sky=Ephemeris(start, orbit))


def frozen(problem: ManeuverProblem) -> ManeuverProblem:
    """The problem with every zone frozen as it is at t = 0 (inertial zones, no sky)."""
    return replace(problem, cones=[], zones=problem.zone_sky().frozen_zones(), sky=None)


def parse_options(text: str) -> dict:
    """``K=V,...`` as {K: float(V)} (the registry then checks names and ranges)."""
    out = {}
    for item in filter(None, (s.strip() for s in text.split(","))):
        key, _, value = item.partition("=")
        try:
            out[key.strip()] = float(value)
        except ValueError:
            raise ValueError(f"--options item {item!r} must be NAME=NUMBER") from None
    return out


def plan_case(problem: ManeuverProblem, method: methods.Method, options: dict, zones: str) -> dict:
    """Plan through :func:`plan_maneuver` seeing the ``zones`` ('frozen': every stage sees the zones
    frozen at the start, :func:`frozen`, and the plan is verified against them; 'moving': their
    motion, verified against the true sky), then measure the method's plan against the true sky.
    Returns the JSON plan entry."""
    planned = frozen(problem) if zones == "frozen" else problem
    seen = {}

    def runner(m, prob, opts, wait):
        cpu = time.process_time()
        seen["plan"] = run_method(m, prob, opts, wait)
        seen["cpu"] = time.process_time() - cpu
        return seen["plan"]

    valid = ValidRequest(planned, method, method.validate(options), "earth_obs", math.inf)
    outcome = plan_maneuver(valid, runner=runner)
    plan = seen["plan"]          # the method's own plan (no first plan, no fallback)
    entry = {"method": method.name, "zones_planned": zones, "tf": plan.duration if len(plan.t) else None,
             "t": plan.t, "torque": plan.torque, "interpolation": str(plan.interpolation),
             "solve_seconds": plan.wall_time, "solve_cpu_seconds": seen["cpu"], "status": str(plan.status),
             "message": plan.message,
             "service": {"code": int(outcome.code), "message": outcome.message, "stage": str(outcome.stage),
                         "returned": (outcome.plan.method if outcome.plan is not None else None)}}
    if not (plan.success and len(plan.t) > 1):
        entry["verification"] = {"passes": False, "rejection": plan.message}
        entry["verification_planned"] = {"passes": False, "rejection": plan.message}
        return entry
    traj = predict(problem, plan)
    own = plan.verification if plan.verification is not None else measure(planned, plan, traj)
    truth = own if planned is problem else measure(problem, plan, traj)
    entry["verification"] = verification(problem, planned, truth, traj)
    why = rejection(own)
    entry["verification_planned"] = {"zones": zones, "passes": why is None, "rejection": why,
                                     "min_cone_margin": own.min_cone_margin,
                                     "zone_margins": dict(zip(own.zone_names, own.cone_margins))}
    entry["samples"] = samples(problem, planned, plan, traj)
    return entry


def samples(problem: ManeuverProblem, planned: ManeuverProblem, plan, traj) -> dict:
    """Per knot of the plan: the predicted attitude ``q_BN`` and the margins (rad) of every zone at its
    true position (``true_margins``) and as the method saw it (``planned_margins``: frozen or fitted)."""
    k = np.clip(np.searchsorted(traj.t, np.asarray(plan.t, float) - 1e-9), 0, len(traj.t) - 1)
    t, q = traj.t[k], traj.q_BN[k]
    names = problem.zone_sky().names
    true = problem.zone_sky().margins(t, q, true=True)
    own = planned.zone_sky().margins(t, q)
    return {"t": t, "q_BN": q, "true_margins": {n: true[:, i] for i, n in enumerate(names)},
            "planned_margins": {n: own[:, i] for i, n in enumerate(names)}}


def verification(problem: ManeuverProblem, planned: ManeuverProblem, ver, traj) -> dict:
    """The suite's verification ``ver`` against the true, moving sky with the per-zone minimum
    margins by name, the zone entered most deeply (or None), and the margins of the predicted
    trajectory ``traj`` against the zones the method planned with (frozen or fitted)."""
    why = rejection(ver)
    margins = dict(zip(ver.zone_names, ver.cone_margins))
    worst = min(margins, key=margins.get) if margins else None
    own = planned.zone_sky().margins(traj.t, traj.q_BN).min(axis=0)
    still = frozen(problem).zone_sky().margins(traj.t, traj.q_BN).min(axis=0)
    return dict(asdict(ver), passes=why is None, rejection=why, zone_margins_vs_motion=margins,
                entered=worst if worst is not None and margins[worst] < 0 else None,
                entered_by=-margins[worst] if worst is not None and margins[worst] < 0 else 0.0,
                zone_margins_vs_planned=dict(zip(ver.zone_names, own.tolist())),
                zone_margins_vs_frozen=dict(zip(ver.zone_names, still.tolist())))


def zone_entries(case: SkyCase, problem: ManeuverProblem) -> list:
    """The zones as the JSON gives them: half-angles at the start (rad, margin included)."""
    half = problem.zone_sky().true_half_angles(0.0)
    out = []
    for z, h in zip(problem.zones, half):
        entry = {"name": z.name, "body": z.body, "sensor_axis": z.sensor_axis, "half_angle": float(h),
                 "keep_in": bool(z.keep_in)}
        if z.body == "earth_limb":
            entry["margin"] = float(z.half_angle)
        if z.body == "inertial":
            entry["direction"] = z.direction
        out.append(entry)
    return out


def _print_table(name: str, payload: dict) -> None:
    names = [z["name"] for z in payload["zones"]]
    print(f"sky / {name}: start {payload['epoch']}; margins (deg) of the true, moving zones; "
          f"load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    head = (f"{'plan':<8}{'t_f s':>8}{'solve s':>9}{'cpu s':>7}  {'verified vs own zones':<23}"
            + "".join(f"{n:>9}" for n in names) + f"  {'on the true sky':<22}")
    print(head)
    print("-" * len(head))
    for kind, p in payload["plans"].items():
        v, own = p["verification"], p.get("verification_planned", {})
        tf = f"{p['tf']:8.1f}" if p["tf"] is not None else f"{'—':>8}"
        zm = v.get("zone_margins_vs_motion", {})
        cells = "".join(f"{math.degrees(zm[n]):9.3f}" if n in zm else f"{'—':>9}" for n in names)
        ok = f"yes ({kind})" if own.get("passes") else f"NO: {own.get('rejection')}"[:23]
        if v.get("entered"):
            truth = f"enters {v['entered']} by {math.degrees(v['entered_by']):.3f}"
        else:
            truth = f"clear by {math.degrees(min(zm.values())):.3f}" if zm else "—"
        print(f"{kind:<8}{tf}{p['solve_seconds']:9.2f}{p['solve_cpu_seconds']:7.2f}  {ok:<23}{cells}  {truth:<22}")


def summary(plans: dict) -> dict:
    """What the motion does: the frozen plan's depth in the true zones (rad, 0 when it stays out) and
    the moving plan's smallest true margin, with t_f and compute of the moving plan against the frozen one."""
    fr, mv = plans["frozen"], plans["moving"]
    out = {"compute_ratio": mv["solve_seconds"] / fr["solve_seconds"] if fr["solve_seconds"] else None,
           "cpu_ratio": mv["solve_cpu_seconds"] / fr["solve_cpu_seconds"] if fr["solve_cpu_seconds"] else None}
    for kind, p in plans.items():
        v = p["verification"]
        out[f"{kind}_verified_vs_own_zones"] = bool(p.get("verification_planned", {}).get("passes"))
        out[f"{kind}_verified_vs_truth"] = bool(v.get("passes"))
        if "zone_margins_vs_motion" in v:
            out[f"{kind}_true_margin"] = min(v["zone_margins_vs_motion"].values())
            out[f"{kind}_entered"], out[f"{kind}_entered_by"] = v["entered"], v["entered_by"]
    if fr["tf"] and mv["tf"]:
        out.update(tf_cost_seconds=mv["tf"] - fr["tf"], tf_ratio=mv["tf"] / fr["tf"])
    return out


def run(args) -> dict:
    case, problem = case_problem(args.case, args.offset)
    method = methods.get(args.method)
    options = parse_options(args.options)
    started = time.perf_counter()
    plans = {kind: plan_case(problem, method, options, kind) for kind in ("frozen", "moving")}
    payload = {
        "case": args.case, "description": case.description, "epoch": format_epoch(problem.epoch),
        "tle": list(case.tle), "J": problem.spacecraft.inertia, "torque_limit": problem.spacecraft.body_torque_max,
        "sensor_axis": problem.sensor_axis, "q_initial": problem.q_initial, "q_final": problem.q_final,
        "zones": zone_entries(case, problem), "plans": plans, "summary": summary(plans),
        "machine": {"cores": os.cpu_count(), "load_1min": os.getloadavg()[0], "python": platform.python_version(),
                    "wall_seconds": time.perf_counter() - started},
    }
    _print_table(args.case, payload)
    s = payload["summary"]
    if s.get("frozen_entered") and "moving_true_margin" in s:
        print(f"the motion: the plan against the frozen zones enters {s['frozen_entered']} on the true sky by "
              f"{math.degrees(s['frozen_entered_by']):.3f} deg; the plan against the moving zones clears every true "
              f"zone by {math.degrees(s['moving_true_margin']):.3f} deg")
    if "tf_cost_seconds" in s:
        print(f"the motion costs {s['tf_cost_seconds']:+.1f} s of t_f ({100 * (s['tf_ratio'] - 1):+.1f} %); "
              f"moving-zone compute {s['compute_ratio']:.2f}x the frozen one (CPU {s['cpu_ratio']:.2f}x)")
    return payload
