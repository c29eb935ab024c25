"""The Slepian planner entry point: our global minimum-time search and :func:`plan_slepian`."""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from att_msgs_py.types import ControlKind, Interpolation, Plan, Status
from att_planner.cones import blocked_endpoint
from att_planner.methods.graph_smooth import plan_graph_smooth
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
)
from att_planner.methods.slepian.sqp import SlepianResult, slepian_result, solve_min_time_local, solve_mssa
from att_planner.problem import ManeuverProblem
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

DEFAULT_M = {"slepian_minimum_time": 8, "mssa": PAPER_M, "dfsp": PAPER_M}
EXPLORE_N = 60          # samples of the coarse grid of the minimum-time multistart


def option_problem(options: dict) -> str | None:
    """Why the Slepian ``options`` (M, N, W and ``method``, defaults filled in) cannot run, or None:
    the basis must hold at least one well-concentrated sequence (N·W ≥ 1) and the M requested
    (M ≤ 2·N·W, the Shannon number)."""
    M = options.get("M", DEFAULT_M[options["method"]])
    N, W = options.get("N", PAPER_N), options.get("W", PAPER_W)
    if N * W < 1.0:
        return f"N (samples) · W (half-bandwidth) = {N * W:g} is below 1: no well-concentrated Slepian sequence"
    if M > np.floor(2 * N * W):
        return (f"M (basis size) = {M} exceeds 2·N·W = {2 * N * W:g}, the number of well-concentrated "
                "Slepian sequences")
    return None


def _pad_alpha(alpha: np.ndarray, N_from: int, N_to: int, M_to: int) -> np.ndarray:
    """Carry α to another sample count (x = α/√N is N-independent) and basis size (zero pad)."""
    x = np.asarray(alpha, float).reshape(3, -1) / np.sqrt(N_from)
    out = np.zeros((3, M_to))
    m = min(M_to, x.shape[1])
    out[:, :m] = x[:, :m]
    return out * np.sqrt(N_to)


def plan_alpha(man: SmoothManeuver, plan: Plan) -> np.ndarray:
    """α (3, M) whose rates are closest to a plan's (least squares: the basis is orthonormal):
    ω*(τ) = t_f ω(τ t_f) at the middle of each of the N samples."""
    tau = (np.arange(man.N) + 0.5) / man.N * plan.duration
    w = np.stack([np.interp(tau, plan.t, plan.omega[:, j]) for j in range(3)], axis=-1) * plan.duration
    return (man.basis.T @ w).T


def solve_min_time(man: SmoothManeuver, *, basis_sizes: tuple = (4, 8), starts: int = 6, seed: int = 0,
                   start_scale: float = 0.5, explore_N: int = EXPLORE_N, explore_maxiter: int = 60,
                   explore_total_iterations: int = 150,
                   end_ratio: float = 1e-3, alpha0: np.ndarray | None = None, time_budget: float | None = None,
                   deadline: float | None = None, feas_tol: float = 1e-6, budget_tol: float = 5e-4,
                   seeds: tuple = ()) -> SlepianResult:
    """Ours: minimum t_f, exactly (epigraph SQP with exact gradients), with global search.

    1. Multistart on a coarse grid (``explore_N`` samples, same N·W so the same Slepian
       functions; x = α/√N carries over): ``alpha0`` if given, ``starts`` seeded Gaussian starts
       x ~ N(0, start_scale²), then α = 0 (eigenaxis-like); each a local epigraph solve, runaway
       starts are cut.
    2. Continuation of the best coarse solution over ``basis_sizes`` (zero-padded α), still coarse.
    3. Refinement at the full N with the final basis size: t_f and α follow the
       conventions of Celani & Bruni (2021) exactly. ``end_ratio`` keeps torque and rate ≈ 0 at both ends for M > 4.
    With a deadline (``time_budget`` or ``deadline``) stage 1 stops at half the budget and stage
    2 at three quarters, so the refinement always gets its turn.
    ``seeds``: α (3, M ≤ the final basis size, at N) of other plans (:func:`plan_alpha`), each solved
    first on the coarse grid with the final basis; the quickest of them and of the continuation is
    refined, so a feasible seed gives a plan when the multistart finds no feasible start.
    ``man`` fixes N and W (its own M is ignored in favour of ``basis_sizes``).
    """
    t0 = time.perf_counter()
    end = None if time_budget is None else time.monotonic() + time_budget
    if deadline is not None:
        end = deadline if end is None else min(end, deadline)
    N = man.N
    # the coarse grid keeps N·W (the same continuous functions) and needs W < 1/2 there: N_c > 2·N·W
    Nc = min(N, max(explore_N, int(np.ceil(4 * N * man.half_bandwidth))))
    M0 = basis_sizes[0]
    coarse = man.resized(N=Nc, M=M0)
    rng = np.random.default_rng(seed)
    candidates = [] if alpha0 is None else [_pad_alpha(alpha0, N, Nc, M0)]
    candidates += [rng.normal(size=(3, M0)) * start_scale * np.sqrt(Nc) for _ in range(starts)]
    candidates.append(np.zeros((3, M0)))
    start_clock = time.monotonic()

    def share(fraction):   # stage deadlines: exploration ≤ 50 %, continuation ≤ 75 % of the budget
        return None if end is None else start_clock + fraction * (end - start_clock)

    seeded = _seeded(coarse.resized(M=basis_sizes[-1]), [_pad_alpha(a, N, Nc, basis_sizes[-1]) for a in seeds],
                     share(0.5), feas_tol, end_ratio)
    best, closest, explored = _multistart(coarse, candidates, share(0.5), maxiter=explore_maxiter,
                                          total_iterations=explore_total_iterations, feas_tol=feas_tol,
                                          end_ratio=end_ratio if M0 > PAPER_M else None)
    if best is None and man.moving and closest is not None:
        best = closest    # the paper basis barely moves near the ends: a larger one may outrun a zone there
    if best is None and seeded is not None:
        best, basis_sizes = seeded, basis_sizes[-1:]
    if best is None:
        status = Status.BUDGET_EXPIRED if end and time.monotonic() > end else Status.FAILED
        return slepian_result(man.resized(M=M0), np.zeros((3, M0)), status,
                              "no feasible start found by the coarse multistart", t0, feas_tol, explored=explored)
    alpha, Mc, tf_c, path = _continuation(coarse, best, basis_sizes[1:], share(0.75), feas_tol, end_ratio)
    if seeded is not None and seeded is not best and (Mc < seeded.alpha.shape[1] or seeded.tf < tf_c):
        alpha, Mc, tf_c = seeded.alpha, seeded.alpha.shape[1], seeded.tf
        path.append(("coarse, seeded", Mc, tf_c))
    fine = man.resized(M=Mc)
    start = _pad_alpha(alpha, Nc, N, Mc)
    r = solve_min_time_local(fine, start, feas_tol=feas_tol, deadline=end,
                             end_ratio=end_ratio if Mc > PAPER_M else None)
    path.append(("fine", Mc, r.tf))
    stats = dict(explored=explored, continuation=path, iterations=r.stats.get("iterations"))
    if r.feasible:
        return slepian_result(fine, r.alpha, r.status, r.message, t0, feas_tol, tf=r.tf, **stats)
    # Refinement unfinished (deadline) or failed: the best of its last iterate and the coarse solution
    # carried over, accepted if it meets the constraints to ``budget_tol`` (well inside the
    # verification's bounds and the cone margin).
    status = Status.BUDGET_EXPIRED if end is not None and time.monotonic() > end else Status.FAILED
    fallback = min((slepian_result(fine, a, status, r.message, t0, budget_tol, tf=tf, **stats)
                    for a, tf in ((r.alpha, r.tf), (start, tf_c))),
                   key=lambda res: (not res.feasible, res.tf))
    if fallback.feasible:
        fallback.message = f"refinement unfinished ({r.message}); constraints met to {budget_tol:g}"
    return fallback


def _continuation(coarse: SmoothManeuver, best: SlepianResult, sizes: tuple, deadline: float | None,
                  feas_tol: float, end_ratio: float):
    """Stage 2 of :func:`solve_min_time`: ``best`` carried over the basis ``sizes`` on the coarse grid
    until ``deadline``; ``(α, M, t_f, path)`` of the last feasible solve."""
    Mc = best.alpha.shape[1]
    alpha, tf_c, path = best.alpha, best.tf, [("coarse", Mc, best.tf)]
    for M in sizes:
        if deadline is not None and time.monotonic() > deadline:
            break
        r = solve_min_time_local(coarse.resized(M=M), _pad_alpha(alpha, coarse.N, coarse.N, M), feas_tol=feas_tol,
                                 deadline=deadline, end_ratio=end_ratio)
        if r.feasible:
            alpha, Mc, tf_c = r.alpha, M, r.tf
            path.append(("coarse", M, r.tf))
    return alpha, Mc, tf_c, path


def _seeded(coarse: SmoothManeuver, seeds: list, deadline: float | None, feas_tol: float,
            end_ratio: float) -> SlepianResult | None:
    """The quickest feasible local solve from ``seeds`` (α on ``coarse``), or None."""
    best = None
    for a0 in seeds:
        r = solve_min_time_local(coarse, a0, feas_tol=feas_tol, deadline=deadline,
                                 end_ratio=end_ratio if coarse.M > PAPER_M else None)
        if r.feasible and (best is None or r.tf < best.tf):
            best = r
    return best


def _multistart(coarse: SmoothManeuver, candidates: list, deadline: float | None, *, maxiter: int,
                total_iterations: int, feas_tol: float, end_ratio: float | None):
    """Stage 1 of :func:`solve_min_time`: a local epigraph solve from each start until ``deadline``
    (runaway starts, 50 × the best peak torque, are cut). Returns the fastest feasible result, the
    least-violating infeasible one and each start's t_f (None: infeasible)."""
    best = closest = None
    explored = []
    for a0 in candidates:
        if deadline is not None and time.monotonic() > deadline:
            break
        limit = 50.0 * best.stats["peak"] if best is not None else np.inf
        r = solve_min_time_local(coarse, a0, maxiter=maxiter, feas_tol=feas_tol, deadline=deadline,
                                 peak_limit=limit, end_ratio=end_ratio, max_total_iterations=total_iterations)
        r.stats["peak"] = evaluate(coarse, r.alpha).peak_torque
        explored.append(round(r.tf, 6) if r.feasible else None)
        if r.feasible and (best is None or r.tf < best.tf):
            best = r
        if not r.feasible and (closest is None or r.stats["violation"] < closest.stats["violation"]):
            closest = r
    return best, closest, explored


def seeded_min_time(man: SmoothManeuver, frozen: SmoothManeuver, *, basis_sizes: tuple = (4, 8),
                    deadline: float | None = None, feas_tol: float = 1e-6, end_ratio: float = 1e-3,
                    **options) -> SlepianResult | None:
    """Moving zones: the minimum time against the zones frozen at t = 0 (``frozen``, the static
    search :func:`solve_min_time`, at most half the time left), then ONE exact local solve of the
    moving program (zone rows at τ_k t_f, the t_f column) from it at the full N; None when the
    frozen search finds nothing. The frozen plan only seeds: the result meets the moving zones.
    The moving multistart alone meets a harder landscape (a random path wanders into a zone that
    moved there), and finds fewer feasible starts."""
    half = None if deadline is None else time.monotonic() + 0.5 * max(deadline - time.monotonic(), 0.0)
    seed = solve_min_time(frozen, basis_sizes=basis_sizes, deadline=half, feas_tol=feas_tol, end_ratio=end_ratio,
                          **options)
    if not seed.feasible:
        return None
    M = seed.alpha.shape[1]
    r = solve_min_time_local(man.resized(M=M), seed.alpha, feas_tol=feas_tol, deadline=deadline,
                             end_ratio=end_ratio if M > PAPER_M else None)
    r.stats.update(seed_tf=seed.tf, seed_seconds=seed.wall_time)
    return r


def physical_profile(man: SmoothManeuver, alpha: np.ndarray, spacecraft: Spacecraft | None = None,
                     tf: float | None = None) -> dict:
    """Physical-time plan of α: knots t_k = τ_k t_f (K = N+1) and ZOH body torque
    T_k = T*(τ_k)/t_f² (the last one zero, T_k held on [t_k, t_{k+1})). t_f: ``tf`` (the result's,
    never below the torque-limited one) or sqrt(J_s T*/T̄).

    The q/ω references at the knots are the rigid-body response to exactly this torque from rest
    (one RK4 step per sample, :func:`att_sim.models.dynamics.simulate_profile`), so the controller tracks
    what the torque does; the ZOH model attitudes R_k lead it by about half a sample.
    Without ``spacecraft`` the references are the model's R_k and ω*(τ_{k−1})/t_f.
    """
    ev = evaluate(man, alpha, tf=tf)
    tf = man.tf_from_peak(ev.peak_torque) if tf is None else float(tf)
    N = man.N
    t = np.arange(N + 1) / N * tf
    torque = np.zeros((N + 1, 3))
    torque[:N] = ev.torque * man.inertia_scale / tf**2
    if spacecraft is None:
        q = rot.from_dcm_NB(ev.R)
        omega = np.zeros((N + 1, 3))
        omega[1:] = ev.omega / tf
    else:
        x0 = dyn.initial_state(spacecraft, rot.from_dcm_NB(man.R_initial))
        traj = dyn.simulate_profile(spacecraft, x0, t, torque, kind=ControlKind.BODY_TORQUE,
                                    interpolation=Interpolation.ZOH, max_step=tf / N)
        q, omega = traj.q_BN, traj.omega_BN_B
    return {"t": t, "torque": torque, "q": q, "omega": omega, "tf": tf, "evaluation": ev}


def plan_slepian(problem: ManeuverProblem, method: str = DEFAULT_METHOD, M: int | None = None,
                 N: int = PAPER_N, W: float = PAPER_W, cone_margin: float = 1e-3, warm_starts: tuple = (),
                 **options) -> Plan:
    """Smooth rest-to-rest keep-out-cone plan (Slepian rate basis), body torque with ZOH.

    ``method``: 'slepian_minimum_time' (ours, default; M is the final basis size of the
    continuation 4 → … → M, default 8), 'mssa' (Celani–Lucarelli) or 'dfsp' (Celani–Bruni), both
    with the paper basis M = 4 by default. N, W: DPSS length and half-bandwidth (paper 500,
    0.015). ``cone_margin`` (rad) is kept from every cone by the optimiser so that the truth
    integration between samples stays outside. Other options go to the method's solver
    (:func:`solve_min_time`, :func:`solve_mssa`, :func:`solve_dfsp`). The registry
    (:mod:`att_planner.methods`) holds the ranges of M, N and W and the combinations that cannot run
    (:func:`option_problem`). Refuses (FAILED) when the start or goal sensor direction is in a cone.
    Honours ``problem.deadline`` (best feasible plan so far, BUDGET_EXPIRED).
    """
    t0 = time.perf_counter()
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    M = DEFAULT_M[method] if M is None else int(M)
    base = {"method_variant": method, "M": M, "N": N, "W": W}
    reason = blocked_endpoint(problem)
    if not reason and not (np.isfinite(problem.spacecraft.body_torque_max) and problem.spacecraft.body_torque_max > 0):
        reason = "spacecraft.body_torque_max must be finite and positive (T̄ sets the maneuver time)"
    if reason:
        return Plan(method=method, status=Status.FAILED, message=reason, wall_time=time.perf_counter() - t0,
                    stats=base)
    man = build_maneuver(problem, M=M if method != "slepian_minimum_time" else PAPER_M, N=N, W=W,
                         cone_margin=cone_margin)
    deadline = problem.deadline
    if method == "slepian_minimum_time":
        sizes = tuple(sorted({min(PAPER_M, M), *range(PAPER_M * 2, M, PAPER_M), M}))
        res = None
        if man.moving:
            frozen = replace(problem, cones=[], zones=problem.zone_sky().frozen_zones(), sky=None)
            res = seeded_min_time(man, build_maneuver(frozen, M=PAPER_M, N=N, W=W, cone_margin=cone_margin),
                                  basis_sizes=sizes, deadline=deadline, **options)
        seeds = tuple(plan_alpha(man.resized(M=M), p) for p in warm_starts if p.success and len(p.t) > 1)
        if res is None or not res.feasible:
            res = solve_min_time(man, basis_sizes=sizes, deadline=deadline, seeds=seeds, **options)
        if not res.feasible and not seeds and (deadline is None or time.monotonic() < deadline):
            first = plan_graph_smooth(problem)      # no feasible start: the constructive plan as a seed
            if first.success:
                res = solve_min_time(man, basis_sizes=sizes, deadline=deadline,
                                     seeds=(plan_alpha(man.resized(M=M), first),), **{**options, "starts": 0})
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
                 **res.stats)
    outcome = dict(method=method, nit=res.nit, nfev=res.nfev, stats=stats)
    if not res.feasible:
        status = Status.BUDGET_EXPIRED if res.status == Status.BUDGET_EXPIRED else Status.FAILED
        return Plan(status=status, message=f"no feasible smooth plan ({res.message}; status {status})",
                    wall_time=time.perf_counter() - t0, **outcome)
    if final_man.sensor_target is not None:
        b_end = evaluate(final_man, res.alpha).R[-1] @ final_man.sensor_axis
        if b_end @ final_man.sensor_target < 0.0:   # the 2-row residual also vanishes at the antipode
            return Plan(status=Status.FAILED, message="converged to the antipode of sensor_target",
                        wall_time=time.perf_counter() - t0, **outcome)
    prof = physical_profile(final_man, res.alpha, problem.spacecraft, tf=res.tf)
    return Plan(t=prof["t"], torque=prof["torque"], q=prof["q"], omega=prof["omega"], status=res.status,
                message=res.message, wall_time=time.perf_counter() - t0, **outcome)
