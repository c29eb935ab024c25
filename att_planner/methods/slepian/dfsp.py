"""DFSP (Celani & Bruni): derivative-free sequential penalty on t_f with objective alternation."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import Status
from att_planner.methods.slepian.model import SmoothManeuver, evaluate
from att_planner.methods.slepian.sqp import SlepianResult, slepian_result, violation


@dataclass
class _PenaltyState:
    x: np.ndarray
    steps: np.ndarray
    eps: float


def _sweep(state: _PenaltyState, merit, z: float, gamma: float, delta: float, theta: float) -> float:
    """One DFSP iteration: along ±e_i for every coordinate i, accept a step with sufficient
    decrease, expand it by 1/δ while the decrease holds, else shrink the tentative step by θ.
    Returns the merit at the new point."""
    for i in range(len(state.x)):
        a = state.steps[i]
        moved = False
        for sign in (1.0, -1.0):
            y = state.x.copy()
            y[i] += sign * a
            zy = merit(y)
            if zy <= z - gamma * a * a:
                # expansion: keep enlarging the step while sufficient decrease holds
                while True:
                    y2 = state.x.copy()
                    y2[i] += sign * a / delta
                    z2 = merit(y2)
                    if z2 > z - gamma * (a / delta) ** 2:
                        break
                    a, y, zy = a / delta, y2, z2
                state.x, z, state.steps[i], moved = y, zy, a, True
                break
        if not moved:
            state.steps[i] = theta * a
    return z


class _Measure:
    """The figures of a point x = α/√N: (t_f, ½Σα², penalty Σ max(0, g)^q + Σ |h|^q); counts the
    evaluations and keeps the best feasible t_f met (violation ≤ ``feas_tol``) and its x."""

    def __init__(self, man: SmoothManeuver, q: float, feas_tol: float):
        self.man, self.q, self.feas_tol = man, q, feas_tol
        self.scale = float(np.sqrt(man.N))
        self.evaluations = 0
        self.best_tf, self.best_x = np.inf, None

    def __call__(self, x: np.ndarray) -> tuple[float, float, float]:
        man, q, s = self.man, self.q, self.scale
        self.evaluations += 1
        ev = evaluate(man, x * s)
        tf = man.tf_from_peak(ev.peak_torque)
        infeas = (np.sum(np.maximum(ev.cones, 0.0) ** q) if ev.cones.size else 0.0) + np.sum(np.abs(ev.final) ** q)
        if violation(man, ev) <= self.feas_tol and tf < self.best_tf:
            self.best_tf, self.best_x = tf, x.copy()
        return tf, 0.5 * float(x @ x) * s * s, infeas


def _phase(state: _PenaltyState, merit, n_iter: int, phase_end: float | None, *, gamma: float, delta: float,
           theta: float, p: float, step_min: float) -> int:
    """One phase: up to ``n_iter`` sweeps, the penalty driven up (ε ← θε) when every step is below
    ε^p; stops early when every step is below ``step_min`` or at ``phase_end``. Returns the sweeps done."""
    z = merit(state.x)
    done = 0
    for done in range(1, n_iter + 1):  # noqa: B007 - the count is reported after the loop
        z = _sweep(state, merit, z, gamma, delta, theta)
        if state.steps.max() <= state.eps ** p:
            state.eps *= theta
            z = merit(state.x)
        if state.steps.max() < step_min:
            break
        if phase_end is not None and time.monotonic() > phase_end:
            break
    return done


def solve_dfsp(man: SmoothManeuver, alpha0: np.ndarray | None = None, *,
               phases: tuple = ("mmt", "mssa", "mmt", "mssa", "mmt"),
               iterations: tuple = (10_000, 10_000, 10_000, 10_000, 30_000),
               time_budget: float | None = 60.0, deadline: float | None = None,
               eps0: float = 1e-1, q: float = 2.0, gamma: float = 1e-6, theta: float = 0.5,
               delta: float = 0.5, p: float = 1.5, step0: float = 0.5, step_min: float = 1e-9,
               feas_tol: float = 5e-4) -> SlepianResult:
    """Celani–Bruni: derivative-free sequential penalty with objective alternation.

    Each phase minimises the merit Z(x; ε) = f(x)/f_ref + (1/ε)(Σ max(0, g_i)^q + Σ |h_j|^q)
    (g: cones, h: final-attitude residual vee log(R_fᵀ R(1))) with the coordinate line searches of
    Liuzzi, Lucidi & Sciandrone (SIAM J. Optim. 2010): along ±e_i, accept a step with sufficient
    decrease Z(x + a d) ≤ Z(x) − γa², expand by 1/δ while it keeps decreasing, otherwise shrink the
    tentative step by θ; ε ← θε (penalty driven up) when every tentative step is below ε^p.
    f is t_f (MMT, not differentiable, evaluated by simulation) or ½Σα² (MSSA). One iteration is
    one sweep over all 2·3M directions; a phase also ends when every step is below ``step_min``.
    Penalty exponent q = 2 (smooth merit: with q near 1 coordinate moves off the curved
    final-attitude manifold are never accepted once ε is small). The published run is 10,000
    iterations per phase (30,000 in the last) — about an hour; ``time_budget`` (seconds, split
    over phases in proportion to their iterations) keeps the default run short. The result is the
    best feasible point met (a penalty method approaches feasibility from outside: ``feas_tol``
    5e-4 rad of final attitude / cone cosine, covered by the planner's cone margin of 1e-3 rad).
    """
    t0 = time.perf_counter()
    if len(phases) != len(iterations):
        raise ValueError("iterations must give one count per phase")
    P = man.n_params
    measure = _Measure(man, q, feas_tol)
    state = _PenaltyState(np.zeros(P) if alpha0 is None else np.ravel(alpha0) / measure.scale, np.full(P, step0), eps0)
    history = []
    total_iterations = float(sum(iterations))
    end = None if time_budget is None else time.monotonic() + time_budget
    if deadline is not None:
        end = deadline if end is None else min(end, deadline)
    stopped = False
    t_unit = float(np.sqrt(man.inertia_scale / man.torque_max))
    phase_start = time.monotonic()
    for phase, n_iter in zip(phases, iterations):
        if phase not in ("mmt", "mssa"):
            raise ValueError(f"phases must be 'mmt' or 'mssa', got {phase!r}")
        phase_end = None if end is None else phase_start + (end - phase_start) * n_iter / total_iterations
        total_iterations -= n_iter
        state.steps[:] = step0          # each phase restarts its coordinate step sizes
        obj_index = 0 if phase == "mmt" else 1
        # objective scale: the time unit sqrt(J_max/T̄) for MMT, the phase's starting energy for MSSA
        ref = t_unit if phase == "mmt" else max(measure(state.x)[1], t_unit)

        def merit(x, obj_index=obj_index, ref=ref):
            vals = measure(x)
            return vals[obj_index] / ref + vals[2] / state.eps

        done = _phase(state, merit, n_iter, phase_end, gamma=gamma, delta=delta, theta=theta, p=p,
                      step_min=step_min)
        phase_start = time.monotonic()
        tf, energy, infeas = measure(state.x)
        history.append({"phase": phase, "iterations": done, "tf": tf, "energy": energy, "infeasibility": infeas,
                        "eps": state.eps, "best_feasible_tf": measure.best_tf})
        if deadline is not None and time.monotonic() > deadline:
            stopped = True
            break
    if measure.best_x is None:
        return slepian_result(man, state.x * measure.scale, Status.BUDGET_EXPIRED if stopped else Status.FAILED,
                              "no feasible point found within the iterations/time budget", t0, feas_tol,
                              evaluations=measure.evaluations, phases=history)
    status = Status.BUDGET_EXPIRED if stopped else Status.FEASIBLE
    return slepian_result(man, measure.best_x * measure.scale, status, "best feasible point of the last MMT phases",
                          t0, feas_tol, evaluations=measure.evaluations, phases=history)
