"""The min-max of Bruni & Celani, ``min_κ max_{h∈H} t_s(κ, h)``: the inner problem (worst initial
condition of given gains), the outer problems (fixed initial condition, and the robust
outer-approximation of Blankenship & Falk 1976), and an independent thorough check over ``H``."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import Status
from att_planner.tuning.evaluation import BatchEvaluator
from att_planner.tuning.search import DirectSearch, direct_batch, sdbox_batch
from att_planner.tuning.settling import CAPPED, H_LOWER, H_UPPER, LOG_GAIN_BOUNDS, SETTLED, multistart_points

# ---------------------------------------------------------------------------------------------
# Inner problem: worst initial condition for given gains
# ---------------------------------------------------------------------------------------------

INNER_METHODS = ("direct", "sdbox", "sdbox-multistart")


@dataclass
class WorstCase:
    """Worst initial condition found for one gain pair (maximum of ``t_s`` over ``H``); ``wall_time`` in s."""

    h: np.ndarray
    ts: float
    capped: bool
    nfev: int
    method: str
    wall_time: float
    X: np.ndarray = field(repr=False, default=None)   # every initial condition evaluated
    T: np.ndarray = field(repr=False, default=None)   # its settling time (orbits)


def _sdbox_starts(method: str, known_x: np.ndarray, known_t: np.ndarray, neg_ts) -> tuple[np.ndarray, np.ndarray]:
    """SDBOX starts and their values ``−t_s``: the known worst (or first) start, after the paper's 8
    starts for 'sdbox-multistart'; known settling times are reused, the others simulated."""
    warm = known_x[np.nanargmax(known_t)][None] if np.isfinite(known_t).any() else known_x[:1]
    pts = warm if method == "sdbox" else np.vstack([multistart_points(), warm])
    if method == "sdbox" and not len(pts):
        pts = multistart_points()[:1]
    f0 = np.full(len(pts), np.nan)
    for i, p in enumerate(pts):
        hit = np.flatnonzero(np.all(np.isclose(known_x, p, rtol=0.0, atol=1e-12), 1) & np.isfinite(known_t))
        if hit.size:
            f0[i] = -known_t[hit[0]]
    missing = np.isnan(f0)
    if missing.any():
        f0[missing] = neg_ts(pts[missing])
    return pts, f0


def worst_case(evaluator: BatchEvaluator, kp: float, kd: float, *, method: str = "sdbox-multistart",
               starts=None, start_ts=None, maxfun: int = 600, deadline: float | None = None) -> WorstCase:
    """Maximise ``t_s(κ_p, κ_d, h)`` over ``h ∈ H``.

    ``method``: 'direct' (batched DIRECT over H), 'sdbox' (one SDBOX start: the first of
    ``starts``, e.g. the previous worst case — the warm start), 'sdbox-multistart' (the paper's 8
    extreme-rate starts plus ``starts``). ``start_ts`` are the known settling times of ``starts``
    (reused, not re-simulated).
    """
    if method not in INNER_METHODS:
        raise ValueError(f"inner method '{method}' is not one of {INNER_METHODS}")
    t0 = time.perf_counter()

    def neg_ts(h):
        return -evaluator.settling(kp, kd, h).ts

    known_x = np.empty((0, len(H_LOWER))) if starts is None else np.atleast_2d(np.asarray(starts, float))
    known_t = np.full(len(known_x), np.nan) if start_ts is None else np.asarray(start_ts, float).reshape(-1)
    if method == "direct":
        res = direct_batch(neg_ts, H_LOWER, H_UPPER, maxfun=maxfun, deadline=deadline)
    else:
        pts, f0 = _sdbox_starts(method, known_x, known_t, neg_ts)
        res = sdbox_batch(neg_ts, H_LOWER, H_UPPER, pts, maxfun=maxfun, deadline=deadline, f_starts=f0)
    X, ts = np.vstack([res.X, known_x]), np.concatenate([-res.F, known_t])
    ts = np.where(np.isnan(ts), -np.inf, ts)
    b = int(np.argmax(ts))
    return WorstCase(X[b].copy(), float(ts[b]), bool(ts[b] >= evaluator.settings.cap_orbits), res.nfev,
                     method, time.perf_counter() - t0, X, ts)


def distinct_worst(X: np.ndarray, T: np.ndarray, count: int, above: float, separation: float = 0.1) -> np.ndarray:
    """Up to ``count`` initial conditions with ``t_s > above``, worst first, pairwise at least
    ``separation`` apart in the unit-scaled box (so the hard set gains new cases, not copies)."""
    order = np.argsort(-T)
    scale = H_UPPER - H_LOWER
    picked = []
    for i in order:
        if T[i] <= above or len(picked) >= count:
            break
        z = X[i] / scale
        if all(np.max(np.abs(z - X[j] / scale)) >= separation for j in picked):
            picked.append(i)
    return X[picked]


# ---------------------------------------------------------------------------------------------
# Outer problems
# ---------------------------------------------------------------------------------------------


@dataclass
class TuningResult:
    """Gains found by :func:`tune_fixed` or :func:`tune_robust`.

    ``ts`` is the objective at the gains (orbits): the settling time at the fixed initial
    condition, or the worst case found over ``H`` by the inner searches. ``worst_ic`` is that
    initial condition as ``(ρ, φ, θ, ω1, ω2, ω3, ψ)``. ``nfev``: simulated cases, ``wall_time`` in s.
    """

    mode: str
    kp: float
    kd: float
    ts: float
    worst_ic: np.ndarray
    nfev: int
    wall_time: float
    status: Status
    message: str
    history: list = field(default_factory=list)     # (seconds, best objective, note)
    hard_set: np.ndarray | None = None
    stats: dict = field(default_factory=dict)


class _GainTable:
    """Settling times of every outer point (log gains) against the hard set, with exactness.

    ``value(i) = max_j T[i, j]`` is exact when every entry is exact (SETTLED/CAPPED) and otherwise
    a lower bound (pruned entries, or hard cases not yet evaluated at that point).
    """

    def __init__(self, evaluator: BatchEvaluator, hard: np.ndarray):
        self.evaluator = evaluator
        self.hard = np.atleast_2d(np.asarray(hard, float))
        self.gains = np.empty((0, 2))
        self.T = np.empty((0, len(self.hard)))
        self.exact = np.empty((0, len(self.hard)), bool)

    def values(self) -> tuple[np.ndarray, np.ndarray]:
        v = np.nanmax(np.where(np.isnan(self.T), -np.inf, self.T), 1)
        return v, self.exact.all(1)

    def incumbent(self) -> tuple[int, float]:
        v, ex = self.values()
        if not ex.any():
            return -1, np.inf
        i = int(np.flatnonzero(ex)[np.argmin(v[ex])])
        return i, float(v[i])

    def add_points(self, log_gains: np.ndarray) -> np.ndarray:
        start = len(self.gains)
        self.gains = np.vstack([self.gains, log_gains])
        self.T = np.vstack([self.T, np.full((len(log_gains), len(self.hard)), np.nan)])
        self.exact = np.vstack([self.exact, np.zeros((len(log_gains), len(self.hard)), bool)])
        return np.arange(start, len(self.gains))

    def add_hard(self, h: np.ndarray):
        h = np.atleast_2d(h)
        self.hard = np.vstack([self.hard, h])
        self.T = np.hstack([self.T, np.full((len(self.gains), len(h)), np.nan)])
        self.exact = np.hstack([self.exact, np.zeros((len(self.gains), len(h)), bool)])

    def fill(self, rows: np.ndarray, bound: float):
        """Make rows exact where they could be ``< bound``: evaluate their missing/inexact entries
        as one batch, pruned at ``bound`` per row (group)."""
        rows = np.asarray(rows, int)
        v, _ = self.values()
        rows = rows[v[rows] < bound]
        pairs = [(i, j) for i in rows for j in np.flatnonzero(~self.exact[i])]
        if not pairs:
            return
        ii, jj = np.array(pairs).T
        g = 10.0 ** self.gains[ii]
        res = self.evaluator.settling(g[:, 0], g[:, 1], self.hard[jj], group=ii, race=True,
                                      stop_above=None if not np.isfinite(bound) else bound)
        self.T[ii, jj] = res.ts
        self.exact[ii, jj] = (res.status == SETTLED) | (res.status == CAPPED)


def _log_gains_result(log_g) -> tuple[float, float]:
    g = 10.0 ** np.asarray(log_g, float)
    return float(g[0]), float(g[1])


def tune_fixed(h, evaluator: BatchEvaluator | None = None, *, maxfun: int = 400, bounds=LOG_GAIN_BOUNDS,
               initial_level: int = 3, deadline: float | None = None, f_target: float = -np.inf,
               progress=None) -> TuningResult:
    """Gains minimising the settling time at the initial condition ``h``: batched DIRECT on log gains.

    Every DIRECT iteration is one batch; a gain still above ν after the best settling time so far
    is stopped there (its value is then a lower bound above the incumbent, which is all DIRECT
    needs to rank it).
    """
    evaluator = evaluator or BatchEvaluator()
    t0 = time.perf_counter()
    h = np.asarray(h, float)
    best = [np.inf]
    history = []

    def fun(log_g):
        g = 10.0 ** np.atleast_2d(log_g)
        res = evaluator.settling(g[:, 0], g[:, 1], np.repeat(h[None], len(g), 0), race=True,
                                 stop_above=best[0] if np.isfinite(best[0]) else None)
        exact = res.exact | (res.status == CAPPED)
        if exact.any():
            best[0] = min(best[0], float(res.ts[exact].min()))
        history.append((time.perf_counter() - t0, best[0], f"{len(g)} gains"))
        if progress is not None:
            progress(min(1.0, evaluator.evaluations / maxfun), best[0])
        return res.ts

    lo, hi = np.array(bounds, float).T
    res = direct_batch(fun, lo, hi, maxfun=maxfun, initial_level=initial_level, f_target=f_target,
                       deadline=deadline)
    kp, kd = _log_gains_result(res.x)
    return TuningResult("fixed", kp, kd, res.fun, h, nfev=evaluator.evaluations, wall_time=time.perf_counter() - t0,
                        status=res.status, message=res.message, history=history,
                        stats={"direct_iterations": res.nit, "case_steps": evaluator.case_steps,
                               "batches": evaluator.batches})


def _outer_iterations(search: DirectSearch, table: _GainTable, iterations: int, maxfun: int, time_left,
                      reserve: float):
    """Up to ``iterations`` DIRECT iterations on the gains against the hard set (step (1) of a cycle)."""
    for _ in range(iterations):
        if search.nfev >= maxfun or time_left() <= reserve:
            break
        search.iterate()
        search.f = table.values()[0]


def tune_robust(evaluator: BatchEvaluator | None = None, *, seeds, inner: str = "sdbox-multistart",
                outer_iterations: int = 8, outer_maxfun: int = 400, inner_maxfun: int = 400, new_cases: int = 2,
                tol: float = 0.02, max_cycles: int = 12, bounds=LOG_GAIN_BOUNDS, initial_level: int = 2,
                deadline: float | None = None, inner_reserve: float = 0.0, progress=None) -> TuningResult:
    """Min-max gains ``min_κ max_{h∈H} t_s`` by outer approximation with DIRECT outside.

    Cycle: (1) ``outer_iterations`` batched DIRECT iterations on log gains against the hard set
    ``S`` (first the ``seeds``, rows of ``H``); each gain's hard cases run together and stop as
    soon as one exceeds the incumbent (hard cases first, for free); (2) at the incumbent, the inner
    search (``inner``, warm-started from its worst hard case) looks for a worse ``h``; (3) if it
    finds one more than ``tol`` worse, the ``new_cases`` distinct worst become hard cases, are
    evaluated at the DIRECT points that could still win (the DIRECT tree is kept) and the cycle
    repeats; otherwise the incumbent is certified by the inner search and returned (OPTIMAL;
    FEASIBLE after ``max_cycles``, BUDGET_EXPIRED at ``deadline``). The answer is the gain pair
    with the smallest inner-search worst case among those searched.
    """
    if inner not in INNER_METHODS:
        raise ValueError(f"inner method '{inner}' is not one of {INNER_METHODS}")
    evaluator = evaluator or BatchEvaluator()
    t0 = time.perf_counter()
    table = _GainTable(evaluator, seeds)
    history, certified = [], []

    def outer_fun(log_g):
        rows = table.add_points(np.atleast_2d(log_g))
        table.fill(rows, table.incumbent()[1])
        return table.values()[0][rows]

    def time_left():
        return np.inf if deadline is None else deadline - time.monotonic()

    lo, hi = np.array(bounds, float).T
    search = DirectSearch(outer_fun, lo, hi, initial_level=initial_level)
    status, message = Status.FEASIBLE, ""
    for cycle in range(max_cycles):
        _outer_iterations(search, table, outer_iterations, outer_maxfun, time_left, inner_reserve)
        i_best, f_best = table.incumbent()
        history.append((time.perf_counter() - t0, f_best,
                        f"cycle {cycle}: outer {search.nfev} gains, |S| = {len(table.hard)}"))
        if progress is not None:
            progress(cycle, f_best, certified)
        kp, kd = _log_gains_result(table.gains[i_best])
        wc = worst_case(evaluator, kp, kd, method=inner, starts=table.hard, start_ts=table.T[i_best],
                        maxfun=inner_maxfun, deadline=deadline)
        certified.append((kp, kd, max(wc.ts, f_best), wc.h, f_best))
        history.append((time.perf_counter() - t0, f_best,
                        f"cycle {cycle}: inner worst {wc.ts:.3f} at κ=({kp:.6g}, {kd:.6g})"))
        if wc.ts <= f_best + tol:
            status = Status.OPTIMAL
            message = f"inner search found nothing worse than the hard set (+{tol}) at cycle {cycle}"
            break
        if time_left() <= 0:
            status, message = Status.BUDGET_EXPIRED, f"time budget spent after {cycle + 1} cycles"
            break
        table.add_hard(distinct_worst(wc.X, wc.T, new_cases, f_best + tol))
        table.fill(np.arange(len(table.gains)), max(wc.ts, f_best))
        search.f = table.values()[0]
    if not message:
        message = f"stopped after {len(certified)} cycles (maxcycles)"
    kp, kd, worst, h_worst, _ = min(certified, key=lambda c: c[2])
    return TuningResult("robust", kp, kd, worst, h_worst, nfev=evaluator.evaluations,
                        wall_time=time.perf_counter() - t0, status=status, message=message, history=history,
                        hard_set=table.hard,
                        stats={"inner": inner, "cycles": len(certified), "outer_gains": len(table.gains),
                               "outer_iterations": search.nit, "case_steps": evaluator.case_steps,
                               "batches": evaluator.batches,
                               "certified": [(c[0], c[1], c[2], c[4]) for c in certified]})


def thorough_worst_case(evaluator: BatchEvaluator, kp: float, kd: float, *, samples: int = 2048, grid_levels: int = 3,
                        refine: int = 8, refine_maxfun: int = 400, seed: int = 12345) -> WorstCase:
    """Independent re-check of gains: a ``grid_levels⁷`` grid of H, ``samples`` scrambled-Sobol
    points, then SDBOX refinement from the ``refine`` worst distinct ones. Use the same call (same
    seed) for every gain pair compared."""
    from scipy.stats import qmc

    t0 = time.perf_counter()
    axes = [np.linspace(l, u, grid_levels) for l, u in zip(H_LOWER, H_UPPER)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(H_LOWER))
    sobol = qmc.scale(qmc.Sobol(len(H_LOWER), seed=seed).random(samples), H_LOWER, H_UPPER)
    X = np.vstack([grid, sobol])
    T = evaluator.settling(kp, kd, X).ts
    starts = distinct_worst(X, T, refine, -np.inf, separation=0.15)
    f0 = -np.array([T[np.flatnonzero(np.all(X == s, 1))[0]] for s in starts])
    res = sdbox_batch(lambda h: -evaluator.settling(kp, kd, h).ts, H_LOWER, H_UPPER, starts,
                      maxfun=refine_maxfun, alpha0=0.1, f_starts=f0)
    X, T = np.vstack([X, res.X]), np.concatenate([T, -res.F])
    b = int(np.argmax(T))
    return WorstCase(X[b].copy(), float(T[b]), bool(T[b] >= evaluator.settings.cap_orbits), len(T),
                     "thorough", time.perf_counter() - t0, X, T)
