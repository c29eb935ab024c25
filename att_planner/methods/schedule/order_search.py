"""The order search of a schedule: leg lower bounds, orders enumerated by increasing bound
(best-first with the exact Held–Karp completion cost), multiphase solves of the candidates, and
the exhaustive check (see :mod:`att_planner.methods.schedule`)."""
from __future__ import annotations

import heapq
import itertools
import time
from dataclasses import dataclass, field

import numpy as np

from att_planner.methods.schedule.transcription import (
    SUBSTEPS,
    MultiphaseTranscription,
    ScheduleSolution,
    cached_transcription,
)
from att_planner.problem import ManeuverProblem
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot

MAX_ORDERS_EXAMINED = 200_000     # orders the search may look at (windows can rule out many in a row)


def leg_bound_matrix(sc: dyn.Spacecraft, q_start, targets: list[np.ndarray], q_end, *, intervals: int = 12,
                     substeps: int = SUBSTEPS, rate_max: float = np.inf, deadline: float | None = None) -> np.ndarray:
    """Minimum leg times with the boundary rates relaxed, as a (n+2)×(n+2) matrix.

    Node 0 is the start (at rest), 1..n the targets, n+1 the end (at rest). Entry (i, j) is the
    minimum time from attitude i to j when only what the schedule imposes at i and j is kept
    (rest at the start/end, ω_z = 0 at a target; other rates and wheel speeds free). Any schedule
    restricted to one leg is feasible for that leg problem, so the sum of the entries along an
    order is a lower bound on that order's schedule time (on the same grid, if the leg NLPs reach
    their global minima). Free–free legs are symmetric under time reversal, so each pair is
    solved once. Entries not computed (deadline, solver failure) are 0 (still a valid bound).
    The leg problems leave out the zones: a relaxation, so the bound stays a bound with zones
    (moving or not: a leg's start time in the tour is not known here).
    """
    n = len(targets)
    nodes = [q_start, *targets, q_end]
    same_ends = rot.angle_between(q_start, q_end) < 1e-9
    legs = [(0, j) for j in range(1, n + 1)] + [(i, j) for i in range(1, n + 1) for j in range(i + 1, n + 1)]
    if not same_ends:
        legs += [(n + 1, j) for j in range(1, n + 1)]   # solved reversed: from the end at rest
    C = np.zeros((n + 2, n + 2))
    tr = cached_transcription(sc, 0, intervals, substeps, rate_max)
    for i, j in legs:
        if deadline is not None and time.monotonic() > deadline:
            break
        sol = tr.solve(nodes[i], [], nodes[j], start_at_rest=i in (0, n + 1), end_at_rest=False)
        value = sol.tau_f * tr.scale.t_sat if sol.converged else 0.0
        if i == n + 1:
            C[j, i] = value
        else:
            C[i, j] = value
            if i > 0:
                C[j, i] = value
        if i == 0 and same_ends:
            C[j, n + 1] = value
    return C


def _completion_costs(C: np.ndarray) -> np.ndarray:
    """Held–Karp over the targets: ``G[S, j]`` = cheapest way from target j through the targets of
    bitmask S (j not in S) to the end node, with costs ``C`` (nodes as in :func:`leg_bound_matrix`).
    Exact dynamic programming, vectorised over subsets of equal size."""
    n = C.shape[0] - 2
    G = np.full((1 << n, n), np.inf)
    G[0, :] = C[1:n + 1, n + 1]
    masks = np.arange(1 << n)
    popcount = sum((masks >> b) & 1 for b in range(n))
    bits = 1 << np.arange(n)
    cost = C[1:n + 1, 1:n + 1]
    for size in range(1, n):
        for S in np.array_split(masks[popcount == size], max(1, (popcount == size).sum() // 4096)):
            inside = (S[:, None] & bits[None, :]) != 0                       # k ∈ S
            # M[s, k] = G[S \ {k}, k] for k ∈ S, +inf otherwise; G[S, j] = min_k cost[j, k] + M[s, k]
            M = np.where(inside, G[S[:, None] ^ bits[None, :], np.arange(n)[None, :]], np.inf)
            Gs = np.full(M.shape, np.inf)
            for k in range(n):
                np.minimum(Gs, M[:, k:k + 1] + cost[None, :, k], out=Gs)
            G[S] = np.where(inside, np.inf, Gs)                              # j ∉ S only
    return G


def orders_by_lower_bound(C: np.ndarray):
    """Yield ``(bound, order)`` for every order of the targets, in increasing order of the leg
    bound sum (best-first search with the exact Held–Karp completion cost as heuristic, so each
    complete order is reached by a direct descent)."""
    n = C.shape[0] - 2
    if n == 0:
        yield float(C[0, 1]), []
        return
    G = _completion_costs(C)
    full = (1 << n) - 1
    heap = [(float(C[0, j + 1] + G[full ^ (1 << j), j]), float(C[0, j + 1]), (j,)) for j in range(n)]
    heapq.heapify(heap)
    while heap:
        f, g, path = heapq.heappop(heap)
        if len(path) == n:
            yield f, list(path)
            continue
        visited = 0
        for j in path:
            visited |= 1 << j
        last = path[-1]
        for j in range(n):
            if not visited >> j & 1:
                rest = full ^ visited ^ (1 << j)
                g2 = g + C[last + 1, j + 1]
                f2 = g2 + (C[j + 1, n + 1] if rest == 0 else G[rest, j])
                heapq.heappush(heap, (float(f2), float(g2), path + (j,)))


VISIBILITY_STEP = 10.0      # s between the samples of a target's visibility among moving zones


def visibility(zones, q: np.ndarray, window: tuple, margin: float = 0.0,
               step: float = VISIBILITY_STEP) -> list[tuple]:
    """The intervals ``(opens, closes)`` (s) within ``window`` in which attitude ``q`` keeps every
    zone of ``zones`` (a FittedZones or None) by ``margin`` rad: among moving zones, runs of clear
    samples ``step`` s apart (within the zones' window, where their fit holds); [] if never."""
    opens, closes = float(window[0]), float(window[1])
    if zones is not None and zones.moving:
        closes = min(closes, zones.window)
    if closes < opens:
        return []
    if zones is None:
        return [(opens, closes)]
    if not zones.moving:
        return [(opens, closes)] if zones.margins(0.0, q).min() >= margin else []
    t = visibility_grid(opens, closes, step)
    return spans(t, zones.margins(t, q).min(axis=1) >= margin)


def visibility_grid(opens: float, closes: float, step: float = VISIBILITY_STEP) -> np.ndarray:
    """Sample times from ``opens`` to ``closes`` (both included), at most ``step`` s apart."""
    return np.linspace(opens, closes, max(2, int(np.ceil((closes - opens) / step)) + 1))


def spans(t: np.ndarray, clear: np.ndarray) -> list[tuple]:
    """The runs ``(first, last)`` of samples ``t`` where ``clear`` holds."""
    edges = np.flatnonzero(np.diff(np.concatenate([[False], clear, [False]]).astype(int)))
    return [(float(t[a]), float(t[b - 1])) for a, b in zip(edges[::2], edges[1::2])]


def earliest_observation(start: float, dwell: float, visible) -> float:
    """The earliest time ≥ ``start`` from which a target can be held for ``dwell`` s inside one of
    its ``visible`` intervals (sorted ``(opens, closes)``); inf if none."""
    for opens, closes in visible:
        at = max(start, opens)
        if at + dwell <= closes:
            return at
    return np.inf


def observed_prefix(C: np.ndarray, order: list[int], dwell: np.ndarray, visible: list) -> tuple[np.ndarray, float]:
    """The earliest arrivals (s) at the targets of ``order`` that can be observed one after the
    other — each leg at least its bound ``C`` (nodes as in :func:`leg_bound_matrix`), each target
    held ``dwell[j]`` s within one of its ``visible[j]`` intervals, waiting where the next one has
    not opened — up to the first that cannot; and the end of the last observation (s)."""
    t, node, arrivals = 0.0, 0, []
    for j in order:
        at = earliest_observation(t + C[node, j + 1], dwell[j], visible[j])
        if not np.isfinite(at):
            break
        arrivals.append(at)
        t, node = at + dwell[j], j + 1
    return np.array(arrivals), t


def tour_bound(C: np.ndarray, order: list[int], dwell: np.ndarray, visible: list) -> tuple[float, np.ndarray]:
    """Lower bound (s) on a tour of target indices ``order`` with its observations, and the
    earliest arrivals it implies (:func:`observed_prefix`, then the leg to the end node).
    ``(inf, None)`` when a target cannot be observed in time: no schedule of that order exists."""
    arrivals, t = observed_prefix(C, order, dwell, visible)
    if len(arrivals) < len(order):
        return np.inf, None
    last = order[-1] + 1 if len(order) else 0
    return t + C[last, C.shape[0] - 1], arrivals


@dataclass
class Solved:
    order: tuple
    tf: float                 # s: the whole tour, observations included
    sol: ScheduleSolution
    transcription: MultiphaseTranscription


@dataclass
class OrderSolver:
    """Solves the multiphase NLP of one order of a schedule problem (normalised attitudes)."""

    sc: dyn.Spacecraft
    q_start: np.ndarray
    q_end: np.ndarray
    targets: dict
    substeps: int = SUBSTEPS
    rate_max: float = np.inf
    deadline: float | None = None
    zones: object = None              # att_planner.zones.FittedZones or None
    zone_margin: float = 0.0          # rad, δ of every zone constraint
    dwell: dict = field(default_factory=dict)       # name -> s held at the target (absent: a passage)
    visible: dict = field(default_factory=dict)     # name -> sorted (opens, closes) s it may be observed in

    @classmethod
    def of(cls, problem: ManeuverProblem, substeps: int = SUBSTEPS, zone_margin: float = 0.0,
           zone_window: float | None = None) -> OrderSolver:
        """The solver of ``problem``, its zones fitted over ``zone_window`` s (default: the problem's);
        each target's visibility: its window (``problem.target_windows``) less the times a moving
        zone covers it (:func:`visibility`)."""
        q_start = rot.normalize(np.asarray(problem.q_initial, float))
        q_end = rot.normalize(np.asarray(problem.q_final, float))
        quats = {k: rot.normalize(np.asarray(v, float)) for k, v in problem.targets.items()}
        zones = problem.zone_sky(zone_window)
        zones = zones if zones.zones else None
        visible = {k: visibility(zones, q, problem.target_windows.get(k, (0.0, np.inf)), zone_margin)
                   for k, q in quats.items()}
        return cls(problem.spacecraft, q_start, q_end, quats, substeps, problem.rate_max, problem.deadline,
                   zones, zone_margin, dict(problem.target_dwell), visible)

    @property
    def moving(self) -> bool:
        """Whether a zone moves (an order and its reverse then differ)."""
        return self.zones is not None and self.zones.moving

    def expired(self) -> bool:
        return self.deadline is not None and time.monotonic() > self.deadline

    def dwells(self, order) -> np.ndarray:
        return np.array([self.dwell.get(k, 0.0) for k in order])

    def solve(self, order, intervals: int, guess: Solved | None = None, expand: bool | None = None,
              arrivals=None) -> Solved:
        """The multiphase NLP of ``order`` (observations held, windows kept); ``arrivals`` (s) place
        the initial guess's targets (:func:`tour_bound`'s waits)."""
        tr = cached_transcription(self.sc, len(order), intervals, self.substeps, self.rate_max, expand,
                                  self.zones, self.zone_margin)
        wall = None if self.deadline is None else self.deadline - time.monotonic()
        start_guess = tr.resample(guess.sol) if guess is not None else None
        dwell = self.dwells(order)
        windows = [(self.visible[k][0][0], self.visible[k][-1][1]) if self.visible.get(k) else (0.0, np.inf)
                   for k in order]
        sol = tr.solve(self.q_start, [self.targets[k] for k in order], self.q_end, guess=start_guess,
                       max_wall_time=wall, dwell=dwell, windows=windows, arrivals=arrivals)
        tf = sol.tau_f * tr.scale.t_sat + dwell.sum() if sol.converged else np.inf
        return Solved(tuple(order), tf, sol, tr)

    def leg_bounds(self, names: list, intervals: int) -> np.ndarray:
        return leg_bound_matrix(self.sc, self.q_start, [self.targets[k] for k in names], self.q_end,
                                intervals=intervals, substeps=self.substeps, rate_max=self.rate_max,
                                deadline=self.deadline)


def search_orders(solver: OrderSolver, names: list, intervals: int, candidates: int, prove: bool,
                  max_order_solves: int, second_start_margin: float, stats: dict) -> list[Solved]:
    """The orders solved on ``intervals`` per phase, in increasing leg bound, until the bound
    reaches the incumbent or ``candidates`` (``prove``: ``max_order_solves``) are solved; the
    search figures go into ``stats`` (see :func:`~att_planner.methods.schedule.planner.plan_schedule`)."""
    t0 = time.perf_counter()
    C = solver.leg_bounds(names, intervals)
    stats["leg_bound_seconds"] = time.perf_counter() - t0
    stats["leg_bounds"] = C
    solved: list[Solved] = []
    incumbent = np.inf
    unsolved_bound = np.inf   # smallest bound among the orders not solved
    dwell = solver.dwells(names)
    visible = [solver.visible.get(k, [(0.0, np.inf)]) for k in names]
    timed = any(v != [(0.0, np.inf)] for v in visible)
    # time reversal maps a tour onto its reverse (observations held alike) among zones that do not
    # move and without windows, not otherwise
    reversible = rot.angle_between(solver.q_start, solver.q_end) < 1e-9 and not solver.moving and not timed
    infeasible = examined = 0
    for bound, idx in orders_by_lower_bound(C):
        bound += dwell.sum()
        if bound >= incumbent or len(solved) >= (max_order_solves if prove else candidates) or solver.expired() \
                or examined >= MAX_ORDERS_EXAMINED:
            unsolved_bound = min(unsolved_bound, bound)
            break
        examined += 1
        windowed, arrivals = tour_bound(C, idx, dwell, visible)
        if not np.isfinite(windowed):
            infeasible += 1        # a target could not be observed in time: no schedule of this order
            continue
        if windowed >= incumbent:
            unsolved_bound = min(unsolved_bound, windowed)
            continue
        if reversible and tuple(names[i] for i in reversed(idx)) in {s.order for s in solved}:
            continue  # time reversal: same schedule duration as an order already solved
        s = solver.solve([names[i] for i in idx], intervals, expand=prove or None,
                         arrivals=arrivals if timed else None)
        solved.append(s)
        incumbent = min(incumbent, s.tf)
    if reversible and solved:
        # second start: an order's reverse has the same optimum but IPOPT may land in another
        # local minimum from the reversed initial guess. For the winner, and with ``prove``
        # for every order within ``second_start_margin`` of it (near-ties), keep the better.
        best_tf = min(s.tf for s in solved)
        margin = second_start_margin if prove else 0.0
        seen = {s.order for s in solved}
        for s in [s for s in solved if s.tf <= best_tf * (1 + margin)]:
            if s.order[::-1] not in seen and not solver.expired():
                seen.add(s.order[::-1])
                solved.append(solver.solve(s.order[::-1], intervals, expand=prove or None))
    # every order not solved costs at least unsolved_bound on the search grid
    incumbent = min(s.tf for s in solved) if solved else np.inf
    stats.update(orders_solved=len(solved), orders_examined=examined, orders_infeasible=infeasible,
                 lower_bound=min(unsolved_bound, incumbent),
                 unsolved_orders_bound=unsolved_bound,
                 order_proven=bool(unsolved_bound >= incumbent), search_seconds=time.perf_counter() - t0,
                 candidates=[{"order": list(s.order), "tf": s.tf} for s in solved])
    return solved


def exhaustive_order_search(problem: ManeuverProblem, *, intervals: int = 8, substeps: int = SUBSTEPS,
                            progress=None, zone_window: float | None = None) -> list[dict]:
    """Solve the multiphase problem of every order (all n! of them, reversals included, as an
    independent check of the time-reversal symmetry — which moving zones and windows break — and of
    the NLP's local minima), observations and windows included, and return
    ``[{"order", "tf", "bound", "converged"}]`` sorted by ``tf``; ``bound`` is :func:`tour_bound`
    on the same grid's leg bounds (so ``bound ≤ tf`` must hold for every order; inf: no schedule)."""
    solver = OrderSolver.of(problem, substeps, zone_window=zone_window)
    names = list(problem.targets)
    C = solver.leg_bounds(names, intervals)
    dwell, visible = solver.dwells(names), [solver.visible[k] for k in names]
    rows = []
    for perm in itertools.permutations(range(len(names))):
        bound, arrivals = tour_bound(C, list(perm), dwell, visible)
        s = solver.solve([names[i] for i in perm], intervals, expand=True,
                         arrivals=arrivals if arrivals is not None else None)
        rows.append({"order": [names[i] for i in perm], "tf": float(s.tf), "bound": float(bound),
                     "converged": s.sol.converged})
        if progress is not None:
            progress(len(rows), rows[-1])
    return sorted(rows, key=lambda r: r["tf"])
