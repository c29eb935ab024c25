"""Smooth rest-to-rest keep-out-cone maneuvers on SO(3) with a Slepian (DPSS) rate basis.

In normalised time τ = t/t_f ∈ [0, 1] the body rate is ω*_j(τ_ℓ) = Σ_k α_jk v_k(τ_ℓ), with v_k the
first M discrete prolate spheroidal sequences of length N and half-bandwidth W (unit energy,
``scipy.signal.windows.dpss(N, N W, Kmax=M)``). With the conventions of the issue (Celani & Bruni
2021, Celani & Lucarelli), on τ_ℓ = (ℓ−1)/N, ℓ = 1..N, Δτ = 1/N:

* attitude by zero-order hold, R_{ℓ+1} = R_ℓ exp(Δτ ω*_ℓ×) (N+1 attitudes, R_1 = R_i);
* torque T*_ℓ = J (ω*_ℓ − ω*_{ℓ−1})/Δτ + ω*_ℓ × J ω*_ℓ (backward difference, zero at ℓ = 1);
* T* = max_{ℓ,j} |T*_jℓ|, maneuver time t_f = sqrt(T*/T̄), physical torque T(t) = T*(t/t_f)/t_f²;
* final attitude R_{N+1} = R_f, cones rᵀ R_ℓᵀ w_i ≤ cos θ_i at all N+1 attitudes.

Exact first derivatives of everything w.r.t. α come from one identity: a perturbation of the rates
moves every attitude by a left (inertial) rotation, dR_n = (η_n×) R_n, with

    η_n = Σ_{m<n} R_{m+1} J_r(Δτ ω*_m) Δτ dω*_m      (J_r: right Jacobian of SO(3)),

a cumulative sum, so all N+1 attitude Jacobians cost O(N M). This is the exact derivative of the
product of exponentials (equivalent to the spectral formula for ∂exp(A + xB)/∂x used by Celani &
Lucarelli, and regular at α = 0, where an eigen-decomposition formula meets the triple zero
eigenvalue of 0× and needs its confluent limit; here J_r(0) = I).

The final-attitude equality tr(R_fᵀ R_{N+1}) = 3 of the papers has a vanishing gradient at its
solution (it is a maximum of the trace), which breaks the constraint qualification of any SQP/IP
solver. The solvers here use the equivalent, well-conditioned 3-vector vee(log(R_fᵀ R_{N+1})) = 0
(exact Jacobian through the inverse left Jacobian); the issue's quantity 3 − tr(...) is reported.

Three methods (all return a :class:`SlepianResult`):

* :func:`solve_mssa` — Celani–Lucarelli: min ½ Σ α² s.t. final attitude and cones, SLSQP.
* :func:`solve_dfsp` — Celani–Bruni: derivative-free sequential penalty (Liuzzi–Lucidi–Sciandrone
  2010) on t_f, alternating MMT (min t_f) and MSSA (min Σα²) phases.
* :func:`solve_min_time` — ours: min s s.t. −s ≤ T*_jℓ ≤ s, final attitude and cones, exact
  gradients (SLSQP on a working set of rows), seeded multistart on a coarse grid, continuation
  over basis sizes M = 4 → 8 (→ 12) with the ends kept smooth, refinement at the full N.

:func:`plan_slepian` turns a :class:`ManeuverProblem` into a :class:`ManeuverPlan` (physical time,
ZOH body torque); :func:`benchmark_problem` gives the published cases.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import minimize
from scipy.signal.windows import dpss

from att_planner.cones import Cone
from att_planner.problem import (STATUS_BUDGET, STATUS_FAILED, STATUS_FEASIBLE, STATUS_OPTIMAL,
                                 ManeuverPlan, ManeuverProblem)
from att_sim import rotations as rot
from att_sim import dynamics as dyn
from att_sim.dynamics import Spacecraft

PAPER_M, PAPER_N, PAPER_W = 4, 500, 0.015
METHODS = ("slepian_minimum_time", "mssa", "dfsp")
DEFAULT_METHOD = "slepian_minimum_time"


# ---------------------------------------------------------------------------------------------
# SO(3) helpers (stacked)
# ---------------------------------------------------------------------------------------------

def _vee(S: np.ndarray) -> np.ndarray:
    return np.stack([S[..., 2, 1], S[..., 0, 2], S[..., 1, 0]], axis=-1)


def _log_so3(R: np.ndarray) -> np.ndarray:
    """Rotation vector of a single rotation matrix (angle in [0, π))."""
    c = np.clip(0.5 * (np.trace(R) - 1.0), -1.0, 1.0)
    th = float(np.arccos(c))
    w = 0.5 * _vee(R - R.T)                   # sin θ · axis
    if th < 1e-6:
        return w * (1.0 + th * th / 6.0)
    if th > np.pi - 1e-6:                     # θ ≈ π: axis from the symmetric part
        axis = rot.to_axis_angle(rot.from_dcm(R))[0]
        return axis * th
    return w * (th / np.sin(th))


def _right_jacobian(phi: np.ndarray) -> np.ndarray:
    """J_r(φ) = I − (1 − cos θ)/θ² φ× + (θ − sin θ)/θ³ (φ×)², stacked, series near θ = 0."""
    th2 = np.sum(phi * phi, axis=-1)
    th = np.sqrt(th2)
    small = th < 1e-4
    ths = np.where(small, 1.0, th)
    a = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    b = np.where(small, 1.0 / 6.0 - th2 / 120.0, (ths - np.sin(ths)) / ths**3)
    P = rot.hat(phi)
    return np.eye(3) - a[..., None, None] * P + b[..., None, None] * (P @ P)


def _left_jacobian_inv(phi: np.ndarray) -> np.ndarray:
    """J_l⁻¹(φ) = I − ½ φ× + (1/θ² − (1 + cos θ)/(2 θ sin θ)) (φ×)² (single vector, θ < π)."""
    th = float(np.linalg.norm(phi))
    P = rot.hat(phi)
    c = 1.0 / 12.0 + th**2 / 720.0 if th < 1e-4 else 1.0 / th**2 - (1.0 + np.cos(th)) / (2.0 * th * np.sin(th))
    return np.eye(3) - 0.5 * P + c * (P @ P)


def _expm_stack(phi: np.ndarray) -> np.ndarray:
    """exp(φ×) for a stack of rotation vectors (Rodrigues, series near 0)."""
    th2 = np.sum(phi * phi, axis=-1)
    th = np.sqrt(th2)
    small = th < 1e-4
    ths = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th2 / 6.0, np.sin(ths) / ths)
    b = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    P = rot.hat(phi)
    return np.eye(3) + a[..., None, None] * P + b[..., None, None] * (P @ P)


def _cumulative_product(E: np.ndarray) -> np.ndarray:
    """P_n = E_0 E_1 … E_n for a stack of matrices (Hillis–Steele scan: log2 N batched products)."""
    P = E.copy()
    shift = 1
    while shift < len(P):
        P[shift:] = P[:-shift] @ P[shift:]
        shift *= 2
    return P


# ---------------------------------------------------------------------------------------------
# The discretised problem and its exact derivatives
# ---------------------------------------------------------------------------------------------

def slepian_basis(N: int, W: float, M: int) -> np.ndarray:
    """(N, M) matrix of the first M unit-energy DPSS of length N, half-bandwidth W."""
    return np.atleast_2d(dpss(N, N * W, Kmax=M)).T.copy()


@dataclass(frozen=True)
class SmoothManeuver:
    """Discretised smooth maneuver (all arrays ready for evaluation).

    ``inertia`` is J divided by ``inertia_scale`` (the largest principal inertia): the optimal α
    does not depend on that scale, and t_f = sqrt(inertia_scale · T*_scaled / T̄).
    ``cone_cos`` holds cos(θ_i + margin): the optimiser keeps a small angular margin so that the
    truth integration of the ZOH torque (which lags the model by half a sample) stays outside.
    """

    basis: np.ndarray            # (N, M) unit-energy DPSS
    inertia: np.ndarray          # (3, 3) scaled
    inertia_scale: float
    torque_max: float
    R_initial: np.ndarray
    R_final: np.ndarray
    sensor_axis: np.ndarray
    cone_dirs: np.ndarray        # (C, 3)
    cone_cos: np.ndarray         # (C,)
    sensor_target: np.ndarray | None = None
    target_basis: np.ndarray | None = None   # (2, 3) rows ⊥ sensor_target
    half_bandwidth: float = PAPER_W

    @property
    def N(self) -> int:
        return self.basis.shape[0]

    @property
    def M(self) -> int:
        return self.basis.shape[1]

    @property
    def n_params(self) -> int:
        return 3 * self.M

    def tf_from_peak(self, peak_scaled_torque: float) -> float:
        return float(np.sqrt(self.inertia_scale * peak_scaled_torque / self.torque_max))

    def resized(self, N: int | None = None, M: int | None = None) -> "SmoothManeuver":
        """Same maneuver with another sample count (same time-bandwidth product N·W, so the same
        continuous Slepian functions) and/or basis size."""
        N = self.N if N is None else N
        M = self.M if M is None else M
        W = self.half_bandwidth * self.N / N
        return replace(self, basis=slepian_basis(N, W, M), half_bandwidth=W)


def build_maneuver(problem: ManeuverProblem, M: int = PAPER_M, N: int = PAPER_N, W: float = PAPER_W,
                   cone_margin: float = 0.0) -> SmoothManeuver:
    """Discretise a :class:`ManeuverProblem` (validated options, see :func:`plan_slepian`)."""
    J = np.asarray(problem.spacecraft.inertia, float)
    scale = float(np.max(np.linalg.eigvalsh(J)))
    cones = list(problem.cones)
    dirs = np.array([c.direction for c in cones]).reshape(-1, 3)
    cos = np.cos(np.array([c.half_angle for c in cones]) + cone_margin)
    r = np.asarray(problem.sensor_axis, float)
    target = tbasis = None
    if problem.sensor_target is not None:
        target = np.asarray(problem.sensor_target, float)
        target = target / np.linalg.norm(target)
        u = np.cross(target, np.eye(3)[np.argmin(np.abs(target))])
        u /= np.linalg.norm(u)
        tbasis = np.stack([u, np.cross(target, u)])
    return SmoothManeuver(slepian_basis(N, W, M), J / scale, scale, float(problem.spacecraft.body_torque_max),
                          rot.dcm(problem.q_initial), rot.dcm(problem.q_final), r / np.linalg.norm(r),
                          dirs, cos, target, tbasis, W)


@dataclass
class Evaluation:
    """Rates, torques, attitudes and constraint values for one α, with optional Jacobians.

    Parameter order: p = j·M + k for α_jk (α is (3, M)). Signs: ``cones`` ≤ 0 and
    ``final`` = 0 are feasible.
    """

    omega: np.ndarray           # (N, 3) normalised-time rates ω*
    torque: np.ndarray          # (N, 3) scaled T* (J/inertia_scale)
    R: np.ndarray               # (N+1, 3, 3)
    final: np.ndarray           # (3,) vee log(R_fᵀ R_{N+1}), or (2,) boresight ⊥ sensor_target
    cones: np.ndarray           # (N+1, C) w·b − cos(θ + margin)
    torque_jac: np.ndarray | None = None   # (N, 3, P)
    final_jac: np.ndarray | None = None    # (3 or 2, P)
    cones_jac: np.ndarray | None = None    # (N+1, C, P)

    @property
    def peak_torque(self) -> float:
        return float(np.abs(self.torque).max())


def evaluate(man: SmoothManeuver, alpha: np.ndarray, jac: bool = False) -> Evaluation:
    """Propagate α through the discretisation conventions (module docstring); exact Jacobians."""
    V = man.basis
    N, M = V.shape
    dt = 1.0 / N
    A = np.asarray(alpha, float).reshape(3, M)
    w = V @ A.T                                           # (N, 3)
    J = man.inertia
    dw = np.empty_like(w)
    dw[0] = 0.0
    dw[1:] = (w[1:] - w[:-1]) / dt
    Jw = w @ J.T
    torque = dw @ J.T + rot.cross(w, Jw)
    phi = dt * w
    E = _expm_stack(phi)
    R = np.concatenate([man.R_initial[None], man.R_initial @ _cumulative_product(E)])
    b = R @ man.sensor_axis                               # (N+1, 3) inertial boresight
    cones = b @ man.cone_dirs.T - man.cone_cos
    if man.sensor_target is None:
        e = _log_so3(man.R_final.T @ R[N])
        final = e
    else:
        final = man.target_basis @ b[N]
    ev = Evaluation(w, torque, R, final, cones)
    if not jac:
        return ev
    P = 3 * M
    # torque: dT_ℓ/dα_jk = J e_j D_ℓk + (ω_ℓ× J − (J ω_ℓ)×) e_j V_ℓk
    D = np.vstack([np.zeros((1, M)), np.diff(V, axis=0)]) / dt
    Agyro = rot.hat(w) @ J - rot.hat(Jw)                  # (N, 3, 3)
    tj = J[None, :, :, None] * D[:, None, None, :] + Agyro[..., None] * V[:, None, None, :]
    ev.torque_jac = tj.reshape(N, 3, P)
    # attitudes: dR_n = (η_n×) R_n, η_n = Σ_{m<n} Δτ R_{m+1} J_r(φ_m) e_j V_mk
    G = R[1:] @ _right_jacobian(phi)                      # (N, 3, 3)
    H = (dt * G[..., None] * V[:, None, None, :]).reshape(N, 3, P)
    eta = np.concatenate([np.zeros((1, 3, P)), np.cumsum(H, axis=0)])   # (N+1, 3, P)
    bw = rot.cross(b[:, None, :], man.cone_dirs[None, :, :])             # (N+1, C, 3)
    ev.cones_jac = np.einsum("nxp,ncx->ncp", eta, bw)
    if man.sensor_target is None:
        ev.final_jac = _left_jacobian_inv(final) @ man.R_final.T @ eta[N]
    else:
        bu = rot.cross(b[N][None, :], man.target_basis)                 # (2, 3)
        ev.final_jac = bu @ eta[N]
    return ev


def trace_residual(man: SmoothManeuver, R_end: np.ndarray) -> float:
    """The papers' final-attitude quantity 3 − tr(R_fᵀ R(1)) (≥ 0, zero at the goal)."""
    return float(3.0 - np.trace(man.R_final.T @ R_end))


# ---------------------------------------------------------------------------------------------
# Published cases (Celani & Bruni 2021, case studies 1 and 2)
# ---------------------------------------------------------------------------------------------

PUBLISHED = {
    # t_f (s for earth_obs, TU for swift) and compute time where given
    "earth_obs": {"mssa": 2.73e3, "dfsp": 755.0, "dfsp_minutes": 136.0, "time_optimal_nonsmooth": 405.0},
    "swift": {"mssa": 6.26, "mssa_conference": 6.37, "dfsp": 5.90, "dfsp_minutes": 55.0,
              "time_optimal_nonsmooth": 3.5},
}
CASES = tuple(PUBLISHED)


def benchmark_problem(case: str) -> ManeuverProblem:
    """The published rest-to-rest cases as :class:`ManeuverProblem` (R_i = I).

    ``earth_obs``: J = diag(3000, 4500, 6000) kg m², T̄ = 0.25 N m, 135° about body x, r = y,
    Sun and Moon cones. ``swift``: J = I, T̄ = 1 (time unit TU), 135° about body z, r = x, Sun,
    Earth and Moon cones.
    """
    if case == "earth_obs":
        sc = Spacecraft(inertia=np.diag([3000.0, 4500.0, 6000.0]), body_torque_max=0.25)
        qf = rot.from_axis_angle([1.0, 0.0, 0.0], 0.75 * np.pi)
        r = np.array([0.0, 1.0, 0.0])
        cones = [Cone(np.array([-0.18, 0.56, 0.81]), np.radians(47.0), "sun"),
                 Cone(np.array([0.95, 0.0, 0.31]), np.radians(36.0), "moon")]
    elif case == "swift":
        sc = Spacecraft(inertia=np.eye(3), body_torque_max=1.0)
        qf = rot.from_axis_angle([0.0, 0.0, 1.0], 0.75 * np.pi)
        r = np.array([1.0, 0.0, 0.0])
        cones = [Cone(np.array([0.5, 0.866, 0.0]), np.radians(47.0), "sun"),
                 Cone(np.array([0.0, 0.0, -1.0]), np.radians(33.0), "earth"),
                 Cone(np.array([0.1795, 0.3109, 0.9333]), np.radians(23.0), "moon")]
    else:
        raise ValueError(f"case must be one of {CASES}, got {case!r}")
    return ManeuverProblem(spacecraft=sc, q_initial=rot.IDENTITY.copy(), q_final=qf, sensor_axis=r, cones=cones)


# ---------------------------------------------------------------------------------------------
# Solvers
# ---------------------------------------------------------------------------------------------

@dataclass
class SlepianResult:
    """Solution of one method: α (3, M) in the issue's convention, t_f, status and statistics."""

    alpha: np.ndarray
    tf: float
    feasible: bool
    status: str
    message: str
    seconds: float
    stats: dict = field(default_factory=dict)


class _Cache:
    """Evaluate once per point; Jacobians only when asked (SLSQP's line search needs values only)."""

    def __init__(self, man: SmoothManeuver):
        self.man = man
        self.alpha_scale = float(np.sqrt(man.N))   # optimise x = α/√N (rates in rad per unit τ)
        self.x = None
        self.ev = None
        self.evaluations = 0

    def __call__(self, x: np.ndarray, jac: bool = False) -> Evaluation:
        if self.x is None or not np.array_equal(x, self.x):
            self.ev = evaluate(self.man, x * self.alpha_scale, jac=jac)
            self.x = np.array(x, copy=True)
            self.evaluations += 1
        elif jac and self.ev.final_jac is None:
            self.ev = evaluate(self.man, x * self.alpha_scale, jac=True)
        return self.ev


def violation(man: SmoothManeuver, ev: Evaluation) -> float:
    """Largest constraint violation: final-attitude residual norm and cone excess (cosine)."""
    cone = float(max(ev.cones.max(), 0.0)) if ev.cones.size else 0.0
    return max(float(np.linalg.norm(ev.final)), cone)


def _result(man: SmoothManeuver, alpha: np.ndarray, status: str, message: str, t0: float, feas_tol: float,
            **stats) -> SlepianResult:
    ev = evaluate(man, alpha)
    viol = violation(man, ev)
    return SlepianResult(np.asarray(alpha, float).reshape(3, man.M), man.tf_from_peak(ev.peak_torque),
                         viol <= feas_tol, status, message, time.perf_counter() - t0,
                         dict(stats, violation=viol, trace_residual=trace_residual(man, ev.R[-1])))


class _WorkingSet:
    """Rows of the (many, smooth, mostly slack) sampled constraints handed to SLSQP.

    SLSQP's dense QP costs grow quickly with the row count (3N torque rows ×2 and (N+1)·C cone rows
    would take ~50 ms per iteration), while only rows near their bound matter. A row enters when
    it is within a band of being active or lies on a coarse stride; after each solve the full set
    is checked and violated rows (with neighbours) are added, so the result satisfies all rows.
    """

    def __init__(self, man: SmoothManeuver, stride: int = 10, torque_band: float = 0.6, cone_band: float = 0.15):
        self.man, self.stride, self.torque_band, self.cone_band = man, stride, torque_band, cone_band
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


def _budget_callback(deadline: float | None, cache: _Cache, track: list, feas_tol: float, merit,
                     peak_limit: float = np.inf):
    """SLSQP callback: remember the best feasible iterate; stop when the deadline has passed or
    the iterate runs away (peak torque above ``peak_limit``: a hopeless start of a multistart)."""
    def callback(x):
        ev = cache(x)
        if violation(cache.man, ev) <= feas_tol:
            value = merit(x, ev)
            if not track or value < track[0][0]:
                track[:] = [(value, np.array(x, copy=True))]
        if (deadline is not None and time.monotonic() > deadline) or ev.peak_torque > peak_limit:
            raise StopIteration
    return callback


def _slsqp_status(res, stopped_by_deadline: bool, feasible: bool) -> str:
    if stopped_by_deadline:
        return STATUS_BUDGET
    if res.success and feasible:
        return STATUS_OPTIMAL
    return STATUS_FEASIBLE if feasible else STATUS_FAILED


def _sqp(man: SmoothManeuver, x0: np.ndarray, *, min_time: bool, maxiter: int, ftol: float, feas_tol: float,
         deadline: float | None, max_rounds: int = 8, peak_limit: float = np.inf, end_ratio: float | None = None,
         max_total_iterations: int | None = None, all_rows: bool = False):
    """SLSQP with exact Jacobians on a growing working set; returns (x, stats, status, message).

    ``min_time``: variables (x, s), min s s.t. s ∓ T*_jℓ ≥ 0 (epigraph of max |T*|); otherwise
    min ½‖x‖² (MSSA). Both with final attitude = 0 and cones ≤ 0. x = α/√N. Each working-set
    round is a fresh SLSQP run of up to ``maxiter`` iterations (which also resets its quasi-Newton
    matrix); rounds stop at ``max_total_iterations`` (default: ``maxiter``·``max_rounds``).

    ``end_ratio`` ρ (min-time only) keeps the ends smooth for any basis size:
    |T*_jℓ| ≤ ρ s at ℓ ∈ {1, 2, N−1, N} and |ω*_j(τ_1)|, |ω*_j(τ_N)| ≤ ρ (rad per unit τ). The
    paper basis (M = 4) meets this by itself (its DPSS vanish to ~1e-7 at the ends); from M ≈ 8
    on the higher-order sequences do not (v_12 at the ends is ~1e-2 of its peak).
    """
    cache = _Cache(man)
    sc = cache.alpha_scale
    P = man.n_params
    ws = _WorkingSet(man, stride=1 if all_rows else 10)
    if all_rows:
        ws.torque[:] = min_time
        ws.cones[:] = True
    if max_total_iterations is None:
        max_total_iterations = maxiter * max_rounds
    ev0 = cache(x0)
    ws.add_near_active(ev0, ev0.peak_torque)
    z = np.append(x0, ev0.peak_torque) if min_time else np.array(x0, float)
    nz = len(z)

    def pad(jac_rows):
        return np.hstack([jac_rows, np.zeros((len(jac_rows), 1))]) if min_time else jac_rows

    def eq_fun(z):
        return cache(z[:P]).final

    def eq_jac(z):
        return pad(cache(z[:P], jac=True).final_jac * sc)

    def cone_fun(z):
        return -cache(z[:P]).cones[ws.cones]

    def cone_jac(z):
        return pad(-cache(z[:P], jac=True).cones_jac[ws.cones] * sc)

    def torque_fun(z):
        T = cache(z[:P]).torque[ws.torque]
        return np.concatenate([z[P] - T, z[P] + T])

    def torque_jac(z):
        Tj = cache(z[:P], jac=True).torque_jac[ws.torque] * sc
        ones = np.ones((len(Tj), 1))
        return np.vstack([np.hstack([-Tj, ones]), np.hstack([Tj, ones])])

    if min_time:
        grad = np.zeros(nz)
        grad[P] = 1.0
        fun, jac = (lambda z: z[P]), (lambda z: grad)
        merit = lambda x, ev: ev.peak_torque  # noqa: E731
    else:
        fun, jac = (lambda z: 0.5 * z @ z), (lambda z: z)
        merit = lambda x, ev: 0.5 * x @ x  # noqa: E731
    track: list = []
    cb = _budget_callback(deadline, cache, track, feas_tol, merit, peak_limit)
    nit, rounds, res, stopped = 0, 0, None, False
    ends = [0, 1, man.N - 2, man.N - 1]
    end_rates = np.kron(np.eye(3), man.basis[[0, -1]] * sc)          # ω*(τ_1), ω*(τ_N) = end_rates @ x

    def end_fun(z):
        T = cache(z[:P]).torque[ends].ravel()
        w = end_rates @ z[:P]
        return np.concatenate([end_ratio * z[P] - T, end_ratio * z[P] + T, end_ratio - w, end_ratio + w])

    def end_jac(z):
        Tj = cache(z[:P], jac=True).torque_jac[ends].reshape(-1, P) * sc
        col = np.full((len(Tj), 1), end_ratio)
        zero = np.zeros((len(end_rates), 1))
        return np.vstack([np.hstack([-Tj, col]), np.hstack([Tj, col]),
                          np.hstack([-end_rates, zero]), np.hstack([end_rates, zero])])

    for rounds in range(1, max_rounds + 1):
        cons = [{"type": "eq", "fun": eq_fun, "jac": eq_jac}]
        if min_time and end_ratio is not None:
            cons.append({"type": "ineq", "fun": end_fun, "jac": end_jac})
        if ws.cones.any():
            cons.append({"type": "ineq", "fun": cone_fun, "jac": cone_jac})
        if min_time:
            cons.append({"type": "ineq", "fun": torque_fun, "jac": torque_jac})
        res = minimize(fun, z, jac=jac, method="SLSQP", constraints=cons, callback=lambda z: cb(z[:P]),
                       options={"maxiter": maxiter, "ftol": ftol})
        nit += int(res.nit)
        z = res.x
        stopped = deadline is not None and time.monotonic() > deadline
        ev = cache(z[:P])
        peak = z[P] if min_time else ev.peak_torque
        if (stopped or ev.peak_torque > peak_limit or nit >= max_total_iterations
                or not ws.add_violated(ev, peak, feas_tol)):
            break
        if min_time:
            z[P] = ev.peak_torque       # restart from a point of the epigraph
    x = z[:P]
    ev = cache(x)
    if track and (violation(man, ev) > feas_tol or track[0][0] < merit(x, ev)):
        x = track[0][1]
    feasible = violation(man, cache(x)) <= feas_tol
    status = _slsqp_status(res, stopped, feasible)
    stats = dict(iterations=nit, rounds=rounds, evaluations=cache.evaluations,
                 working_rows=int(ws.torque.sum() * (2 if min_time else 0) + ws.cones.sum()))
    return x * sc, stats, status, str(res.message)


def solve_mssa(man: SmoothManeuver, alpha0: np.ndarray | None = None, *, maxiter: int = 300,
               ftol: float = 1e-10, feas_tol: float = 1e-6, deadline: float | None = None,
               restarts: int = 0, seed: int = 0, start_scale: float = 1.0) -> SlepianResult:
    """Celani–Lucarelli: min ½ Σ α_jk² s.t. final attitude and cones (SLSQP, exact gradients).

    ``alpha0 = None`` starts from α = 0 as in the paper (the rest attitude R_i, every exp is the
    identity). There the right-Jacobian derivative is regular (J_r(0) = I) while an
    eigen-decomposition formula for the derivative of exp needs its confluent limit; SQP's first
    step is the eigenaxis rotation, which then has to bend around the cones. If that start ends infeasible, up to ``restarts``
    seeded Gaussian starts (x = α/√N ~ N(0, start_scale²)) are tried (not in the paper). All
    (N+1)·C cone rows are handed to SLSQP, as in the paper.
    """
    t0 = time.perf_counter()
    x0 = np.zeros(man.n_params) if alpha0 is None else np.ravel(alpha0) / np.sqrt(man.N)
    rng = np.random.default_rng(seed)
    tried = []
    for attempt in range(restarts + 1):
        if attempt:   # seeded random restart, only when the previous attempt found no feasible point
            x0 = rng.normal(size=man.n_params) * start_scale
        alpha, stats, status, message = _sqp(man, x0, min_time=False, maxiter=maxiter, ftol=ftol,
                                             feas_tol=feas_tol, deadline=deadline, max_rounds=1, all_rows=True)
        tried.append(status)
        if status != STATUS_FAILED or (deadline is not None and time.monotonic() > deadline):
            break
    return _result(man, alpha, status, message, t0, feas_tol, energy=0.5 * float(np.sum(alpha ** 2)),
                   attempts=tried, **stats)


def solve_min_time_local(man: SmoothManeuver, alpha0: np.ndarray, *, maxiter: int = 300, ftol: float = 1e-10,
                         feas_tol: float = 1e-6, deadline: float | None = None,
                         peak_limit: float = np.inf, end_ratio: float | None = None,
                         max_total_iterations: int | None = None) -> SlepianResult:
    """Ours, one local solve: min s s.t. −s ≤ T*_jℓ(α) ≤ s, final attitude, cones (SLSQP).

    The epigraph form makes the non-smooth max |T*| a smooth program whose optimum is exactly the
    minimum of t_f = sqrt(T*/T̄) over α (s ↦ sqrt(s) is monotone).
    """
    t0 = time.perf_counter()
    alpha, stats, status, message = _sqp(man, np.ravel(alpha0) / np.sqrt(man.N), min_time=True, maxiter=maxiter,
                                         ftol=ftol, feas_tol=feas_tol, deadline=deadline, peak_limit=peak_limit,
                                         end_ratio=end_ratio, max_total_iterations=max_total_iterations)
    return _result(man, alpha, status, message, t0, feas_tol, **stats)


@dataclass
class _PenaltyState:
    x: np.ndarray
    steps: np.ndarray
    eps: float


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
    final-attitude manifold are never accepted once ε is small). The published run is 10,000 iterations per phase (30,000
    in the last) — about an hour; ``time_budget`` (seconds, split over phases in proportion to
    their iterations) keeps the default run short. The result is the best feasible point met
    (a penalty method approaches feasibility from outside: ``feas_tol`` 5e-4 rad of final
    attitude / cone cosine, covered by the planner's cone margin of 1e-3 rad).
    """
    t0 = time.perf_counter()
    if len(phases) != len(iterations):
        raise ValueError("iterations must give one count per phase")
    s = float(np.sqrt(man.N))
    P = man.n_params
    x = np.zeros(P) if alpha0 is None else np.ravel(alpha0) / s
    state = _PenaltyState(x, np.full(P, step0), eps0)
    evals = 0
    best = [np.inf, None]           # best feasible t_f and its x
    history = []
    total_iterations = float(sum(iterations))
    end = None if time_budget is None else time.monotonic() + time_budget
    if deadline is not None:
        end = deadline if end is None else min(end, deadline)
    stopped = False

    def measure(x):
        nonlocal evals
        evals += 1
        ev = evaluate(man, x * s)
        tf = man.tf_from_peak(ev.peak_torque)
        infeas = (np.sum(np.maximum(ev.cones, 0.0) ** q) if ev.cones.size else 0.0) + np.sum(np.abs(ev.final) ** q)
        viol = violation(man, ev)
        if viol <= feas_tol and tf < best[0]:
            best[0], best[1] = tf, x.copy()
        return tf, 0.5 * float(x @ x) * s * s, infeas

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

        def merit(x):
            vals = measure(x)
            return vals[obj_index] / ref + vals[2] / state.eps

        z = merit(state.x)
        done = 0
        for done in range(1, n_iter + 1):
            for i in range(P):
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
            if state.steps.max() <= state.eps ** p:
                state.eps *= theta
                z = merit(state.x)
            if state.steps.max() < step_min:
                break
            if phase_end is not None and time.monotonic() > phase_end:
                break
        phase_start = time.monotonic()
        tf, energy, infeas = measure(state.x)
        history.append({"phase": phase, "iterations": done, "tf": tf, "energy": energy, "infeasibility": infeas,
                        "eps": state.eps, "best_feasible_tf": best[0]})
        if deadline is not None and time.monotonic() > deadline:
            stopped = True
            break
    if best[1] is None:
        return _result(man, state.x * s, STATUS_BUDGET if stopped else STATUS_FAILED,
                       "no feasible point found within the iterations/time budget", t0, feas_tol,
                       evaluations=evals, phases=history)
    status = STATUS_BUDGET if stopped else STATUS_FEASIBLE
    return _result(man, best[1] * s, status, "best feasible point of the last MMT phases", t0, feas_tol,
                   evaluations=evals, phases=history)


def _pad_alpha(alpha: np.ndarray, N_from: int, N_to: int, M_to: int) -> np.ndarray:
    """Carry α to another sample count (x = α/√N is N-independent) and basis size (zero pad)."""
    x = np.asarray(alpha, float).reshape(3, -1) / np.sqrt(N_from)
    out = np.zeros((3, M_to))
    m = min(M_to, x.shape[1])
    out[:, :m] = x[:, :m]
    return out * np.sqrt(N_to)


def solve_min_time(man: SmoothManeuver, *, basis_sizes: tuple = (4, 8), starts: int = 6, seed: int = 0,
                   start_scale: float = 0.5, explore_N: int = 60, explore_maxiter: int = 60,
                   explore_total_iterations: int = 150,
                   end_ratio: float = 1e-3, alpha0: np.ndarray | None = None, time_budget: float | None = None,
                   deadline: float | None = None, feas_tol: float = 1e-6, budget_tol: float = 5e-4) -> SlepianResult:
    """Ours: minimum t_f, exactly (epigraph SQP with exact gradients), with global search.

    1. Multistart on a coarse grid (``explore_N`` samples, same N·W so the same Slepian
       functions; x = α/√N carries over): ``alpha0`` if given, ``starts`` seeded Gaussian starts
       x ~ N(0, start_scale²), then α = 0 (eigenaxis-like); each a local epigraph solve, runaway
       starts are cut.
    2. Continuation of the best coarse solution over ``basis_sizes`` (zero-padded α), still coarse.
    3. Refinement at the full N with the final basis size: t_f and α follow the issue's
       conventions exactly. ``end_ratio`` keeps torque and rate ≈ 0 at both ends for M > 4.
    With a deadline (``time_budget`` or ``deadline``) stage 1 stops at half the budget and stage
    2 at three quarters, so the refinement always gets its turn.
    ``man`` fixes N and W (its own M is ignored in favour of ``basis_sizes``).
    """
    t0 = time.perf_counter()
    end = None if time_budget is None else time.monotonic() + time_budget
    if deadline is not None:
        end = deadline if end is None else min(end, deadline)
    N = man.N
    Nc = min(explore_N, N)
    M0 = basis_sizes[0]
    coarse = man.resized(N=Nc, M=M0)
    rng = np.random.default_rng(seed)
    candidates = [] if alpha0 is None else [_pad_alpha(alpha0, N, Nc, M0)]
    candidates += [rng.normal(size=(3, M0)) * start_scale * np.sqrt(Nc) for _ in range(starts)]
    candidates.append(np.zeros((3, M0)))
    explored = []
    best = None
    start_clock = time.monotonic()

    def share(fraction):   # stage deadlines: exploration ≤ 50 %, continuation ≤ 75 % of the budget
        return None if end is None else start_clock + fraction * (end - start_clock)

    for a0 in candidates:
        if end is not None and time.monotonic() > share(0.5):
            break
        limit = 50.0 * best.stats["peak"] if best is not None else np.inf
        r = solve_min_time_local(coarse, a0, maxiter=explore_maxiter, feas_tol=feas_tol, deadline=share(0.5),
                                 peak_limit=limit, end_ratio=end_ratio if M0 > PAPER_M else None,
                                 max_total_iterations=explore_total_iterations)
        r.stats["peak"] = evaluate(coarse, r.alpha).peak_torque
        explored.append(round(r.tf, 6) if r.feasible else None)
        if r.feasible and (best is None or r.tf < best.tf):
            best = r
    if best is None:
        return _result(man.resized(M=M0), np.zeros((3, M0)), STATUS_BUDGET if end and time.monotonic() > end
                       else STATUS_FAILED, "no feasible start found by the coarse multistart", t0, feas_tol,
                       explored=explored)
    alpha, Mc, path = best.alpha, M0, [("coarse", M0, best.tf)]
    for M in basis_sizes[1:]:
        if end is not None and time.monotonic() > share(0.75):
            break
        r = solve_min_time_local(coarse.resized(M=M), _pad_alpha(alpha, Nc, Nc, M), feas_tol=feas_tol,
                                 deadline=share(0.75), end_ratio=end_ratio)
        if r.feasible:
            alpha, Mc = r.alpha, M
            path.append(("coarse", M, r.tf))
    fine = man.resized(M=Mc)
    start = _pad_alpha(alpha, Nc, N, Mc)
    r = solve_min_time_local(fine, start, feas_tol=feas_tol, deadline=end,
                             end_ratio=end_ratio if Mc > PAPER_M else None)
    path.append(("fine", Mc, r.tf))
    stats = dict(explored=explored, continuation=path, iterations=r.stats.get("iterations"))
    if r.feasible:
        return _result(fine, r.alpha, r.status, r.message, t0, feas_tol, **stats)
    # Refinement unfinished (deadline) or failed: the best of its last iterate and the coarse solution
    # carried over, accepted if it meets the constraints to ``budget_tol`` (well inside the
    # verification's bounds and the cone margin).
    status = STATUS_BUDGET if end is not None and time.monotonic() > end else STATUS_FAILED
    fallback = min((_result(fine, a, status, r.message, t0, budget_tol, **stats) for a in (r.alpha, start)),
                   key=lambda res: (not res.feasible, res.tf))
    if fallback.feasible:
        fallback.message = f"refinement unfinished ({r.message}); constraints met to {budget_tol:g}"
    return fallback


# ---------------------------------------------------------------------------------------------
# Planner entry point
# ---------------------------------------------------------------------------------------------

_METHOD_OPTIONS = {
    "slepian_minimum_time": {"starts", "seed", "start_scale", "explore_N", "explore_maxiter",
                             "explore_total_iterations", "end_ratio", "time_budget", "feas_tol", "budget_tol"},
    "mssa": {"maxiter", "ftol", "feas_tol", "restarts", "seed", "start_scale"},
    "dfsp": {"phases", "iterations", "time_budget", "eps0", "q", "gamma", "theta", "delta", "p", "step0",
             "step_min", "feas_tol", "seed_with_mssa"},
}
DEFAULT_M = {"slepian_minimum_time": 8, "mssa": PAPER_M, "dfsp": PAPER_M}


def _validate(method: str, M: int | None, N: int, W: float, cone_margin: float, options: dict) -> int:
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if not isinstance(N, (int, np.integer)) or not 20 <= N <= 20_000:
        raise ValueError(f"N (samples) must be an integer in [20, 20000], got {N!r}")
    if not (isinstance(W, (int, float)) and 0.0 < W < 0.5 and N * W >= 1.0):
        raise ValueError(f"W (half-bandwidth) must be in (0, 0.5) with N·W ≥ 1, got {W!r} for N = {N}")
    M = DEFAULT_M[method] if M is None else M
    max_M = int(np.floor(2 * N * W))
    if not isinstance(M, (int, np.integer)) or not 1 <= M <= max_M:
        raise ValueError(f"M (basis size) must be an integer in [1, 2·N·W = {max_M}] (well-concentrated "
                         f"Slepian sequences), got {M!r}")
    if not (isinstance(cone_margin, (int, float)) and 0.0 <= cone_margin < 0.2):
        raise ValueError(f"cone_margin must be in [0, 0.2) rad, got {cone_margin!r}")
    unknown = set(options) - _METHOD_OPTIONS[method]
    if unknown:
        raise ValueError(f"option(s) {sorted(unknown)} not understood by method {method!r} "
                         f"(valid: {sorted(_METHOD_OPTIONS[method])})")
    return int(M)


def _reject_cone_endpoints(problem: ManeuverProblem) -> str | None:
    """A sentence naming the cone that contains the start or goal sensor direction, else None."""
    r = np.asarray(problem.sensor_axis, float)
    r = r / np.linalg.norm(r)
    ends = {"start": rot.dcm(problem.q_initial) @ r}
    if problem.sensor_target is not None:
        ends["goal"] = np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
    else:
        ends["goal"] = rot.dcm(problem.q_final) @ r
    for which, b in ends.items():
        for i, c in enumerate(problem.cones):
            margin = float(np.arccos(np.clip(b @ c.direction, -1.0, 1.0)) - c.half_angle)
            if margin < 0.0:
                name = c.name or f"#{i}"
                return (f"infeasible request: the {which} sensor direction is inside keep-out cone {name} "
                        f"({np.degrees(-margin):.2f} deg inside its {np.degrees(c.half_angle):.1f} deg half-angle)")
    return None


def _empty_plan(method: str, status: str, message: str, seconds: float, stats: dict) -> ManeuverPlan:
    return ManeuverPlan(method=method, t=np.zeros(0), torque=np.zeros((0, 3)), q=np.zeros((0, 4)),
                        omega=np.zeros((0, 3)), interpolation="zoh", status=status, message=message,
                        solve_seconds=seconds, stats=stats)


def physical_profile(man: SmoothManeuver, alpha: np.ndarray, spacecraft: Spacecraft | None = None) -> dict:
    """Physical-time plan of α: knots t_k = τ_k t_f (K = N+1) and ZOH body torque
    T_k = T*(τ_k)/t_f² (the last one zero, T_k held on [t_k, t_{k+1})).

    The q/ω references at the knots are the rigid-body response to exactly this torque from rest
    (one RK4 step per sample, :func:`att_sim.dynamics.simulate_profile`), so the controller tracks
    what the torque does; the ZOH model attitudes R_k lead it by about half a sample.
    Without ``spacecraft`` the references are the model's R_k and ω*(τ_{k−1})/t_f.
    """
    ev = evaluate(man, alpha)
    tf = man.tf_from_peak(ev.peak_torque)
    N = man.N
    t = np.arange(N + 1) / N * tf
    torque = np.zeros((N + 1, 3))
    torque[:N] = ev.torque * man.inertia_scale / tf**2
    if spacecraft is None:
        q = rot.from_dcm(ev.R)
        omega = np.zeros((N + 1, 3))
        omega[1:] = ev.omega / tf
    else:
        x0 = dyn.initial_state(spacecraft, rot.from_dcm(man.R_initial))
        traj = dyn.simulate_profile(spacecraft, x0, t, torque, kind="body_torque", interpolation="zoh",
                                    max_step=tf / N)
        q, omega = traj.q, traj.omega
    return {"t": t, "torque": torque, "q": q, "omega": omega, "tf": tf, "evaluation": ev}


def plan_slepian(problem: ManeuverProblem, method: str = DEFAULT_METHOD, M: int | None = None,
                 N: int = PAPER_N, W: float = PAPER_W, cone_margin: float = 1e-3, **options) -> ManeuverPlan:
    """Smooth rest-to-rest keep-out-cone plan (Slepian rate basis), body torque with ZOH.

    ``method``: 'slepian_minimum_time' (ours, default; M is the final basis size of the
    continuation 4 → … → M, default 8), 'mssa' (Celani–Lucarelli) or 'dfsp' (Celani–Bruni), both
    with the paper basis M = 4 by default. N, W: DPSS length and half-bandwidth (paper 500,
    0.015). ``cone_margin`` (rad) is kept from every cone by the optimiser so that the truth
    integration between samples stays outside. Other options go to the method's solver
    (:func:`solve_min_time`, :func:`solve_mssa`, :func:`solve_dfsp`); unknown ones raise
    ValueError. Refuses (STATUS_FAILED) when the start or goal sensor direction is in a cone.
    Honours ``problem.deadline`` (best feasible plan so far, STATUS_BUDGET).
    """
    t0 = time.perf_counter()
    M = _validate(method, M, N, W, cone_margin, options)
    base = {"method_variant": method, "M": M, "N": N, "W": W}
    reason = _reject_cone_endpoints(problem)
    if reason:
        return _empty_plan(method, STATUS_FAILED, reason, time.perf_counter() - t0, base)
    tmax = problem.spacecraft.body_torque_max
    if not (np.isfinite(tmax) and tmax > 0):
        return _empty_plan(method, STATUS_FAILED, "spacecraft.body_torque_max must be finite and positive "
                           "(T̄ sets the maneuver time)", time.perf_counter() - t0, base)
    man = build_maneuver(problem, M=M if method != "slepian_minimum_time" else PAPER_M, N=N, W=W,
                         cone_margin=cone_margin)
    deadline = problem.deadline
    if method == "slepian_minimum_time":
        sizes = tuple(sorted({min(PAPER_M, M), *range(PAPER_M * 2, M, PAPER_M), M}))
        res = solve_min_time(man, basis_sizes=sizes, deadline=deadline, **options)
    elif method == "mssa":
        res = solve_mssa(man, deadline=deadline, **options)
    else:
        opts = dict(options)
        alpha0 = None
        if opts.pop("seed_with_mssa", True):
            seed_res = solve_mssa(man, deadline=deadline, restarts=4)
            alpha0 = seed_res.alpha if seed_res.feasible else None
        res = solve_dfsp(man, alpha0, deadline=deadline, **opts)
    final_man = man.resized(M=res.alpha.shape[1])
    stats = dict(base, M=int(res.alpha.shape[1]), alpha=res.alpha.tolist(), tf=res.tf, feasible=res.feasible,
                 **{k: v for k, v in res.stats.items()})
    seconds = time.perf_counter() - t0
    if not res.feasible:
        status = STATUS_BUDGET if res.status == STATUS_BUDGET else STATUS_FAILED
        return _empty_plan(method, STATUS_FAILED, f"no feasible smooth plan ({res.message}; status {status})",
                           seconds, stats)
    if final_man.sensor_target is not None:
        b_end = evaluate(final_man, res.alpha).R[-1] @ final_man.sensor_axis
        if b_end @ final_man.sensor_target < 0.0:   # the 2-row residual also vanishes at the antipode
            return _empty_plan(method, STATUS_FAILED, "converged to the antipode of sensor_target",
                               seconds, stats)
    prof = physical_profile(final_man, res.alpha, problem.spacecraft)
    return ManeuverPlan(method=method, t=prof["t"], torque=prof["torque"], q=prof["q"], omega=prof["omega"],
                        interpolation="zoh", status=res.status, message=res.message, solve_seconds=seconds,
                        stats=stats)
