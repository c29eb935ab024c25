"""sky: plans against the real, moving sky — the zones frozen at the start vs their motion.

``att-bench sky --case {leo_observatory,moon_parallax} --json PATH`` plans each case twice with the
default method (``slepian_minimum_time``) through the planner service's pipeline
(:func:`att_planner.service.planning.plan_maneuver`: the method, then the suite's one verification):

* ``frozen``: the method sees every zone as it is at the start epoch
  (:meth:`att_planner.zones.FittedZones.frozen_zones`, inertial cones — what planners that read the
  zone directions once do);
* ``moving``: the method sees the zones' motion (:meth:`ManeuverProblem.zone_sky`, Chebyshev fits).

Both are verified against the motion: the prediction of the plan's ZOH torque from rest at
``q_initial``, every zone at its true position (orbit by SGP4, Sun and Moon by DE421) at every
dense-grid time. The table gives t_f, compute, the minimum margin of each zone against the motion
and the zone a plan enters; the JSON holds everything to redo it (case, epoch, TLE, spacecraft,
attitudes, zones, both plans with their torques and verifications), so that the plans can be
re-checked without the suite (test/att_planner/tools/test_bench_sky.py does so with its own RK4 and
skyfield).

Cases (:data:`CASES`), the earth_obs spacecraft of the smooth benchmark (J = diag(3000, 4500, 6000)
kg m², 0.25 N m) with sensor +y and keep-out zones Sun 47°, Moon 23°, Earth limb + 10°:

* ``leo_observatory`` — the 135° slew about body x from identity, in a
  580 km / 20.56° TLE orbit, starting 460 s after 2026-12-21T00:00:00Z. The Earth-limb zone
  (76.6° about nadir, sweeping at orbit rate) then lies 3.5° from the start direction and rises
  over the first part of the path at ≈ 0.06°/s: the plan made against the frozen limb is overtaken
  by it. The start came from an offset search outside the bench (skyfield directly, the frozen
  zones as cones): the start direction is clear of the limb from about 5400 s to 515 s (mod the
  5776 s period); the frozen plan enters the moving limb from 458 s on (by 0.12° at 460 s, 2.58° at
  500 s, where the eigenaxis_smooth plan clears the frozen limb by 1.10° and enters the moving one
  by 1.76°); the M = 8 Slepian basis, which barely moves near τ = 0, outruns the limb only up to
  about 460 s.
* ``moon_parallax`` — slow motion that still matters: a 120° slew about body axis (1, 0, 0.4)
  in a 700 km sun-synchronous orbit (TLE below), starting 2027-03-20T01:15:00Z with the Moon near
  the zenith, placed 6° from the unconstrained path's midpoint on the side the Moon appears to
  move to. The Moon's direction from the spacecraft moves by lunar parallax (the spacecraft flies
  ≈ 3400 km across the line of sight during the slew, ≈ 0.3° at the Moon's distance), so a plan
  that grazes the frozen Moon zone enters the moving one.
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
from att_planner.verification import predict, rejection
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


def configure(parser) -> None:
    parser.add_argument("--case", choices=list(CASES), default="leo_observatory")
    parser.add_argument("--offset", type=float, default=None,
                        help="start, seconds after the case's epoch (default: the case's)")
    parser.add_argument("--method", choices=[m.name for m in methods.REGISTRY], default=methods.REGISTRY[0].name,
                        help="planning method (default: the planner's default)")
    parser.add_argument("--options", default="", metavar="K=V,...",
                        help="method options, checked by the registry (e.g. M=4,N=60)")


def case_problem(name: str, offset: float | None = None) -> tuple[SkyCase, ManeuverProblem]:
    """The case as a :class:`ManeuverProblem` whose zones move (epoch = the maneuver start)."""
    case = CASES[name]
    offset = case.offset if offset is None else float(offset)
    start = parse_epoch(case.epoch) + timedelta(seconds=offset)
    orbit = TLEOrbit(case.epoch, *case.tle)
    sensor = np.array(case.sensor_axis, float)
    zones = [Zone(n, body, sensor, math.radians(deg)) for n, body, deg in case.zones]
    sc = Spacecraft(inertia=np.diag(EARTH_OBS_J), body_torque_max=EARTH_OBS_TORQUE)
    problem = ManeuverProblem(sc, rot.normalize(np.array(case.q_initial)), rot.normalize(np.array(case.q_final)),
                              sensor_axis=sensor, zones=zones, epoch=start, sky=Ephemeris(start, orbit))
    return case, problem


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
    """Plan against the ``zones`` ('frozen' or 'moving') through :func:`plan_maneuver` (the method
    on that problem, the verification against the motion) and return the JSON plan entry."""
    seen = {}

    def runner(m, prob, opts, wait):
        target = frozen(prob) if zones == "frozen" else prob
        cpu = time.process_time()
        seen["problem"], seen["plan"] = target, run_method(m, target, opts, wait)
        seen["cpu"] = time.process_time() - cpu
        return seen["plan"]

    valid = ValidRequest(problem, method, method.validate(options), "earth_obs", math.inf)
    outcome = plan_maneuver(valid, runner=runner)
    plan = seen["plan"]          # the method's own plan, verified against the motion (no fallback)
    entry = {"method": method.name, "tf": plan.duration if len(plan.t) else None, "t": plan.t,
             "torque": plan.torque, "interpolation": str(plan.interpolation), "solve_seconds": plan.wall_time,
             "solve_cpu_seconds": seen["cpu"], "status": str(plan.status), "message": plan.message,
             "service": {"code": int(outcome.code), "message": outcome.message,
                         "returned": (outcome.plan.method if outcome.plan is not None else None)}}
    entry["verification"] = verification(problem, seen["problem"], plan) if plan.verification else {
        "passes": False, "rejection": plan.message}
    return entry


def verification(problem: ManeuverProblem, planned: ManeuverProblem, plan) -> dict:
    """The service's verification (against the motion) with the per-zone minimum margins by name,
    the zone entered most deeply (or None), and the margins against the zones the method planned
    with (frozen or fitted)."""
    ver = plan.verification
    why = rejection(ver)
    margins = dict(zip(ver.zone_names, ver.cone_margins))
    worst = min(margins, key=margins.get) if margins else None
    traj = predict(problem, plan)
    own = planned.zone_sky().margins(traj.t, traj.q_BN).min(axis=0)
    return dict(asdict(ver), passes=why is None, rejection=why, zone_margins_vs_motion=margins,
                entered=worst if worst is not None and margins[worst] < 0 else None,
                entered_by=-margins[worst] if worst is not None and margins[worst] < 0 else 0.0,
                zone_margins_vs_planned=dict(zip(ver.zone_names, own.tolist())))


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
    head = (f"{'case':<16}{'plan':<8}{'t_f s':>8}{'solve s':>9}{'cpu s':>7}" + "".join(f"{n:>9}" for n in names)
            + f"  {'entered (deg)':<20}verified")
    print(head)
    print("-" * len(head))
    for kind, p in payload["plans"].items():
        v = p["verification"]
        tf = f"{p['tf']:8.1f}" if p["tf"] is not None else f"{'—':>8}"
        zm = v.get("zone_margins_vs_motion", {})
        cells = "".join(f"{math.degrees(zm[n]):9.3f}" if n in zm else f"{'—':>9}" for n in names)
        entered = f"{v['entered']} by {math.degrees(v['entered_by']):.3f}" if v.get("entered") else "none"
        print(f"{name:<16}{kind:<8}{tf}{p['solve_seconds']:9.2f}{p['solve_cpu_seconds']:7.2f}{cells}  {entered:<20}"
              f"{'yes' if v.get('passes') else 'NO: ' + str(v.get('rejection'))}")


def summary(plans: dict) -> dict:
    """What the motion costs: t_f and compute of the moving plan against the frozen one."""
    fr, mv = plans["frozen"], plans["moving"]
    out = {"compute_ratio": mv["solve_seconds"] / fr["solve_seconds"] if fr["solve_seconds"] else None,
           "cpu_ratio": mv["solve_cpu_seconds"] / fr["solve_cpu_seconds"] if fr["solve_cpu_seconds"] else None}
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
    if "tf_cost_seconds" in s:
        print(f"the motion costs {s['tf_cost_seconds']:+.1f} s of t_f ({100 * (s['tf_ratio'] - 1):+.1f} %); "
              f"moving-zone compute {s['compute_ratio']:.2f}x the frozen one (CPU {s['cpu_ratio']:.2f}x)")
    return payload
