"""Smooth rest-to-rest keep-out-cone maneuvers on SO(3) with a Slepian (DPSS) rate basis.

In normalised time τ = t/t_f ∈ [0, 1] the body rate is ω*_j(τ_ℓ) = Σ_k α_jk v_k(τ_ℓ), with v_k the
first M discrete prolate spheroidal sequences of length N and half-bandwidth W (unit energy,
``scipy.signal.windows.dpss(N, N W, Kmax=M)``). With the conventions of Celani & Bruni
(2021) and Celani & Lucarelli, on τ_ℓ = (ℓ−1)/N, ℓ = 1..N, Δτ = 1/N:

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

Zones (:mod:`att_planner.zones`): zone z with body sensor axis s_z, sign σ_z (+1 keep-out,
−1 keep-in), axis a_z(t) and half-angle θ_z(t) is the row c_kz = σ_z (a_z(t_k)·R_k s_z − cos(θ_z(t_k) +
σ_z m)) ≤ 0 at the physical time t_k = τ_k t_f. A cone is a static keep-out zone (no t_f in its row:
cone-only plans are exactly those of Celani & Bruni's cone rows). With moving zones the rows couple to t_f, the
minimum-time program's epigraph variable in other units (t_f = sqrt(J_s s/T̄)), through the exact
column ∂c/∂t_f = σ τ_k (ȧ·R_k s + sin θ̃ θ̇) (:mod:`.model`, :class:`.sqp._Rows`); MSSA holds t_f per
solve and iterates it to its fixed point, DFSP takes each point's own t_f.

The final-attitude equality tr(R_fᵀ R_{N+1}) = 3 of the papers has a vanishing gradient at its
solution (it is a maximum of the trace), which breaks the constraint qualification of any SQP/IP
solver. The solvers here use the equivalent, well-conditioned 3-vector vee(log(R_fᵀ R_{N+1})) = 0
(exact Jacobian through the inverse left Jacobian); the residual 3 − tr(...) is reported.

Modules: :mod:`.model` (basis, discretisation, exact derivatives), :mod:`.sqp` (SLSQP on a working
set of rows: MSSA and one local minimum-time solve), :mod:`.dfsp`, :mod:`.planner` (the global
minimum-time search and :func:`plan_slepian`). Three methods (their solvers return a
:class:`~.sqp.SlepianResult`):

* :func:`solve_mssa` — Celani–Lucarelli: min ½ Σ α² s.t. final attitude and cones, SLSQP.
* :func:`solve_dfsp` — Celani–Bruni: derivative-free sequential penalty (Liuzzi–Lucidi–Sciandrone
  2010) on t_f, alternating MMT (min t_f) and MSSA (min Σα²) phases.
* :func:`solve_min_time` — ours: min s s.t. −s ≤ T*_jℓ ≤ s, final attitude and cones, exact
  gradients (SLSQP on a working set of rows), seeded multistart on a coarse grid, continuation
  over basis sizes M = 4 → 8 (→ 12) with the ends kept smooth, refinement at the full N.

:func:`plan_slepian` turns a :class:`ManeuverProblem` into a :class:`~att_msgs_py.types.Plan`
(physical time, ZOH body torque); the published cases are in :mod:`att_planner.reference.celani_bruni`.
"""
from att_planner.methods.slepian.dfsp import solve_dfsp
from att_planner.methods.slepian.model import (
                                               DEFAULT_METHOD,
                                               METHODS,
                                               PAPER_M,
                                               PAPER_N,
                                               PAPER_W,
                                               SmoothManeuver,
                                               build_maneuver,
                                               evaluate,
                                               slepian_basis,
                                               trace_residual,
)
from att_planner.methods.slepian.planner import physical_profile, plan_slepian, solve_min_time
from att_planner.methods.slepian.sqp import SlepianResult, solve_mssa

__all__ = ["DEFAULT_METHOD", "METHODS", "PAPER_M", "PAPER_N", "PAPER_W", "SlepianResult", "SmoothManeuver",
           "build_maneuver", "evaluate", "physical_profile", "plan_slepian", "slepian_basis", "solve_dfsp",
           "solve_min_time", "solve_mssa", "trace_residual"]
