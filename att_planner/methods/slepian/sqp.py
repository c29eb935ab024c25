"""SLSQP with exact Jacobians on a working set of sampled rows: MSSA (Celani–Lucarelli) and one
local solve of our minimum-time epigraph program (see the package docstring)."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from att_msgs_py.types import Status
from att_planner.methods.slepian.model import Evaluation, SmoothManeuver, evaluate, trace_residual, zones_at


@dataclass
class SlepianResult:
    """Solution of one solver: α (3, M) in the convention of :mod:`att_planner.methods.slepian`, t_f,
    whether it meets the constraints, and the outcome fields every result of the suite has."""

    alpha: np.ndarray
    tf: float
    feasible: bool
    status: Status
    message: str
    wall_time: float
    nit: int = 0
    nfev: int = 0
    stats: dict = field(default_factory=dict)


class _Cache:
    """Evaluate once per point; Jacobians only when asked (SLSQP's line search needs values only).
    Moving zones: the point is (x, t_f); a new t_f at the same x re-evaluates the zone rows only."""

    def __init__(self, man: SmoothManeuver):
        self.man = man
        self.alpha_scale = float(np.sqrt(man.N))   # optimise x = α/√N (rates in rad per unit τ)
        self.x = None
        self.ev = None
        self.evaluations = 0

    def __call__(self, x: np.ndarray, jac: bool = False, tf: float | None = None) -> Evaluation:
        if self.x is None or not np.array_equal(x, self.x):
            self.ev = evaluate(self.man, x * self.alpha_scale, jac=jac, tf=tf)
            self.x = np.array(x, copy=True)
            self.evaluations += 1
        elif jac and self.ev.final_jac is None:
            self.ev = evaluate(self.man, x * self.alpha_scale, jac=True, tf=tf)
        elif self.man.moving:
            tf = self.man.tf_from_peak(self.ev.peak_torque) if tf is None else tf
            if tf != self.ev.tf:
                self.ev = zones_at(self.man, self.ev, tf, jac=self.ev.eta is not None)
        return self.ev


def violation(man: SmoothManeuver, ev: Evaluation) -> float:
    """Largest constraint violation: final-attitude residual norm and zone excess (cosine); a
    moving-zone evaluation beyond the zones' window is infeasible (the fit ends there)."""
    if man.moving and ev.tf > man.zone_sky.window:
        return np.inf
    cone = float(max(ev.cones.max(), 0.0)) if ev.cones.size else 0.0
    return max(float(np.linalg.norm(ev.final)), cone)


def slepian_result(man: SmoothManeuver, alpha: np.ndarray, status: str, message: str, t0: float, feas_tol: float,
                   tf: float | None = None, **stats) -> SlepianResult:
    """The result of α on ``man``: t_f from its peak torque (moving zones: ``tf`` if longer, the
    epigraph's t_f of the minimum-time program), feasible when the constraints hold to ``feas_tol``
    with the zones at the times of that t_f; ``stats`` gain the violation and the trace residual."""
    ev = evaluate(man, alpha)
    tf_plan = man.tf_from_peak(ev.peak_torque)
    if man.moving:
        tf_plan = tf_plan if tf is None else max(tf_plan, float(tf))
        ev = zones_at(man, ev, tf_plan)
    viol = violation(man, ev)
    return SlepianResult(np.asarray(alpha, float).reshape(3, man.M), tf_plan,
                         viol <= feas_tol, status, message, time.perf_counter() - t0,
                         int(stats.get("iterations", 0)), int(stats.get("evaluations", 0)),
                         dict(stats, violation=viol, trace_residual=trace_residual(man, ev.R[-1])))


MOVING_ROUND_ITERATIONS = 30     # SLSQP iterations per round, moving zones, minimum time


class _WorkingSet:
    """Rows of the (many, smooth, mostly slack) sampled constraints handed to SLSQP.

    SLSQP's dense QP costs grow quickly with the row count (3N torque rows ×2 and (N+1)·C cone rows
    would take ~50 ms per iteration), while only rows near their bound matter. A row enters when
    it is within a band of being active or lies on a coarse stride; after each solve the full set
    is checked and violated rows (with neighbours) are added, so the result satisfies all rows.
    """

    def __init__(self, man: SmoothManeuver, stride: int = 10, torque_band: float = 0.6, cone_band: float = 0.15):
        self.stride, self.torque_band, self.cone_band = stride, torque_band, cone_band
        N, C = man.N, man.cone_dirs.shape[0]
        self.torque = np.zeros((N, 3), bool)
        self.cones = np.zeros((N + 1, C), bool)
        self.torque[::stride] = True
        self.cones[::stride] = True
        self.cones[-1] = True

    def add_near_active(self, ev: Evaluation, peak: float):
        self.torque |= np.abs(ev.torque) >= self.torque_band * peak
        self.cones |= ev.cones >= -self.cone_band

    def add_violated(self, ev: Evaluation, peak: float, feas_tol: float) -> bool:
        """Add violated rows and their neighbours; True if any was missing."""
        bad_t = (np.abs(ev.torque) > peak * (1.0 + 1e-9) + feas_tol) & ~self.torque
        bad_c = (ev.cones > feas_tol) & ~self.cones
        for bad, mask in ((bad_t, self.torque), (bad_c, self.cones)):
            grown = bad.copy()
            grown[1:] |= bad[:-1]
            grown[:-1] |= bad[1:]
            mask |= grown
        return bool(bad_t.any() or bad_c.any())


def _budget_callback(deadline: float | None, rows: _Rows, track: list, feas_tol: float,
                     peak_limit: float = np.inf):
    """SLSQP callback: remember the best feasible iterate z (:meth:`_Rows.flown`); stop when the
    deadline has passed or the iterate runs away (peak torque above ``peak_limit``: a hopeless
    start of a multistart)."""
    def callback(z):
        ev = rows.ev(z)
        if np.linalg.norm(ev.final) <= feas_tol:     # zones at the flown t_f only then (moving zones)
            ev, value = rows.flown(z)
            if violation(rows.man, ev) <= feas_tol and (not track or value < track[0][0]):
                track[:] = [(value, np.array(z, copy=True))]
        if (deadline is not None and time.monotonic() > deadline) or ev.peak_torque > peak_limit:
            raise StopIteration
    return callback


def _slsqp_status(res, stopped_by_deadline: bool, feasible: bool) -> Status:
    if stopped_by_deadline:
        return Status.BUDGET_EXPIRED
    if res.success and feasible:
        return Status.OPTIMAL
    return Status.FEASIBLE if feasible else Status.FAILED


class _Rows:
    """The SLSQP objective and constraints of :func:`_sqp` as functions of its variables ``z``:
    ``z = (x, s)`` for the minimum-time epigraph, ``z = x`` for MSSA (x = α/√N).

    Moving zones couple to t_f: in the epigraph t_f = sqrt(J_s s/T̄) is the decision variable s in
    other units (the torque rows |T*| ≤ s are T ≤ T̄ at that t_f), so the zone rows at
    t_k = τ_k t_f(s) gain the column ∂c/∂s = ∂c/∂t_f · t_f/(2s); MSSA holds ``tf`` fixed.
    """

    S_MIN = 1e-12       # floor of s in t_f(s) (SLSQP's line search may step below zero)

    def __init__(self, man: SmoothManeuver, cache: _Cache, ws: _WorkingSet, min_time: bool,
                 end_ratio: float | None, tf: float | None = None):
        self.man, self.cache, self.ws, self.min_time, self.end_ratio, self.tf = man, cache, ws, min_time, end_ratio, tf
        self.P, self.sc = man.n_params, cache.alpha_scale
        self.ends = [0, 1, man.N - 2, man.N - 1]
        self.end_rates = np.kron(np.eye(3), man.basis[[0, -1]] * self.sc)   # ω*(τ_1), ω*(τ_N) = end_rates @ x

    def tf_of(self, z) -> float | None:
        """t_f of the zone rows at z: t_f(s) (moving, minimum time), the fixed ``tf`` (moving,
        MSSA), None (static zones)."""
        if not self.man.moving:
            return None
        return self.man.tf_from_peak(max(z[self.P], self.S_MIN)) if self.min_time else self.tf

    def ev(self, z, jac: bool = False) -> Evaluation:
        return self.cache(z[:self.P], jac, self.tf_of(z))

    def flown(self, z) -> tuple[Evaluation, float]:
        """The evaluation at the t_f a plan of z would fly and its merit: the peak torque (static
        minimum time), t_f(max(s, T*)) as max(s, T*) (moving minimum time: never above T̄), ½‖x‖²."""
        ev = self.ev(z)
        if not self.min_time:
            return ev, 0.5 * float(z @ z)
        if not self.man.moving:
            return ev, ev.peak_torque
        s = max(float(z[self.P]), ev.peak_torque)
        return self.cache(z[:self.P], tf=self.man.tf_from_peak(s)), s

    def bounds(self) -> list | None:
        """Moving zones, minimum time: 0 ≤ s ≤ s(window), t_f within the zones' fit (none otherwise)."""
        if not (self.man.moving and self.min_time):
            return None
        s_max = self.man.torque_max * self.man.zone_sky.window ** 2 / self.man.inertia_scale
        return [(None, None)] * self.P + [(0.0, s_max)]

    def objective(self):
        """(fun, jac): the objective of z."""
        P = self.P
        if self.min_time:
            grad = np.zeros(P + 1)
            grad[P] = 1.0
            return (lambda z: z[P]), (lambda z: grad)
        return (lambda z: 0.5 * z @ z), (lambda z: z)

    def constraints(self) -> list[dict]:
        """This round's constraint dictionaries (the working set as it is now)."""
        cons = [{"type": "eq", "fun": self.eq_fun, "jac": self.eq_jac}]
        if self.min_time and self.end_ratio is not None:
            cons.append({"type": "ineq", "fun": self.end_fun, "jac": self.end_jac})
        if self.ws.cones.any():
            cons.append({"type": "ineq", "fun": self.cone_fun, "jac": self.cone_jac})
        if self.min_time:
            cons.append({"type": "ineq", "fun": self.torque_fun, "jac": self.torque_jac})
        return cons

    def _pad(self, jac_rows):
        return np.hstack([jac_rows, np.zeros((len(jac_rows), 1))]) if self.min_time else jac_rows

    def eq_fun(self, z):
        return self.ev(z).final

    def eq_jac(self, z):
        return self._pad(self.ev(z, jac=True).final_jac * self.sc)

    def cone_fun(self, z):
        return -self.ev(z).cones[self.ws.cones]

    def cone_jac(self, z):
        ev = self.ev(z, jac=True)
        rows = -ev.cones_jac[self.ws.cones] * self.sc
        if not (self.man.moving and self.min_time):
            return self._pad(rows)
        s = z[self.P]
        ds = self.man.dtf_dpeak(s) if s > self.S_MIN else 0.0
        return np.hstack([rows, -ev.cones_dtf[self.ws.cones][:, None] * ds])

    def torque_fun(self, z):
        T = self.ev(z).torque[self.ws.torque]
        return np.concatenate([z[self.P] - T, z[self.P] + T])

    def torque_jac(self, z):
        Tj = self.ev(z, jac=True).torque_jac[self.ws.torque] * self.sc
        ones = np.ones((len(Tj), 1))
        return np.vstack([np.hstack([-Tj, ones]), np.hstack([Tj, ones])])

    def end_fun(self, z):
        P, rho = self.P, self.end_ratio
        T = self.ev(z).torque[self.ends].ravel()
        w = self.end_rates @ z[:P]
        return np.concatenate([rho * z[P] - T, rho * z[P] + T, rho - w, rho + w])

    def end_jac(self, z):
        P = self.P
        Tj = self.ev(z, jac=True).torque_jac[self.ends].reshape(-1, P) * self.sc
        col = np.full((len(Tj), 1), self.end_ratio)
        zero = np.zeros((len(self.end_rates), 1))
        return np.vstack([np.hstack([-Tj, col]), np.hstack([Tj, col]),
                          np.hstack([-self.end_rates, zero]), np.hstack([self.end_rates, zero])])


def _sqp(man: SmoothManeuver, x0: np.ndarray, *, min_time: bool, maxiter: int, ftol: float, feas_tol: float,
         deadline: float | None, max_rounds: int = 8, peak_limit: float = np.inf, end_ratio: float | None = None,
         max_total_iterations: int | None = None, all_rows: bool = False, tf: float | None = None):
    """SLSQP with exact Jacobians on a growing working set; returns (x, t_f, stats, status, message)
    with t_f the maneuver time of x's zone rows (None: static zones).

    ``min_time``: variables (x, s), min s s.t. s ∓ T*_jℓ ≥ 0 (epigraph of max |T*|); otherwise
    min ½‖x‖² (MSSA, moving zones at the fixed ``tf``). Both with final attitude = 0 and zones ≤ 0.
    x = α/√N. Each working-set round is a fresh SLSQP run of up to ``maxiter`` iterations (which
    also resets its quasi-Newton matrix); rounds stop at ``max_total_iterations`` (default:
    ``maxiter``·``max_rounds``).

    Moving zones, minimum time: rounds of at most :data:`MOVING_ROUND_ITERATIONS` iterations, a
    round that ends at that limit followed by another (same total): the t_f column makes the
    Lagrangian's curvature change along the path, and a fresh quasi-Newton matrix converges in
    far fewer iterations than one long run (a third, on the LEO case).

    ``end_ratio`` ρ (min-time only) keeps the ends smooth for any basis size:
    |T*_jℓ| ≤ ρ s at ℓ ∈ {1, 2, N−1, N} and |ω*_j(τ_1)|, |ω*_j(τ_N)| ≤ ρ (rad per unit τ). The
    paper basis (M = 4) meets this by itself (its DPSS vanish to ~1e-7 at the ends); from M ≈ 8
    on the higher-order sequences do not (v_12 at the ends is ~1e-2 of its peak).
    """
    cache = _Cache(man)
    P = man.n_params
    ws = _WorkingSet(man, stride=1 if all_rows else 10)
    if all_rows:
        ws.torque[:] = min_time
        ws.cones[:] = True
    if max_total_iterations is None:
        max_total_iterations = maxiter * max_rounds
    short_rounds = man.moving and min_time
    if short_rounds:
        maxiter = min(maxiter, MOVING_ROUND_ITERATIONS)
        max_rounds = max(max_rounds, -(-max_total_iterations // maxiter))
    rows = _Rows(man, cache, ws, min_time, end_ratio, tf)
    z = np.append(x0, cache(x0).peak_torque) if min_time else np.array(x0, float)
    ev0 = rows.ev(z)
    ws.add_near_active(ev0, ev0.peak_torque)
    fun, jac = rows.objective()
    bounds = rows.bounds()
    track: list = []
    cb = _budget_callback(deadline, rows, track, feas_tol, peak_limit)
    nit, rounds, res, stopped = 0, 0, None, False
    for rounds in range(1, max_rounds + 1):  # noqa: B007 - the count is reported after the loop
        res = minimize(fun, z, jac=jac, method="SLSQP", constraints=rows.constraints(), callback=cb, bounds=bounds,
                       options={"maxiter": maxiter, "ftol": ftol})
        nit += int(res.nit)
        z = res.x
        stopped = deadline is not None and time.monotonic() > deadline
        ev = rows.ev(z)
        peak = z[P] if min_time else ev.peak_torque
        unfinished = short_rounds and res.status == 9      # this round's iteration limit
        if (stopped or ev.peak_torque > peak_limit or nit >= max_total_iterations
                or not (ws.add_violated(ev, peak, feas_tol) or unfinished)):
            break
        if min_time:                    # restart from a point of the epigraph (moving: t_f never shorter)
            z[P] = max(z[P], ev.peak_torque) if man.moving else ev.peak_torque
    ev, value = rows.flown(z)
    if track and (violation(man, ev) > feas_tol or track[0][0] < value):
        z = track[0][1]
        ev, value = rows.flown(z)
    feasible = violation(man, ev) <= feas_tol
    status = _slsqp_status(res, stopped, feasible)
    stats = dict(iterations=nit, rounds=rounds, evaluations=cache.evaluations,
                 working_rows=int(ws.torque.sum() * (2 if min_time else 0) + ws.cones.sum()))
    return z[:P] * cache.alpha_scale, ev.tf, stats, status, str(res.message)


def solve_mssa(man: SmoothManeuver, alpha0: np.ndarray | None = None, *, maxiter: int = 300,
               ftol: float = 1e-10, feas_tol: float = 1e-6, deadline: float | None = None,
               restarts: int = 0, seed: int = 0, start_scale: float = 1.0, tf_iterations: int = 12,
               tf_rtol: float = 1e-7) -> SlepianResult:
    """Celani–Lucarelli: min ½ Σ α_jk² s.t. final attitude and zones (SLSQP, exact gradients).

    ``alpha0 = None`` starts from α = 0 as in the paper (the rest attitude R_i, every exp is the
    identity). There the right-Jacobian derivative is regular (J_r(0) = I) while an
    eigen-decomposition formula for the derivative of exp needs its confluent limit; SQP's first
    step is the eigenaxis rotation, which then has to bend around the cones. If that start ends
    infeasible, up to ``restarts`` seeded Gaussian starts (x = α/√N ~ N(0, start_scale²)) are
    tried (not in the paper). All (N+1)·Z zone rows are handed to SLSQP, as in the paper.

    Moving zones: MSSA's t_f = sqrt(J_s T*(α)/T̄) follows from α, so each solve holds t_f fixed
    and evaluates the zones at its times τ_k t_f: first t_f = 0 (the zones at the start), then
    t_f ← t_f(α) with a warm start, up to ``tf_iterations`` solves, until t_f changes by at most
    ``tf_rtol`` relatively. The result is judged with the zones at its own t_f(α).
    """
    t0 = time.perf_counter()
    x0 = np.zeros(man.n_params) if alpha0 is None else np.ravel(alpha0) / np.sqrt(man.N)
    rng = np.random.default_rng(seed)
    tried = []
    tf = 0.0 if man.moving else None
    options = dict(min_time=False, maxiter=maxiter, ftol=ftol, feas_tol=feas_tol, deadline=deadline, max_rounds=1,
                   all_rows=True)
    for attempt in range(restarts + 1):
        if attempt:   # seeded random restart, only when the previous attempt found no feasible point
            x0 = rng.normal(size=man.n_params) * start_scale
        alpha, _, stats, status, message = _sqp(man, x0, tf=tf, **options)
        tried.append(status)
        if status != Status.FAILED or (deadline is not None and time.monotonic() > deadline):
            break
    tf_history = []
    while man.moving and status != Status.FAILED and len(tf_history) < tf_iterations:
        tf_next = man.tf_from_peak(evaluate(man, alpha).peak_torque)
        tf_history.append(tf_next)
        if abs(tf_next - tf) <= tf_rtol * tf_next or (deadline is not None and time.monotonic() > deadline):
            break
        tf = tf_next
        alpha, _, stats, status, message = _sqp(man, alpha / np.sqrt(man.N), tf=tf, **options)
    extra = {"tf_iterations": tf_history} if man.moving else {}
    return slepian_result(man, alpha, status, message, t0, feas_tol, energy=0.5 * float(np.sum(alpha ** 2)),
                          attempts=tried, **extra, **stats)


def solve_min_time_local(man: SmoothManeuver, alpha0: np.ndarray, *, maxiter: int = 300, ftol: float = 1e-10,
                         feas_tol: float = 1e-6, deadline: float | None = None,
                         peak_limit: float = np.inf, end_ratio: float | None = None,
                         max_total_iterations: int | None = None) -> SlepianResult:
    """Ours, one local solve: min s s.t. −s ≤ T*_jℓ(α) ≤ s, final attitude, zones (SLSQP).

    The epigraph form makes the non-smooth max |T*| a smooth program whose optimum is exactly the
    minimum of t_f = sqrt(T*/T̄) over α (s ↦ sqrt(s) is monotone). With moving zones s is t_f
    itself (t_f = sqrt(J_s s/T̄)), the zone rows at τ_k t_f(s) carry their exact ∂/∂s column
    (:class:`_Rows`), and the plan flies t_f(max(s, T*)).
    """
    t0 = time.perf_counter()
    alpha, tf, stats, status, message = _sqp(man, np.ravel(alpha0) / np.sqrt(man.N), min_time=True,
                                             maxiter=maxiter, ftol=ftol, feas_tol=feas_tol, deadline=deadline,
                                             peak_limit=peak_limit, end_ratio=end_ratio,
                                             max_total_iterations=max_total_iterations)
    return slepian_result(man, alpha, status, message, t0, feas_tol, tf=tf, **stats)
