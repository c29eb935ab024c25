"""Derivative-free searches on a box that evaluate whole batches of points: DIRECT (Jones,
Perttunen & Stuckman 1993) and SDBOX-style coordinate search (Lucidi & Sciandrone 2002)."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import Status


@dataclass
class SearchResult:
    """Result of a search (minimisation of ``fun``), in the style of ``scipy.optimize``.

    ``status``: OPTIMAL (converged), FEASIBLE (evaluation or iteration limit) or BUDGET_EXPIRED
    (deadline); ``message`` says which limit. ``wall_time`` in s.
    """

    x: np.ndarray
    fun: float
    nfev: int
    nit: int
    status: Status
    message: str
    wall_time: float
    X: np.ndarray = field(repr=False, default=None)   # every point evaluated
    F: np.ndarray = field(repr=False, default=None)   # their values


class DirectSearch:
    """DIRECT on a box (Jones, Perttunen & Stuckman 1993), one batch per iteration.

    Each iteration selects the potentially optimal hyper-rectangles (lower-right convex hull of
    (half-diagonal, value) with the ε-test ``f_j − K d_j ≤ f_min − ε |f_min|``), samples
    ``c ± δ e_i`` along their longest sides — all of them evaluated together by ``fun_batch`` —
    and trisects them in the order of ``min(f(c+δe_i), f(c−δe_i))``. The state (centres, side
    levels, values) is kept, so a caller may change the objective and update ``f`` (the min-max
    does when its set of hard initial conditions grows) and go on iterating.
    ``scipy.optimize.direct`` implements the same method but asks for one point at a time, which
    would waste the batch simulator (:func:`direct_scipy` wraps it for comparison).
    """

    def __init__(self, fun_batch, lower, upper, eps: float = 1e-4, initial_level: int = 0):
        self.start = time.perf_counter()
        self.fun_batch = fun_batch
        self.lower, self.upper = np.asarray(lower, float), np.asarray(upper, float)
        self.eps = eps
        self.dim = self.lower.size
        # initial_level L > 0 starts from the uniform partition into 3^L cells per side (the
        # rectangles DIRECT would reach by dividing everything L times), evaluated as one batch
        ticks = (np.arange(3**initial_level) + 0.5) / 3**initial_level
        self.centers = np.stack(np.meshgrid(*[ticks] * self.dim, indexing="ij"), -1).reshape(-1, self.dim)
        self.levels = np.full(self.centers.shape, int(initial_level))
        self.f = np.asarray(self.fun_batch(self.to_box(self.centers)), float).reshape(len(self.centers))
        self.nfev, self.nit = len(self.centers), 0

    def to_box(self, z: np.ndarray) -> np.ndarray:
        return self.lower + z * (self.upper - self.lower)

    @property
    def best(self) -> int:
        return int(np.argmin(self.f))

    def potentially_optimal(self) -> np.ndarray:
        sizes = 0.5 * np.linalg.norm(3.0 ** (-self.levels.astype(float)), axis=1)
        sizes = np.round(sizes, 12)
        f_min = self.f.min()
        cand = []
        for d in np.unique(sizes):
            idx = np.flatnonzero(sizes == d)
            cand.append(idx[np.argmin(self.f[idx])])
        cand = np.array(cand)                       # ascending size
        d, fv = sizes[cand], self.f[cand]
        start = int(np.flatnonzero(fv == fv.min())[-1])
        hull = [start]
        for j in range(start + 1, len(cand)):
            while len(hull) >= 2:
                a, b = hull[-2], hull[-1]
                # drop b if it lies on or above the segment a→j
                if (fv[b] - fv[a]) * (d[j] - d[a]) >= (fv[j] - fv[a]) * (d[b] - d[a]):
                    hull.pop()
                else:
                    break
            if len(hull) == 1 and fv[j] <= fv[hull[0]]:
                hull[0] = j
                continue
            hull.append(j)
        chosen = []
        for pos, j in enumerate(hull):
            if pos + 1 < len(hull):
                k = hull[pos + 1]
                slope = (fv[k] - fv[j]) / (d[k] - d[j])
                if fv[j] - slope * d[j] > f_min - self.eps * abs(f_min):
                    continue
            chosen.append(cand[j])
        return np.array(chosen, int)

    def iterate(self) -> int:
        """One DIRECT iteration; returns the number of new evaluations."""
        chosen = self.potentially_optimal()
        plans, points = [], []
        for r in chosen:
            lv = self.levels[r]
            dims = np.flatnonzero(lv == lv.min())
            delta = 3.0 ** (-(lv.min() + 1))
            for i in dims:
                for sgn in (1.0, -1.0):
                    p = self.centers[r].copy()
                    p[i] += sgn * delta
                    points.append(p)
            plans.append((r, dims))
        points = np.array(points)
        values = np.asarray(self.fun_batch(self.to_box(points)), float)
        new_c, new_l, new_f = [], [], []
        pos = 0
        for r, dims in plans:
            vals = values[pos:pos + 2 * len(dims)].reshape(-1, 2)
            pts = points[pos:pos + 2 * len(dims)].reshape(-1, 2, self.dim)
            pos += 2 * len(dims)
            order = np.argsort(vals.min(1), kind="stable")
            lv = self.levels[r].copy()
            for o in order:
                lv[dims[o]] += 1
                for s in range(2):
                    new_c.append(pts[o, s])
                    new_l.append(lv.copy())
                    new_f.append(vals[o, s])
            self.levels[r] = lv
        self.centers = np.vstack([self.centers, new_c])
        self.levels = np.vstack([self.levels, new_l])
        self.f = np.concatenate([self.f, new_f])
        self.nfev += len(points)
        self.nit += 1
        return len(points)

    def result(self, status: Status, message: str) -> SearchResult:
        b = self.best
        return SearchResult(self.to_box(self.centers[b]), float(self.f[b]), self.nfev, self.nit, status, message,
                            time.perf_counter() - self.start, self.to_box(self.centers), self.f.copy())


def direct_batch(fun_batch, lower, upper, *, maxfun: int = 2000, maxiter: int = 1000, eps: float = 1e-4,
                 initial_level: int = 0, f_target: float = -np.inf, deadline: float | None = None,
                 callback=None) -> SearchResult:
    """Minimise ``fun_batch`` (rows of points → values) on the box with batched DIRECT.

    OPTIMAL when ``f_target`` is reached, FEASIBLE at ``maxfun``/``maxiter``, BUDGET_EXPIRED at
    ``deadline`` (``time.monotonic()``).
    """
    search = DirectSearch(fun_batch, lower, upper, eps, initial_level)
    status, reason = Status.FEASIBLE, "maxiter"
    while search.nit < maxiter:
        if search.nfev >= maxfun:
            reason = "maxfun"
            break
        if deadline is not None and time.monotonic() >= deadline:
            status, reason = Status.BUDGET_EXPIRED, "deadline"
            break
        if search.f.min() <= f_target:
            status, reason = Status.OPTIMAL, "converged"
            break
        search.iterate()
        if callback is not None:
            callback(search)
    return search.result(status, f"{reason} after {search.nfev} evaluations, {search.nit} iterations")


def direct_scipy(fun, lower, upper, *, maxfun: int = 2000, maxiter: int = 1000, eps: float = 1e-4,
                 locally_biased: bool = False) -> SearchResult:
    """``scipy.optimize.direct`` on a scalar objective (sequential: one point per call)."""
    from scipy.optimize import Bounds, direct

    start = time.perf_counter()
    X, F = [], []

    def wrapped(x):
        X.append(np.array(x))
        F.append(float(fun(x)))
        return F[-1]

    res = direct(wrapped, Bounds(lower, upper), eps=eps, maxfun=maxfun, maxiter=maxiter,
                 locally_biased=locally_biased)
    return SearchResult(np.asarray(res.x), float(res.fun), int(res.nfev), int(res.nit),
                        Status.OPTIMAL if res.success else Status.FEASIBLE, str(res.message),
                        time.perf_counter() - start, np.array(X), np.array(F))


# ---------------------------------------------------------------------------------------------
# SDBOX
# ---------------------------------------------------------------------------------------------


@dataclass
class _Trials:
    """Points of one SDBOX batch (unit cube): the start each belongs to, the coordinate it moves
    and its step (signed for polls, the absolute length for line-search expansions)."""

    owners: np.ndarray
    coords: np.ndarray
    steps: np.ndarray
    points: np.ndarray

    @classmethod
    def of(cls, rows: list) -> _Trials | None:
        if not rows:
            return None
        owners, coords, steps, points = zip(*rows)
        return cls(np.array(owners), np.array(coords), np.array(steps), np.array(points))


def _poll(z: np.ndarray, alpha: np.ndarray, active: np.ndarray) -> _Trials | None:
    """``z_s ± α_si e_i`` of every active start ``s`` and coordinate ``i``, steps cut to the cube."""
    rows = []
    for s in np.flatnonzero(active):
        for i in range(z.shape[1]):
            for sgn in (1.0, -1.0):
                step = min(alpha[s, i], (1.0 - z[s, i]) if sgn > 0 else z[s, i])
                if step <= 0.0:
                    continue
                y = z[s].copy()
                y[i] += sgn * step
                rows.append((s, i, sgn * step, y))
    return _Trials.of(rows)


def _accept_polls(z, fz, alpha, active, poll: _Trials, vals, gamma: float, theta: float) -> list:
    """Move each active start to its best poll with sufficient decrease ``f ≤ f(z) − γ α²``;
    shrink ``α_i ← θ α_i`` where both signs failed. Returns the moves ``(start, coordinate, step)``."""
    moves = []
    for s in np.flatnonzero(active):
        mine = poll.owners == s
        gain = fz[s] - gamma * poll.steps[mine] ** 2 - vals[mine]
        ok_coords = set(poll.coords[mine][gain >= 0.0])
        for i in range(z.shape[1]):
            if i not in ok_coords:
                alpha[s, i] *= theta
        if ok_coords:
            b = np.flatnonzero(mine)[np.argmax(gain)]
            z[s], fz[s] = poll.points[b], vals[b]
            moves.append((s, poll.coords[b], poll.steps[b]))
    return moves


def _expansions(z: np.ndarray, moves: list, expansions: int) -> _Trials | None:
    """Line-search points ``z_s + (2^k − 1) step e_i``, ``k = 1..expansions``, along each move (cut to the cube)."""
    rows = []
    for s, i, step in moves:
        for k in range(1, expansions + 1):
            y = z[s].copy()
            y[i] = np.clip(y[i] + step * (2.0**k - 1.0), 0.0, 1.0)
            if y[i] == z[s, i]:
                break
            rows.append((s, i, abs(step) * 2.0**k, y))
            if y[i] in (0.0, 1.0):
                break
    return _Trials.of(rows)


def _accept_expansions(z, fz, alpha, moves: list, line: _Trials, vals, gamma: float):
    """Keep each move's best expansion if it decreases enough (``α_i`` ← its length), else ``α_i ← |step|``."""
    for s, i, step in moves:
        mine = np.flatnonzero(line.owners == s)
        if mine.size == 0:
            continue
        b = mine[np.argmin(vals[mine])]
        if vals[b] <= fz[s] - gamma * line.steps[b] ** 2:
            z[s], fz[s] = line.points[b], vals[b]
            alpha[s, i] = line.steps[b]
        else:
            alpha[s, i] = abs(step)


def sdbox_batch(fun_batch, lower, upper, starts, *, maxfun: int = 2000, alpha0: float = 0.25,
                alpha_tol: float = 1e-3, gamma: float = 1e-6, theta: float = 0.5, expansions: int = 3,
                deadline: float | None = None, f_starts=None) -> SearchResult:
    """SDBOX-style coordinate search in a box, several starts in lockstep (Lucidi & Sciandrone 2002).

    Works on the unit cube of the box. Per start and round: poll ``x ± α_i e_i`` for every
    coordinate (step cut to the box), a trial succeeds on sufficient decrease
    ``f(y) ≤ f(x) − γ α²``; the best success moves the start and is followed by a derivative-free
    line search along it (steps ``2α, 4α, …`` evaluated together, the best kept, α updated);
    coordinates where both signs fail shrink ``α_i ← θ α_i``. A start stops when every
    ``α_i < alpha_tol`` (OPTIMAL once all have); FEASIBLE at ``maxfun``, BUDGET_EXPIRED at
    ``deadline``. All pending points of all starts form one batch per round.
    """
    start = time.perf_counter()
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    span = upper - lower
    z = np.clip((np.atleast_2d(np.asarray(starts, float)) - lower) / span, 0.0, 1.0)
    n_starts, dim = z.shape
    alpha = np.full((n_starts, dim), float(alpha0))
    all_x, all_f = [], []

    def evaluate(zs):
        vals = np.asarray(fun_batch(lower + zs * span), float)
        all_x.append(lower + zs * span)
        all_f.append(vals)
        return vals

    fz = evaluate(z) if f_starts is None else np.asarray(f_starts, float).copy()
    nfev, nit = (n_starts if f_starts is None else 0), 0
    status, reason = Status.OPTIMAL, "converged"
    active = np.ones(n_starts, bool)
    while True:
        active &= alpha.max(1) >= alpha_tol
        if not active.any():
            break
        if nfev >= maxfun:
            status, reason = Status.FEASIBLE, "maxfun"
            break
        if deadline is not None and time.monotonic() >= deadline:
            status, reason = Status.BUDGET_EXPIRED, "deadline"
            break
        poll = _poll(z, alpha, active)
        if poll is None:
            break
        vals = evaluate(poll.points)
        nfev += len(poll.points)
        nit += 1
        moves = _accept_polls(z, fz, alpha, active, poll, vals, gamma, theta)
        line = _expansions(z, moves, expansions) if moves else None
        if line is None:
            continue
        vals = evaluate(line.points)
        nfev += len(line.points)
        _accept_expansions(z, fz, alpha, moves, line, vals, gamma)
    b = int(np.argmin(fz))
    X = np.vstack(all_x) if all_x else np.empty((0, dim))
    F = np.concatenate(all_f) if all_f else np.empty(0)
    return SearchResult(lower + z[b] * span, float(fz[b]), nfev, nit, status,
                        f"{reason}: {nfev} evaluations, {nit} poll rounds, {n_starts} start(s)",
                        time.perf_counter() - start, X, F)
