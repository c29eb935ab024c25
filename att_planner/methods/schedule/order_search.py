"""The order search of a schedule: leg lower bounds, orders enumerated by increasing bound
(best-first with the exact Held–Karp completion cost), multiphase solves of the candidates, and
the exhaustive check (see :mod:`att_planner.methods.schedule`)."""
from __future__ import annotations

import heapq
import itertools
import time
from dataclasses import dataclass

import numpy as np

from att_planner.methods.schedule.transcription import (
    SUBSTEPS,
    MultiphaseTranscription,
    ScheduleSolution,
    cached_transcription,
)
from att_planner.problem import ManeuverProblem
from att_sim import dynamics as dyn
from att_sim import rotations as rot


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


@dataclass
class Solved:
    order: tuple
    tf: float
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
    zones: object = None              # att_planner.zones.ZoneSky or None
    zone_margin: float = 0.0          # rad, δ of every zone constraint

    @classmethod
    def of(cls, problem: ManeuverProblem, substeps: int = SUBSTEPS, zone_margin: float = 0.0,
           zone_window: float | None = None) -> OrderSolver:
        """The solver of ``problem``, its zones fitted over ``zone_window`` s (default: the problem's)."""
        q_start = rot.normalize(np.asarray(problem.q_initial, float))
        q_end = rot.normalize(np.asarray(problem.q_final, float))
        quats = {k: rot.normalize(np.asarray(v, float)) for k, v in problem.targets.items()}
        zones = problem.zone_sky(zone_window)
        return cls(problem.spacecraft, q_start, q_end, quats, substeps, problem.rate_max, problem.deadline,
                   zones if zones.zones else None, zone_margin)

    @property
    def moving(self) -> bool:
        """Whether a zone moves (an order and its reverse then differ)."""
        return self.zones is not None and self.zones.moving

    def expired(self) -> bool:
        return self.deadline is not None and time.monotonic() > self.deadline

    def solve(self, order, intervals: int, guess: Solved | None = None, expand: bool | None = None) -> Solved:
        tr = cached_transcription(self.sc, len(order), intervals, self.substeps, self.rate_max, expand,
                                  self.zones, self.zone_margin)
        wall = None if self.deadline is None else self.deadline - time.monotonic()
        start_guess = tr.resample(guess.sol) if guess is not None else None
        sol = tr.solve(self.q_start, [self.targets[k] for k in order], self.q_end, guess=start_guess,
                       max_wall_time=wall)
        tf = sol.tau_f * tr.scale.t_sat if sol.converged else np.inf
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
    unsolved_bound = np.inf   # smallest leg bound among the orders not solved
    # time reversal maps a tour onto its reverse among zones that do not move, not among moving ones
    reversible = rot.angle_between(solver.q_start, solver.q_end) < 1e-9 and not solver.moving
    for bound, idx in orders_by_lower_bound(C):
        if bound >= incumbent or len(solved) >= (max_order_solves if prove else candidates) or solver.expired():
            unsolved_bound = bound
            break
        if reversible and tuple(names[i] for i in reversed(idx)) in {s.order for s in solved}:
            continue  # time reversal: same schedule duration as an order already solved
        s = solver.solve([names[i] for i in idx], intervals, expand=prove or None)
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
    stats.update(orders_solved=len(solved), lower_bound=min(unsolved_bound, incumbent),
                 unsolved_orders_bound=unsolved_bound,
                 order_proven=bool(unsolved_bound >= incumbent), search_seconds=time.perf_counter() - t0,
                 candidates=[{"order": list(s.order), "tf": s.tf} for s in solved])
    return solved


def exhaustive_order_search(problem: ManeuverProblem, *, intervals: int = 8, substeps: int = SUBSTEPS,
                            progress=None) -> list[dict]:
    """Solve the multiphase problem of every order (all n! of them, reversals included, as an
    independent check of the time-reversal symmetry — which moving zones break — and of the NLP's
    local minima) and return
    ``[{"order", "tf", "bound", "converged"}]`` sorted by ``tf``; ``bound`` is the leg lower bound
    of :func:`leg_bound_matrix` on the same grid (so ``bound ≤ tf`` must hold for every order)."""
    solver = OrderSolver.of(problem, substeps)
    names = list(problem.targets)
    C = solver.leg_bounds(names, intervals)
    index = {k: i + 1 for i, k in enumerate(names)}
    rows = []
    for perm in itertools.permutations(names):
        s = solver.solve(perm, intervals, expand=True)
        chain = [0] + [index[k] for k in perm] + [len(names) + 1]
        bound = float(sum(C[a, b] for a, b in zip(chain[:-1], chain[1:])))
        rows.append({"order": list(perm), "tf": float(s.tf), "bound": bound, "converged": s.sol.converged})
        if progress is not None:
            progress(len(rows), rows[-1])
    return sorted(rows, key=lambda r: r["tf"])
