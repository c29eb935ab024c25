"""fastest: the time-optimal answer against every other verified plan of the planner service.

``att-bench fastest [--sets N] [--budget S] [--padding-deg D] [--options JSON] [--methods M,...] --json PATH``
plans each of the seeded random keep-out sets of :mod:`att_planner.reference.random_keepout` (the
Swift cones plus 1–7 random cones near the path) through the planner service's own pipeline in this
process (:func:`att_planner.service.planning.plan_maneuver`, the node's default cone padding, no
ROS), once per method (``--options``: time_optimal's request options, checked by the registry, e.g.
a coarse mesh), and re-verifies every answer against the unpadded problem
(:func:`att_planner.verification.verify`, the suite's tolerances). The first plan (graph_smooth, the
service's first stage) and the smooth plan (smooth_collocation, the default method) are the plans
the time-optimal answer must not be slower than: a *violation* is a set where time_optimal's
verified t_f exceeds the smaller verified t_f of those two, or time_optimal has no verified answer
where one of them has. The study passes when there is none and every answer verifies. The JSON
holds each set's problem (inertia J, torque limit, start and goal attitudes, sensor axis, cones) and
each answer's profile (t, q, omega, torque; s, [x, y, z, w], rad/s, N m) for an independent check.
Times are in TU (J = I, T̄ = 1).
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import replace

import numpy as np

from att_msgs_py.errors import RequestError
from att_planner import methods
from att_planner.reference.random_keepout import FASTEST_SETS, keepout_set
from att_planner.service.planner_parameters import PLANNER
from att_planner.service.planning import plan_maneuver, run_method
from att_planner.service.requests import ValidRequest
from att_planner.verification import rejection, verify

FIRST, SMOOTH, TIME_OPTIMAL = "graph_smooth", "smooth_collocation", "time_optimal"
DEFAULT_METHODS = (FIRST, SMOOTH, TIME_OPTIMAL)
SLACK_S = 1e-9          # t_f of the same plan compared twice
PROFILE_DIGITS = 10     # significant digits of the profiles in the JSON
JSON_INDENT = None      # the JSON on one line: it holds every answer's profile


def configure(parser):
    parser.add_argument("--sets", type=int, default=len(FASTEST_SETS), help="the first N seeded sets")
    parser.add_argument("--budget", type=float, default=20.0, help="time budget of each request, seconds")
    parser.add_argument("--padding-deg", type=float, default=None,
                        help="cone padding of the service, deg (default: the planner node's)")
    parser.add_argument("--options", default="{}", metavar="JSON",
                        help="time_optimal's request options, a JSON object, e.g. "
                             "'{\"intervals\": 4, \"max_intervals\": 4}'")
    parser.add_argument("--methods", default=",".join(DEFAULT_METHODS),
                        help=f"methods planned per set, comma-separated (must include {FIRST}, {SMOOTH}, "
                             f"{TIME_OPTIMAL})")


def _answer(problem, method: str, budget: float, padding: float, options: dict) -> dict:
    """One request through the service (``options`` validated by the registry): the answer
    re-verified on the unpadded problem, its profile."""
    valid = ValidRequest(replace(problem, deadline=time.monotonic() + budget), methods.get(method), options, "swift",
                         budget)
    start = time.perf_counter()
    outcome = plan_maneuver(valid, cone_padding=padding, runner=run_method)
    seconds = time.perf_counter() - start
    plan = outcome.plan
    row = {"method": method, "code": int(outcome.code), "stage": str(outcome.stage), "seconds": seconds,
           "message": outcome.message, "stages": [{"name": str(s.name), "method": s.method, "seconds": s.seconds,
                                                   "verified": s.verified, "duration": s.duration}
                                                  for s in outcome.stages],
           "verified": False, "tf": None}
    if outcome.verification is not None and plan is not None and len(plan.t) > 1:
        ver = verify(problem, plan)
        why = rejection(ver)
        row.update(verified=why is None, rejection=why, tf=float(plan.duration), status=str(plan.status),
                   min_margin_deg=math.degrees(ver.min_cone_margin), fastest=plan.stats.get("fastest"),
                   interpolation=str(plan.interpolation),
                   profile={k: _rounded(getattr(plan, k)) for k in ("t", "q", "omega", "torque")})
    return row


def _rounded(values: np.ndarray) -> list:
    """``values`` as nested lists of floats of :data:`PROFILE_DIGITS` significant digits."""
    values = np.asarray(values, float)
    return np.array([float(f"{v:.{PROFILE_DIGITS}g}") for v in values.ravel()]).reshape(values.shape).tolist()


def _violation(rows: dict) -> str:
    """Why time_optimal's answer is slower than the verified first or smooth plan, or ''."""
    bounds = {m: rows[m]["tf"] for m in (FIRST, SMOOTH) if rows[m]["verified"]}
    if not bounds:
        return ""
    best = min(bounds, key=bounds.get)
    to = rows[TIME_OPTIMAL]
    if not to["verified"]:
        return f"time_optimal has no verified answer; {best} has t_f {bounds[best]:.4f}"
    if to["tf"] > bounds[best] + SLACK_S:
        return f"time_optimal t_f {to['tf']:.4f} > {best} t_f {bounds[best]:.4f}"
    return ""


def run(args) -> dict:
    names = [m.strip() for m in args.methods.split(",") if m.strip()]
    missing = [m for m in DEFAULT_METHODS if m not in names]
    if missing:
        raise SystemExit(f"att-bench fastest: --methods must include {', '.join(missing)}")
    for name in names:
        methods.get(name)            # an unknown name is refused before anything runs
    try:
        options = json.loads(args.options)
        if not isinstance(options, dict):
            raise ValueError(f"expected a JSON object, found {type(options).__name__}")
        options = methods.get(TIME_OPTIMAL).validate(options)
    except (ValueError, RequestError) as exc:
        raise SystemExit(f"att-bench fastest: --options {args.options!r}: {exc}") from None
    padding_deg = PLANNER["cone_padding_deg"].default if args.padding_deg is None else args.padding_deg
    padding = math.radians(padding_deg)
    sets, violations, unverified = [], [], []
    print(f"fastest: {args.sets} random keep-out sets, budget {args.budget:g} s, padding {padding_deg:g} deg, "
          f"time_optimal options {options} (t_f in TU; * = not verified)")
    print(f"{'seed':>4} {'cones':>5} " + " ".join(f"{m[:14]:>14}" for m in names) + "  time_optimal answer")
    for seed in list(FASTEST_SETS)[:args.sets]:
        problem = keepout_set(seed)
        rows = {m: _answer(problem, m, args.budget, padding, options if m == TIME_OPTIMAL else {}) for m in names}
        why = _violation(rows)
        if why:
            violations.append({"seed": seed, "why": why})
        unverified += [{"seed": seed, "method": m} for m, r in rows.items()
                       if r["tf"] is not None and not r["verified"]]
        answer = (rows[TIME_OPTIMAL].get("fastest") or {}).get("answer", "")
        print(f"{seed:4d} {len(problem.cones):5d} " + " ".join(
            f"{'—' if r['tf'] is None else format(r['tf'], '.4f') + ('' if r['verified'] else '*'):>14}"
            for r in rows.values()) + f"  {answer}{'  VIOLATION: ' + why if why else ''}")
        sets.append({"seed": seed, "J": problem.spacecraft.inertia, "torque_limit": problem.spacecraft.body_torque_max,
                     "q_initial": problem.q_initial, "q_final": problem.q_final, "sensor_axis": problem.sensor_axis,
                     "cones": [{"name": c.name, "direction": c.direction, "half_angle_deg": math.degrees(c.half_angle)}
                               for c in problem.cones],
                     "plans": rows, "violation": why})
    to_seconds = [s["plans"][TIME_OPTIMAL]["seconds"] for s in sets]
    summary = {m: {"verified": sum(s["plans"][m]["verified"] for s in sets),
                   "median_seconds": float(np.median([s["plans"][m]["seconds"] for s in sets]))} for m in names}
    answers = [(s["plans"][TIME_OPTIMAL].get("fastest") or {}).get("answer", "") for s in sets]
    passed = not violations and not unverified
    print(f"violations (time_optimal slower than the verified first or smooth plan): {len(violations)}; "
          f"answers not verified: {len(unverified)}; time_optimal answered by a warm start on "
          f"{sum(a.startswith('warm start') for a in answers)} sets, by a further start on "
          f"{sum(a.startswith('further start') for a in answers)}; time_optimal request median "
          f"{np.median(to_seconds):.2f} s, max {max(to_seconds):.2f} s")
    return {"fastest_sets": len(sets), "budget_s": args.budget, "padding_deg": padding_deg, "methods": names,
            "time_optimal_options": options,
            "violations": violations, "unverified": unverified, "summary": summary,
            "time_optimal_seconds": {"median": float(np.median(to_seconds)), "max": float(max(to_seconds))},
            "warm_start_answers": sum(a.startswith("warm start") for a in answers),
            "further_start_answers": sum(a.startswith("further start") for a in answers),
            "passed": passed, "sets": sets}
