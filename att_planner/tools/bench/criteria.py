"""The studies' criteria: how each study's JSON is recognised and summarised as one history line.

Each :class:`Study` names a study of ``att-bench``, recognises its JSON from its keys, reduces it to a
:class:`Summary` (the headline figure, its unit, the criterion in words and whether it is met, the
other figures) and rebuilds the command that wrote it. Every figure is read from the JSON; each
study's criterion is written once, here (:data:`STUDIES`). :mod:`.history` appends the lines and
:mod:`.summary` renders them.
"""
from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass

from att_planner.tools.cpu_layers import parts as cpu_parts

MC_TARGET_RUNS = 1000            # runs of the demo maneuver ...
MC_TARGET_RUNS_PER_S = 3.3       # ... in 5 minutes on the 2-core machine
SMOOTH_COMPUTE_S = 10.0          # compute of the default smooth plan
SCHEDULE_TF_RATIO = 1.01         # t_f against the published schedule
MOMENTUM_WHEEL_RATIO = 0.5       # peak wheel speed with dumping, fraction of the limit
MOMENTUM_POINTING_DEG = 0.002    # pointing error rms bound
GAINS_FIXED_TS_ORBITS = 1.78     # settling time at IC (20), fixed gains
GAINS_FIXED_S = 60.0             # compute of the fixed-gains search
GAINS_ROBUST_WORST_ORBITS = 4.086  # thorough worst case of the published robust gains
GAINS_ROBUST_S = 600.0           # compute of the min-max search


class HistoryError(ValueError):
    """A JSON that cannot be summarised, or a history file that cannot be read."""


@dataclass(frozen=True)
class Summary:
    """The figures of one run: the headline ``value`` of ``metric`` in ``unit``, judged against ``target``."""

    case: str
    metric: str
    value: float
    unit: str
    target: str
    met: bool | None
    metrics: dict


@dataclass(frozen=True)
class Study:
    """How a study's JSON is recognised (``detect``), summarised and re-made (``command``)."""

    name: str
    detect: Callable[[dict], bool]
    summarise: Callable[[dict, str | None], Summary]
    command: Callable[[dict, str], str]


def _get(payload: dict, *keys):
    """``payload[k0][k1]...``, or a :class:`HistoryError` naming the missing key."""
    node = payload
    for i, key in enumerate(keys):
        if not isinstance(node, dict) or key not in node:
            raise HistoryError(f"the JSON has no '{'.'.join(str(k) for k in keys[:i + 1])}' (expected for this study)")
        node = node[key]
    return node


def _num(payload: dict, *keys) -> float:
    value = _get(payload, *keys)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise HistoryError(f"'{'.'.join(str(k) for k in keys)}' must be a finite number, found {value!r}")
    return float(value)


def _passes(payload: dict) -> bool:
    ver = _get(payload, "verification")
    if not isinstance(ver, dict):
        raise HistoryError(f"'verification' must be an object, found {ver!r}")
    return bool(ver.get("passes", ver.get("passed", False)))


# --- one summary per study -------------------------------------------------------------------------------------

def _smooth(p: dict, case: str | None) -> Summary:
    case = case or str(_get(p, "case"))
    unit = "TU" if _get(p, "case") == "swift" else "s"
    tf, secs, dfsp = _num(p, "tf"), _num(p, "solve_seconds"), _num(p, "published", "dfsp")
    met = tf <= dfsp and secs <= SMOOTH_COMPUTE_S and _passes(p)
    metrics = {"tf": tf, "solve_s": secs, "M": _get(p, "M"), "method": _get(p, "method"), "verified": _passes(p)}
    for run in p.get("runs") or []:         # every method and basis size the study tabulates
        if isinstance(run, dict) and {"method", "M", "tf"} <= run.keys():
            metrics[f"tf_{run['method']}_M{run['M']}"] = run["tf"]
    return Summary(case, "t_f, default smooth plan", tf, unit,
                   f"≤ {dfsp:g} {unit} (published DFSP), ≤ {SMOOTH_COMPUTE_S:g} s compute, verified", met, metrics)


def _time_optimal(p: dict, case: str | None) -> Summary:
    case = case or str(_get(p, "case"))
    tf = _num(p, "tf")
    metrics = {"tf": tf, "solve_s": _num(p, "solve_seconds"), "method": _get(p, "method"), "verified": _passes(p)}
    for name, plan in (p.get("plans") or {}).items():
        if isinstance(plan, dict) and "tf" in plan:
            metrics[f"tf_{name}"] = plan["tf"]
    sweep = (p.get("sweep") or {}).get("summary") or {}
    for name in ("bp", "ba", "lambda"):     # the orientation sweep: best and worst over the orientations
        if isinstance(sweep.get(name), dict):
            metrics[f"sweep_{name}_best_worst"] = [sweep[name]["best"], sweep[name]["worst"]]
    return Summary(case, "t_f, time-optimal plan", tf, "TU", "a verified plan", _passes(p), metrics)


def _schedule(p: dict, case: str | None) -> Summary:
    experiment = str(_get(p, "experiment"))
    case = case or f"experiment {experiment}"
    tf, secs = _num(p, "tf"), _num(p, "solve_seconds")
    published, published_s = _num(p, "published", "tf"), _num(p, "published", "solve_seconds")
    stats = _get(p, "stats")
    if case == f"experiment {experiment}":     # the fast run: the paper's t_f and compute
        target = (f"≤ {SCHEDULE_TF_RATIO:g} × published t_f ({published:g} s), compute ≤ published "
                  f"({published_s:g} s), verified")
        met = tf <= SCHEDULE_TF_RATIO * published and secs <= published_s and _passes(p)
    else:                                      # a proof of the order (--prove, --exhaustive)
        target = f"order proven, ≤ {SCHEDULE_TF_RATIO:g} × published t_f ({published:g} s), verified"
        met = bool(stats.get("order_proven")) and tf <= SCHEDULE_TF_RATIO * published and _passes(p)
    metrics = {"tf": tf, "order": "".join(_get(p, "order")), "solve_s": secs, "published_solve_s": published_s,
               "orders_solved": stats.get("orders_solved"), "order_proven": stats.get("order_proven"),
               "verified": _passes(p), "rest_to_rest_ab_s": (p.get("rest_to_rest_ab") or {}).get("tf")}
    if isinstance(p.get("published_order_here"), dict):     # the paper's order under this model
        metrics["published_order_here_s"] = p["published_order_here"].get("tf")
        metrics["stopping_at_every_target_s"] = p["published_order_here"].get("rest_to_rest_legs_tf")
    if isinstance(p.get("grid_study"), list):
        metrics["grid_intervals_tf_s"] = {str(g["intervals"]): g["tf"] for g in p["grid_study"]}
    if isinstance(p.get("exhaustive"), dict):
        e = p["exhaustive"]
        metrics["orders"] = e.get("orders")
        metrics["best_orders_s"] = e.get("best_pair_tf")
        metrics["orders_above_their_reverse_0.1pct"] = e.get("orders_worse_than_their_reverse_by_0.1pct")
        metrics["exhaustive_s"] = e.get("seconds")
    return Summary(case, "t_f, schedule", tf, "s", target, met, metrics)


def _sky(p: dict, case: str | None) -> Summary:
    case = case or str(_get(p, "case"))
    s = _get(p, "summary")
    if "moving_true_margin" in s:
        moving = math.degrees(_num(s, "moving_true_margin"))
        frozen = math.degrees(_num(s, "frozen_true_margin"))
        met = bool(_get(s, "moving_verified_vs_truth"))
    else:       # the first sky JSONs: each plan verified against the true sky, margins in its verification
        moving = math.degrees(_num(p, "plans", "moving", "verification", "min_cone_margin"))
        frozen = math.degrees(_num(p, "plans", "frozen", "verification", "min_cone_margin"))
        met = _passes(_get(p, "plans", "moving"))
    return Summary(case, "moving plan's smallest true margin", moving, "deg",
                   "moving plan clear of every true zone, verified", met,
                   {"moving_margin_deg": moving, "frozen_margin_deg": frozen,
                    "frozen_entered": s.get("frozen_entered"), "tf_moving": _num(p, "plans", "moving", "tf"),
                    "tf_frozen": _num(p, "plans", "frozen", "tf"), "tf_ratio": s.get("tf_ratio")})


def _speed(p: dict, case: str | None) -> Summary:
    rows, goal = _get(p, "cases"), _get(p, "targets")
    first = max(_num(r, "first", "solve_cpu_seconds") for r in rows)
    best = max(_num(r, "best", "solve_seconds") for r in rows)
    ratio = max(_num(r, "best_tf_ratio") for r in rows)
    to = max(_num(r, "time_optimal_seconds") for r in rows)
    met = (first <= _num(goal, "first_seconds") and best <= _num(goal, "best_seconds")
           and ratio <= _num(goal, "best_tf_ratio") and to <= _num(goal, "time_optimal_seconds"))
    return Summary(case or "/".join(str(_get(r, "case")) for r in rows), "time-optimal method stage, slowest case",
                   to, "s", f"first plan ≤ {goal['first_seconds'] * 1e3:g} ms CPU; best ≤ {goal['best_seconds']:g} s "
                   f"and ≤ {goal['best_tf_ratio']:g} × t_o; time-optimal ≤ {goal['time_optimal_seconds']:g} s", met,
                   {"first_cpu_s": first, "best_s": best, "best_tf_ratio": ratio, "time_optimal_s": to})


def _estimation(p: dict, case: str | None) -> Summary:
    err = _num(p, "final_pointing_error_deg")
    if "pointing_bound_deg" in p:
        bound = _num(p, "pointing_bound_deg")
        target, met = f"≤ 3σ of the star tracker ({bound:.4f}°), success", bool(_get(p, "success")) and err <= bound
    else:       # a JSON without the bound: judged by the study's own success
        target, met = "success", bool(_get(p, "success"))
    truth = p.get("truth_loop") or {}
    return Summary(case or "swift_demo", "final pointing error, flown on the estimate", err, "deg", target, met,
                   {"final_pointing_error_deg": err, "attitude_error_rms_arcsec": _num(p, "attitude_error_rms_arcsec"),
                    "nees_mean": _num(p, "nees_mean"), "min_cone_margin_deg": _num(p, "min_cone_margin_deg"),
                    "truth_final_pointing_error_deg": truth.get("final_pointing_error_deg"),
                    "truth_min_cone_margin_deg": truth.get("min_cone_margin_deg")})


def _momentum(p: dict, case: str | None) -> Summary:
    peak = _num(p, "dumping", "peak_wheel_speed_ratio")
    rms = _num(p, "dumping", "pointing_error_rms_deg")
    met = peak < MOMENTUM_WHEEL_RATIO and rms <= MOMENTUM_POINTING_DEG
    return Summary(case or f"{_num(p, 'orbits'):g} orbits", "peak wheel speed with dumping", peak, "of the limit",
                   f"< {MOMENTUM_WHEEL_RATIO:g} of the limit, pointing rms ≤ {MOMENTUM_POINTING_DEG:g}°", met,
                   {"peak_wheel_ratio_dumping": peak, "pointing_error_rms_deg": rms,
                    "peak_wheel_ratio_no_dumping": _num(p, "no_dumping", "peak_wheel_speed_ratio"),
                    "saturation_time_s_no_dumping": _get(p, "no_dumping", "saturation_time_s")})


def _observe(p: dict, case: str | None) -> Summary:
    ratio = _num(p, "zone_cost_ratio")
    met = bool(_get(p, "with_zones", "verified")) and bool(_get(p, "without_zones", "verified"))
    return Summary(case or f"{len(_get(p, 'sources'))} sources", "tour t_f among the zones / without", ratio, "×",
                   "both tours verified on the true sky", met,
                   {"tf_with_zones": _num(p, "with_zones", "tf"), "tf_without_zones": _num(p, "without_zones", "tf"),
                    "solve_s_with_zones": _num(p, "with_zones", "solve_seconds")})


def _day(p: dict, case: str | None) -> Summary:
    observed, missed = int(_num(p, "observed")), int(_num(p, "missed"))
    margin = _num(p, "min_margin_deg")
    if case is None and p.get("rtf_mode", "").startswith("max"):
        case = f"{p.get('mission', 'observatory_day')}, --rtf max"
    return Summary(case or "observatory_day", "targets observed", observed, f"of {observed + missed}",
                   "every zone kept (smallest margin ≥ 0)", margin >= 0.0,
                   {"observed": observed, "missed": missed, "min_margin_deg": margin,
                    "peak_wheel_ratio": _num(p, "peak_wheel_ratio"), "rtf": _num(p, "rtf"),
                    "sim_s": _num(p, "sim_seconds")})


def _timing(p: dict, case: str | None) -> Summary:
    scalar = [_num(f, "scalar", "median_s") for group in ("sky", "orbit") for f in _get(p, group).values()]
    vector = [_num(f, "vector", "median_s") for group in ("sky", "orbit") for f in _get(p, group).values()]
    goal = _get(p, "targets")
    return Summary(case or "sky, orbit, request checks", "slowest single call (median)", max(scalar) * 1e6, "µs",
                   f"a call ≤ {_num(goal, 'scalar_s') * 1e6:g} µs; {_get(p, 'vector_times')} times ≤ "
                   f"{_num(goal, 'vector_s') * 1e3:g} ms; 16-cone check ≤ {_num(goal, 'closed_sky_s') * 1e3:g} ms",
                   bool(_get(p, "passed")),
                   {"scalar_worst_us": max(scalar) * 1e6, "vector_worst_ms": max(vector) * 1e3,
                    "closed_sky_ms": _num(p, "closed_sky", "median_s") * 1e3,
                    "goal_in_cone_ms": _num(p, "goal_in_cone", "median_s") * 1e3})


def _logtools(p: dict, case: str | None) -> Summary:
    tools, limits = _get(p, "tools"), _get(p, "limits")
    wall = max(_num(t, "worst_wall_s") for t in tools.values())
    rss = max(_num(t, "worst_rss_mb") for t in tools.values())
    return Summary(case or f"{_get(p, 'files')} files × {len(tools)} tools", "worst refusal time", wall, "s",
                   f"one line, a documented exit, ≤ {_num(limits, 'wall_s'):g} s, ≤ {_num(limits, 'rss_mb'):g} MB",
                   bool(_get(p, "passed")), {"worst_wall_s": wall, "worst_rss_mb": rss,
                                             "failed": len(_get(p, "failed"))})


def _flood(p: dict, case: str | None) -> Summary:
    growth = _get(p, "growth_mib")
    worst = max(_num(growth, k) for k in growth)
    late = _get(p, "worst_past_budget")
    return Summary(case or f"{int(_num(p, 'messages'))} messages", "largest RSS growth of a process", worst, "MiB",
                   f"≤ {_num(p, 'growth_limit_mib'):g} MiB per process", bool(_get(p, "passed")),
                   {"growth_mib": growth, "worst_past_budget_s": max(_num(late, k) for k in late),
                    "flood_s": _num(p, "flood_seconds")})


def _monte_carlo(p: dict, case: str | None) -> Summary:
    runs, workers, rate = int(_num(p, "runs")), int(_num(p, "workers")), _num(p, "runs_per_second")
    requested, success = int(_num(p, "requested")), _num(p, "success_rate")
    if requested >= MC_TARGET_RUNS:
        target = f"≥ {MC_TARGET_RUNS} runs at ≥ {MC_TARGET_RUNS_PER_S:g} runs/s, every run a success"
        met = runs >= MC_TARGET_RUNS and rate >= MC_TARGET_RUNS_PER_S and success == 1.0
    else:                                      # a scaling or A/B run: no target of its own
        target, met = "none (a scaling or comparison run)", None
    return Summary(case or f"{requested} runs, {workers} worker{'s' if workers > 1 else ''}",
                   "closed-loop runs per second", rate, "runs/s", target, met,
                   {"runs": runs, "workers": workers, "wall_s": _num(p, "wall_seconds"),
                    "cpu_s_per_run": _num(p, "cpu_seconds_per_run", "mean"), "success_rate": success,
                    "final_error_deg_p99": _num(p, "final_error_deg", "p99"),
                    "final_error_deg_max": _num(p, "final_error_deg", "max"),
                    "min_margin_deg_min": _num(p, "min_margin_deg", "min")})


def _gains(p: dict, case: str | None) -> Summary:
    mode, ts, secs = _get(p, "mode"), _num(p, "ts"), _num(p, "solve_seconds")
    if mode == "fixed":
        return Summary(case or "fixed", "t_s at IC (20), truth path", ts, "orbits",
                       f"≤ {GAINS_FIXED_TS_ORBITS:g} orbits in ≤ {GAINS_FIXED_S:g} s",
                       ts <= GAINS_FIXED_TS_ORBITS and secs <= GAINS_FIXED_S,
                       {"kp": _num(p, "kp"), "kd": _num(p, "kd"), "ts_orbits": ts, "solve_s": secs})
    return Summary(case or "robust", "thorough worst-case t_s", ts, "orbits",
                   f"≤ {GAINS_ROBUST_WORST_ORBITS:g} orbits (published robust gains) in ≤ {GAINS_ROBUST_S:g} s",
                   ts <= GAINS_ROBUST_WORST_ORBITS and secs <= GAINS_ROBUST_S,
                   {"kp": _num(p, "kp"), "kd": _num(p, "kd"), "ts_orbits": ts, "solve_s": secs})


def _soak(p: dict, case: str | None) -> Summary:
    dropped = int(_num(p, "dropped_state"))
    clean = dropped == 0 and not any(_get(p, "exit_codes").values())
    if "rtf_target" in p:          # a real-time factor study: the scenario, its length and rate name the case
        rtf, target = _num(p, "real_time_factor"), _num(p, "rtf_target")
        estimator = ", with the estimator" if "estimator" in p["nodes"] else ""
        figures = {"rtf": rtf, "dropped_state": dropped, "sim_s": _num(p, "sim_time"),
                   "loop_wall_s": _num(p, "loop_wall_seconds"),
                   "cpu_ms_per_sim_s": {k: v / _num(p, "sim_time") * 1e3 for k, v in p["cpu_seconds"].items()}}
        if "cpu_layers" in p:
            try:
                figures["cpu_by_layer_ms_per_sim_s"] = cpu_parts(_get(p, "cpu_layers"))
            except (KeyError, TypeError, AttributeError, ValueError) as err:
                raise HistoryError(f"'cpu_layers' is not a soak's CPU by layer ({err!r})") from None
        return Summary(case or f"{p['scenario']}, {_num(p, 'hours'):g} h at {_num(p, 'rate_Hz'):g} Hz{estimator}",
                       "real-time factor through the nodes", rtf, "×",
                       f"≥ {target:g}, every state recorded, every process exits 0", rtf >= target and clean, figures)
    return Summary(case or f"{_num(p, 'orbits'):g} orbits", "state messages dropped", dropped, "",
                   "none dropped, every process exits 0", dropped == 0 and not any(_get(p, "exit_codes").values()),
                   {"rtf": _num(p, "real_time_factor"), "state_messages": _num(p, "state_messages"),
                    "settling_orbits": p.get("settling_orbits")})


def _cluster(p: dict, case: str | None) -> Summary:
    ratio, target = _num(p, "throughput_ratio"), _num(p, "throughput_target")
    workers = _get(p, "rss", "workers")
    return Summary(case or f"{int(_num(p, 'runs'))} runs, {int(_num(p, 'workers'))} workers",
                   "cluster processes' runs/s / the local cluster's", ratio, "×",
                   f"≥ {target:g}×, the same rows, worker RSS growth ≤ {_num(p, 'growth_limit_mib'):g} MiB",
                   bool(_get(p, "passed")),
                   {"campaign": _get(p, "campaign"), "local_runs_per_s": _num(p, "local"),
                    "cluster_runs_per_s": _num(p, "cluster"), "rows_equal": bool(_get(p, "rows_equal")),
                    "rss_growth_mib": _num(p, "rss_growth_mib"),
                    "rss_peak_mib": max(_num(w, "peak_mib") for w in workers) if workers else None})


def _fastest(p: dict, case: str | None) -> Summary:
    violations, unverified = len(_get(p, "violations")), len(_get(p, "unverified"))
    seconds = _get(p, "time_optimal_seconds")
    options = p.get("time_optimal_options") or {}
    named = ", time_optimal " + ", ".join(f"{k} {v}" for k, v in options.items()) if options else ""
    return Summary(case or f"{int(_num(p, 'fastest_sets'))} random keep-out sets{named}",
                   "sets where time_optimal is slower than the verified first or smooth plan", violations, "",
                   "none, every answer verified", violations == 0 and unverified == 0 and bool(_get(p, "passed")),
                   {"unverified": unverified, "warm_start_answers": _num(p, "warm_start_answers"),
                    "further_start_answers": _num(p, "further_start_answers"),
                    "time_optimal_median_s": _num(seconds, "median"), "time_optimal_max_s": _num(seconds, "max")})


def _rtf(p: dict, case: str | None) -> Summary:
    rtf, target = _num(p, "rtf"), _num(p, "target_rtf")
    success = bool(_get(p, "success"))
    return Summary(case or f"{_get(p, 'scenario')}, in process", "real-time factor, one closed-loop run alone", rtf,
                   "×", f"≥ {target:g}× real time, the maneuver a success", rtf >= target and success,
                   {"sim_s": _num(p, "sim_seconds"), "flight_wall_s": _num(p, "wall_seconds"),
                    "rtf_cpu": _num(p, "rtf_cpu"), "setup_s": _num(p, "setup_seconds"),
                    "planning_s": _num(p, "planning_seconds"),
                    "final_error_deg": _num(p, "final_error_deg"), "success": success})


AEOS_GREEDY_RATIO = 1.1          # flown images at each level against the greedy policy's
AEOS_LEVEL_A_FRACTION = 0.65     # flown level-(a) images, fraction of the accessible sites
AEOS_LEVEL_B_FRACTION = 0.45     # flown level-(b) images
AEOS_CPU_PER_ORBIT_S = 10.0      # planner CPU per simulated orbit


AEOS_POLICIES = ("greedy", "ours", "rollout")   # the baseline first, then ours from the simplest


def _aeos_flown(p: dict, case: str | None) -> Summary:
    """A flown day: the headline is the last flown policy's level-(b) images (of :data:`AEOS_POLICIES`,
    the last present), judged against the greedy baseline's."""
    flown, accessible = _get(p, "flown"), _num(_get(p, "accessible"), "sites")
    policies = [k for k in AEOS_POLICIES if isinstance(flown.get(k), dict) and flown[k].get("status") == "flown"]
    planned_only = not policies
    if planned_only:
        policies = [k for k in AEOS_POLICIES if isinstance(flown.get(k), dict)]
        if not policies:
            raise HistoryError("an aeos JSON whose 'flown' holds no policy")
    head = policies[-1]
    metrics = {}
    for k in policies:
        e = flown[k]
        if planned_only:
            metrics.update({f"{k}_planned": _num(e, "planned_images"), f"{k}_priority": _num(e, "planned_priority"),
                            f"{k}_cpu_s_per_orbit": _num(e, "planner_cpu_s_per_orbit")})
            continue
        metrics.update({f"{k}_level_a": _num(e, "level_a", "images"), f"{k}_level_b": _num(e, "level_b", "images"),
                        f"{k}_lost_b": _num(e, "level_b", "lost"), f"{k}_planned": _num(e, "planned_images"),
                        f"{k}_cpu_s_per_orbit": _num(e, "planner_cpu_s_per_orbit"),
                        f"{k}_zone_entries": _num(e, "zone_entries"),
                        f"{k}_worst_zone_margin_deg": _num(e, "flown_worst_zone_margin_deg")})
    metrics["accessible_sites"] = accessible
    if head != "greedy" and "greedy" in policies:
        keys = ("planned_images",) if planned_only else ("level_b", "images")
        metrics[f"{head}_over_greedy"] = _num(flown[head], *keys) / _num(flown["greedy"], *keys)
    if isinstance(p.get("bound"), dict):
        metrics["bound_images"] = _num(p, "bound", "images")
    if planned_only:
        return Summary(case or f"{_get(p, 'targets')} seed {_get(p, 'seed')}, {_num(p, 'orbits'):g} orbits, planned "
                               f"{'/'.join(policies)}",
                       f"{head} images planned with verified slews (not flown)", _num(flown[head], "planned_images"),
                       f"of {int(accessible)} accessible", "none (planned, not flown)", None, metrics)
    met = None
    if head != "greedy" and "greedy" in policies:
        g, o = flown["greedy"], flown[head]
        met = all(_num(o, f"level_{x}", "images") >= AEOS_GREEDY_RATIO * _num(g, f"level_{x}", "images")
                  for x in "ab") and _num(o, "level_a", "images") >= AEOS_LEVEL_A_FRACTION * accessible \
            and _num(o, "level_b", "images") >= AEOS_LEVEL_B_FRACTION * accessible \
            and all(_num(e, "zone_entries") == 0 and _num(e, "planner_cpu_s_per_orbit") <= AEOS_CPU_PER_ORBIT_S
                    for e in (g, o))
    return Summary(case or f"{_get(p, 'targets')} seed {_get(p, 'seed')}, {_num(p, 'orbits'):g} orbits, flown "
                           f"{'/'.join(policies)}",
                   f"{head} images flown at level (b), checked on the truth", _num(flown[head], "level_b", "images"),
                   f"of {int(accessible)} accessible",
                   f"each level >= {AEOS_GREEDY_RATIO:g}x greedy; (a) >= {AEOS_LEVEL_A_FRACTION:.0%}, (b) >= "
                   f"{AEOS_LEVEL_B_FRACTION:.0%} of the accessible; 0 zone entries; planner CPU <= "
                   f"{AEOS_CPU_PER_ORBIT_S:g} s per orbit", met, metrics)


def _aeos(p: dict, case: str | None) -> Summary:
    if isinstance(p.get("flown"), dict):
        return _aeos_flown(p, case)
    greedy, accessible = _get(p, "greedy"), _get(p, "accessible")
    return Summary(case or f"{_get(p, 'targets')} seed {_get(p, 'seed')}, {_num(p, 'orbits'):g} orbits",
                   f"greedy images {_get(greedy, 'status')}", _num(greedy, "images"),
                   f"of {int(_num(accessible, 'sites'))} accessible", "none (a planning estimate)", None,
                   {"accessible_sites": _num(accessible, "sites"), "accessible_priority": _num(accessible, "priority"),
                    "greedy_priority": _num(greedy, "priority"), "access_windows": _num(p, "access_windows", "total"),
                    "compute_s": _num(p, "compute_s", "access") + _num(p, "compute_s", "greedy")})


def _faults(p: dict, case: str | None) -> Summary:
    met, alarms = _get(p, "met"), _get(p, "false_alarm_campaign")
    right, cases = _num(met, "detected_in_time_right"), _num(met, "cases")
    unseen = _num(met, "unobservable") if "unobservable" in met else 0.0
    runs, false = _num(alarms, "runs"), _num(alarms, "runs_with_a_report")
    return Summary(case or f"{_get(p, 'scenario')}, {int(cases)} cases, {int(runs)} fault-free runs",
                   "faults detected in time and isolated right", right,
                   f"of {int(cases - unseen)} observable ({int(unseen)} with no reading after the onset)"
                   if "unobservable" in met else f"of {int(cases)}",
                   "every fault in <= 5 s (wheels, gyro) or <= 30 s, no zone entered, 0 false alarms in 1000 runs",
                   bool(_get(p, "passed")) and runs >= 1000,
                   {"zone_entered": _num(met, "zone_entered"), "false_alarm_runs": false, "fault_free_runs": runs,
                    "wall_s": _num(p, "wall_seconds")})


def _cmd(template: str) -> Callable[[dict, str], str]:
    return lambda p, path: template.format(path=path, **{k: v for k, v in p.items()
                                                                                 if isinstance(v, str | int | float)})


def _day_command(p: dict, path: str) -> str:
    """``att-bench day`` with the mission and the ``--rtf`` of its ``rtf_mode`` (none: paced)."""
    mode = str(p.get("rtf_mode", ""))
    rtf = "max" if mode.startswith("max") else mode.split()[2].rstrip(",") if mode.startswith("at most") else None
    return ("att-bench day" + (f" --mission {p['mission']}" if "mission" in p else "")
            + (f" --rtf {rtf}" if rtf else "") + f" --json {path}")


STUDIES: tuple[Study, ...] = (
    Study("monte-carlo", lambda p: "runs_per_second" in p and "campaign" in p, _monte_carlo,
          lambda p, path: f"att-mc {p['campaign']} --runs {p['requested']} --workers {p['workers']} "
                          f"--json {path}"),
    Study("smooth", lambda p: {"N", "W", "alpha"} <= p.keys(), _smooth,
          _cmd("att-bench smooth --case {case} --json {path}")),
    Study("schedule", lambda p: "experiment" in p, _schedule,
          _cmd("att-bench schedule --experiment {experiment} --json {path}")),
    Study("sky", lambda p: isinstance(p.get("plans"), dict) and {"frozen", "moving"} <= p["plans"].keys(), _sky,
          _cmd("att-bench sky --case {case} --json {path}")),
    Study("time-optimal", lambda p: {"case", "tf", "torque", "verification"} <= p.keys(), _time_optimal,
          _cmd("att-bench time-optimal --case {case} --json {path}")),
    Study("speed", lambda p: "cases" in p and "targets" in p, _speed, _cmd("att-bench speed --ros --json {path}")),
    Study("estimation", lambda p: "nees_mean" in p, _estimation, _cmd("att-bench estimation --json {path}")),
    Study("momentum", lambda p: "dumping" in p and "no_dumping" in p, _momentum,
          _cmd("att-bench momentum --in-process --orbits {orbits:g} --json {path}")),
    Study("observe", lambda p: "zone_cost_ratio" in p, _observe, _cmd("att-bench observe --json {path}")),
    Study("day", lambda p: "observed" in p and "missed" in p, _day, _day_command),
    Study("timing", lambda p: "closed_sky" in p, _timing, _cmd("att-bench timing --json {path}")),
    Study("logtools", lambda p: "tools" in p and "allowed_exits" in p, _logtools,
          _cmd("att-bench logtools --json {path}")),
    Study("flood", lambda p: "growth_mib" in p, _flood, _cmd("att-bench flood --messages {messages} --json {path}")),
    Study("gains", lambda p: p.get("mode") in ("fixed", "robust") and "kp" in p, _gains,
          _cmd("att-bench gains --mode {mode} --json {path}")),
    Study("soak", lambda p: "dropped_state" in p, _soak,
          lambda p, path: f"att-bench soak --scenario {p['scenario']} "
                          + (f"--hours {p['hours']:g} --rate-Hz {p['rate_Hz']:g} " if "rtf_target" in p
                             else f"--orbits {p['orbits']:g} ") + ("--cpu bench_out/soak_cpu " if "cpu_layers" in p
                                                                   else "") + f"--json {path}"),
    Study("cluster", lambda p: "throughput_ratio" in p, _cluster,
          _cmd("att-bench cluster --campaign {campaign} --runs {runs} --workers {workers} --json {path}")),
    Study("rtf", lambda p: "target_rtf" in p and p.get("in_process") is True, _rtf,
          _cmd("att-bench rtf --in-process --scenario {scenario} --json {path}")),
    Study("fastest", lambda p: "fastest_sets" in p, _fastest,
          lambda p, path: f"att-bench fastest --sets {p['fastest_sets']} --budget {p['budget_s']:g} "
                          + (f"--options '{json.dumps(p['time_optimal_options'])}' " if p.get("time_optimal_options")
                             else "") + f"--json {path}"),
    Study("faults", lambda p: p.get("study") == "faults", _faults,
          _cmd("att-bench faults --scenario {scenario} --runs {runs} --workers {workers} --json {path}")),
    Study("aeos", lambda p: p.get("study") == "aeos", _aeos,
          lambda p, path: f"att-bench aeos --targets {p['targets']} --seed {p['seed']} --orbits {p['orbits']:g} "
                          + (f"--fly --policies {','.join(p['flown'])} " if isinstance(p.get("flown"), dict) else "")
                          + ("--plan-only " if isinstance(p.get("flown"), dict) and not any(
                              isinstance(e, dict) and e.get("status") == "flown" for e in p["flown"].values()) else "")
                          + ("--bound " if "bound" in p else "") + f"--json {path}"),
)
BY_NAME = {s.name: s for s in STUDIES}


def detect(payload: dict) -> Study:
    """The one study whose JSON ``payload`` is; a :class:`HistoryError` when none or several match."""
    found = [s for s in STUDIES if s.detect(payload)]
    if len(found) != 1:
        what = "no study" if not found else "several studies (" + ", ".join(s.name for s in found) + ")"
        raise HistoryError(f"the JSON matches {what}; name it with --study (one of {', '.join(BY_NAME)})")
    return found[0]
