"""The collocation mesh and its refinement: a uniform mesh, the path constraints checked between the
collocation points on the Hermite cubic interpolant (:func:`path_violations`), the intervals where a
bang-bang control switches (:func:`switch_intervals`), and :func:`refine_mesh` splitting the
intervals they name (the mesh refinement of Betts, *Practical Methods for Optimal Control*, 2nd ed.,
whose Hermite–Simpson transcription :mod:`.collocation` implements)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from att_planner.methods.time_optimal.collocation import PhaseSolution


def uniform_mesh(intervals: int) -> np.ndarray:
    """Mesh fractions ``τ_k = k/N`` for ``N`` equal intervals."""
    if intervals < 1:
        raise ValueError("intervals must be a positive integer")
    return np.linspace(0.0, 1.0, intervals + 1)


def refine_mesh(mesh: np.ndarray, intervals, max_intervals: int | None = None, parts: int = 2) -> np.ndarray:
    """Split the listed intervals of ``mesh`` into ``parts`` equal ones (bisect them by default), the
    first listed first, up to ``max_intervals`` intervals in all."""
    mesh = np.asarray(mesh, float)
    chosen = sorted({int(k) for k in intervals})
    if max_intervals is not None:
        chosen = chosen[: max(0, max_intervals - (len(mesh) - 1)) // (parts - 1)]
    inner = np.arange(1, parts) / parts
    cuts = [mesh[k] + (mesh[k + 1] - mesh[k]) * inner for k in chosen]
    return np.unique(np.concatenate([mesh, *cuts]))


def path_violations(solution: PhaseSolution, samples_per_interval: int = 8, tol: float = 0.0,
                    t_start: float = 0.0):
    """Check the path constraints between collocation points on the Hermite interpolant
    (a time-dependent one at ``t_start + duration τ``).

    Returns ``(intervals, worst)``: the indices of intervals where some ``g`` leaves its bounds by
    more than ``tol`` and the largest excess found (≤ 0 when everything holds).
    """
    ph = solution.phase
    if ph.path is None:
        return np.array([], int), -np.inf
    s = (np.arange(1, samples_per_interval + 1) / (samples_per_interval + 1))
    tau = (ph.mesh[:-1, None] + np.diff(ph.mesh)[:, None] * s[None, :]).ravel()
    x = solution.state_at(tau)
    u = solution.control_at(tau)
    gval = np.array(ph.path(*ph.path_args(x.T, u.T, (t_start + solution.duration * tau)[None, :], tau))).T
    lb, ub = ph.path_bounds
    excess = np.maximum(lb - gval, gval - ub).max(axis=1).reshape(ph.intervals, samples_per_interval).max(axis=1)
    return np.flatnonzero(excess > tol), float(excess.max())


def switch_intervals(solution: PhaseSolution, rel_tol: float = 0.02, limit: int | None = None) -> np.ndarray:
    """Intervals of a bang-bang control where a component switches: not saturated there while
    saturated in a neighbouring interval. Bisecting them localises the switching instants.

    Sorted by decreasing jump of the control across the interval's neighbours (relative to the
    bound span); ``limit`` keeps the strongest ones only (singular or state-constrained arcs, where
    the control is interior, would otherwise flag interval after interval)."""
    ph = solution.phase
    lb, ub = ph.control_bounds
    span = np.where(np.isfinite(ub - lb), ub - lb, np.inf)
    u = solution.u
    saturated = (u <= lb + rel_tol * span) | (u >= ub - rel_tol * span)      # (K, nu)
    if ph.control == "linear":
        saturated = saturated[:-1] & saturated[1:]
    nb = np.zeros_like(saturated)
    nb[1:] |= saturated[:-1]
    nb[:-1] |= saturated[1:]
    flagged = np.flatnonzero(np.any(~saturated & nb, axis=1))
    padded = np.vstack([u[:1], u, u[-1:]])
    jump = np.max(np.abs(padded[2:] - padded[:-2]) / np.where(np.isfinite(span), span, 1.0), axis=1)
    order = flagged[np.argsort(-jump[flagged], kind="stable")]
    return order if limit is None else order[:limit]
