"""Robust magnetorquer PD gains (Bruni & Celani): batch settling-time simulation and min-max search.

The problem: choose the gains ``(κ_p, κ_d)`` of the law of
:mod:`att_planner.control.magnetorquer` to minimise the settling time ``t_s`` (orbits) of the
attitude ``|q_i| ≤ ν`` under the worst initial condition of the set ``H`` (attitude ``(ρ, φ, θ)``,
rates ``|ω_i| ≤ 0.1 rad/s``, orbit argument ``ψ``)::

    min_{κ ∈ K} max_{h ∈ H} t_s(κ, h)

Building blocks, all pure numpy:

* :mod:`.settling` — the problem data and :func:`simulate_settling`: one vectorised RK4
  (:func:`att_sim.models.dynamics.rk4`) integration of many (gain, initial condition) cases at once, with
  the field code of :mod:`att_sim.models.environment` and the law written out per row; finished cases are
  retired and the batch shrinks. :func:`truth_settling_time` re-checks one case through the truth
  dynamics.
* :mod:`.evaluation` — :class:`BatchEvaluator`, the one place simulations run: in process, or
  split over an executor (local processes, or a Dask distributed client; :func:`make_executor`).
* :mod:`.search` — :func:`direct_batch`, DIRECT (Jones, Perttunen & Stuckman 1993) evaluating all
  the points of an iteration as one batch (:func:`direct_scipy` wraps ``scipy.optimize.direct``,
  sequential), and :func:`sdbox_batch`, SDBOX-style coordinate search with derivative-free line
  search in a box (Lucidi & Sciandrone 2002), any number of starts advanced in lockstep, all polls
  batched.
* :mod:`.minmax` — :func:`worst_case`, the inner maximisation with the three options of the paper
  (``'direct'``, ``'sdbox'`` single start, ``'sdbox-multistart'``); :func:`tune_fixed` /
  :func:`tune_robust`, the outer problems: :func:`tune_robust` is an outer-approximation min-max
  (Blankenship & Falk 1976): DIRECT on the gains against a growing set of hard initial conditions,
  the inner search at the incumbent adds the worst case it finds, the outer DIRECT tree is kept and
  only the new case is evaluated at its points; :func:`thorough_worst_case`, an independent, larger
  search over ``H`` to re-check gains.

The paper's initial conditions, gains and figures are in :mod:`att_planner.reference.bruni_celani`;
the callers pass them in (``tune_fixed(h, ...)``, ``tune_robust(seeds=...)``).
"""
from att_planner.tuning.evaluation import BatchEvaluator, DaskExecutor, ProcessExecutor, SerialExecutor, make_executor
from att_planner.tuning.minmax import (
    INNER_METHODS,
    TuningResult,
    WorstCase,
    distinct_worst,
    thorough_worst_case,
    tune_fixed,
    tune_robust,
    worst_case,
)
from att_planner.tuning.search import DirectSearch, SearchResult, direct_batch, direct_scipy, sdbox_batch
from att_planner.tuning.settling import (
    ABOVE,
    CAPPED,
    DROPPED,
    H_LOWER,
    H_NAMES,
    H_UPPER,
    LOG_GAIN_BOUNDS,
    SETTLED,
    STATUS_NAMES,
    MagnetorquerCase,
    SettlingResult,
    SimSettings,
    initial_states,
    multistart_points,
    propagate,
    simulate_settling,
    truth_settling_time,
)

__all__ = [
    "ABOVE", "CAPPED", "DROPPED", "H_LOWER", "H_NAMES", "H_UPPER", "INNER_METHODS", "LOG_GAIN_BOUNDS",
    "SETTLED", "STATUS_NAMES", "BatchEvaluator", "DaskExecutor", "DirectSearch", "MagnetorquerCase", "ProcessExecutor",
    "SearchResult", "SerialExecutor", "SettlingResult", "SimSettings", "TuningResult", "WorstCase", "direct_batch",
    "direct_scipy", "distinct_worst", "initial_states", "make_executor", "multistart_points", "propagate",
    "sdbox_batch", "simulate_settling", "thorough_worst_case", "truth_settling_time", "tune_fixed", "tune_robust",
    "worst_case",
]
