"""Minimum time with a C¹ torque: the time-optimal collocation of :mod:`.planner` with the
torque a smooth state instead of a bang-bang control.

Normalised as in :mod:`.planner` (time unit ``τ_u = sqrt(J0/T̄)``, torque ``u = T/T̄``), the state is
``x = [q, ω̃, u, u̇]`` and the control the torque's second derivative ``a = ü``, held over each
mesh interval, with ``|a_j| ≤ a_max`` (``torque_accel``, T̄ per τ_u²)::

    q̇ = ½ q ⊗ [ω̃, 0] + ½ (1 − |q|²) q,   J̃ ω̃̇ = u − ω̃ × J̃ ω̃,   (u)˙ = u̇,   (u̇)˙ = a,   |u_j| ≤ 1,
    ω̃ = u = u̇ = 0 at both ends,  the final attitude and every zone as in :mod:`.planner`.

A moving goal (``problem.goal_motion``) replaces the end at rest by the goal's attitude and rate at
t_f (the terminal condition of :mod:`.planner`, on the goal's series) and the torque at t_f by the
one that tracks the goal, ``J̃ ω̃̇_g + ω̃_g × J̃ ω̃_g`` (the derivative of the rate's series), so the
controller's feedforward continues without a step at the hand-over
(:func:`.model.ties_end_torque`: when that torque stays within T̄ over the goal's window; near a
ground pass of a slow spacecraft it does not, and the end torque is left free within the bound).
Such a plan is not slowed down to keep T̄ between the collocation points (:func:`smooth_plan`):
where its torque bulges past T̄ the NLP is solved again with ``|u|`` bounded by
``1/(bulge (1 + TORQUE_ROOM))²``.

So the torque is piecewise quadratic with a continuous derivative (C¹) and it and its rate vanish at
both ends; ``a_max`` bounds how fast it swings (from −T̄ to +T̄ at rest in ``2 sqrt(2/a_max)`` τ_u): as
it grows the plan approaches the bang-bang time-optimal one. Hermite–Simpson integrates the
torque's chain of integrators exactly, so the plan samples each interval's quadratic exactly
(:data:`SAMPLES_PER_INTERVAL` knots, linear interpolation between them). The NLP starts from the
given plans (``warm_starts``: the planner service passes its first plan) or, without them, from
:func:`att_planner.methods.graph_smooth.plan_graph_smooth`'s plan; the durations of the intervals are
built once per shape (:func:`.model.transcription`, which holds the NLP of both). The solution is
integrated through the prediction model (:mod:`att_planner.verification`); where the dense grid
enters a zone the mesh is bisected and the NLP solved again (:data:`REFINE_ROUNDS` times at most),
and all of it when a moving goal's arrival misses its tolerance.
Anytime: when the deadline stops IPOPT before it converges, the iterate of least t_f that met the
constraints (:data:`.anytime.INCUMBENT_VIOLATION`) becomes the plan, if it verifies (on
leo_observatory IPOPT reaches t_f within 0.2 % of its optimum in half its iterations, then polishes).
"""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from att_msgs_py.types import Interpolation, Plan, Status
from att_planner.cones import blocked_endpoint
from att_planner.methods.axis_rotations import no_torque_limit
from att_planner.methods.graph_smooth import plan_graph_smooth
from att_planner.methods.time_optimal import collocation as col
from att_planner.methods.time_optimal import mesh as meshes
from att_planner.methods.time_optimal.model import Scaling, _state_bounds, rigid_body_dynamics, scaling, transcription
from att_planner.methods.time_optimal.planner import CONVERGED_VIOLATION, _truth_violation_intervals
from att_planner.problem import ManeuverProblem
from att_planner.verification import TOLERANCES, measure, predict, rejection
from att_sim.models import rotations as rot

METHOD = "smooth_collocation"
DEFAULT_INTERVALS = 30
DEFAULT_TORQUE_ACCEL = 100.0      # T̄ per τ_u²: a full swing of the torque takes 0.28 τ_u
SAMPLES_PER_INTERVAL = 8          # plan knots per mesh interval
REFINE_ROUNDS = 3                 # mesh bisections where the truth enters a zone
LIMIT_RATIO = TOLERANCES.limit_ratio  # a torque peak above this fails the verification
TORQUE_ROOM = 2e-3                # a moving goal's bound on |u| is cut by twice the bulge and this much more


def expired_at(problem: ManeuverProblem) -> bool:
    """Whether the problem's deadline has passed."""
    return problem.deadline is not None and time.monotonic() > problem.deadline


def guess(plan: Plan, s: Scaling, phase: col.Phase) -> col.PhaseGuess:
    """The NLP's start from another method's plan: its attitudes, rates and torques (normalised), the
    torque's derivative by finite differences, no second derivative (a start from zero converged in
    fewer iterations than the finite differences on the cases of the speed benchmark)."""
    tn = np.asarray(plan.t, float) / s.tu
    u = np.asarray(plan.torque, float) / s.torque_max
    u_dot = np.gradient(u, tn, axis=0)

    def at(values, t):
        return np.stack([np.interp(t, tn, values[:, j]) for j in range(values.shape[1])], axis=-1)

    def state(t):
        return np.concatenate([rot.normalize(at(plan.q, t)), at(plan.omega, t) * s.tu, at(u, t), at(u_dot, t)],
                              axis=-1)

    return col.guess_from_functions(phase, float(tn[-1]), state, lambda t: np.zeros((len(t), 3)))


def smooth_plan(sol: col.PhaseSolution, s: Scaling, moving: bool = False) -> Plan:
    """The plan of a solution: each interval's torque quadratic sampled exactly at
    :data:`SAMPLES_PER_INTERVAL` knots, the Hermite interpolant's attitudes and rates. The NLP
    bounds ``|u| ≤ 1`` at the collocation points only; where a quadratic bulges past it in between,
    the plan is slowed by ``c = sqrt(max |u|)`` (times × c, torques / c², rates / c: the same path of
    the same rigid body from rest, within T̄; t_f × c). A plan onto a ``moving`` goal cannot be
    slowed (the goal would not wait): its last torque is kept (it hands over at that torque), its
    torque clipped to T̄ and its peak before the clip in ``stats['torque_peak']``:
    :func:`plan_smooth_collocation` solves such a plan again on a tighter bound."""
    mesh = sol.phase.mesh
    frac = np.arange(SAMPLES_PER_INTERVAL) / SAMPLES_PER_INTERVAL
    tau = np.append((mesh[:-1, None] + np.diff(mesh)[:, None] * frac[None]).ravel(), 1.0)
    k = np.minimum(np.arange(len(tau)) // SAMPLES_PER_INTERVAL, sol.phase.intervals - 1)
    dt = ((tau - mesh[k]) * sol.duration)[:, None]
    x = sol.state_at(tau)
    u = sol.x[k, 7:10] + sol.x[k, 10:] * dt + 0.5 * sol.u[k] * dt**2
    peak = float(np.abs(u).max())
    if moving:
        u = np.clip(u, -1.0, 1.0)
    else:
        u[-1] = 0.0
    c = 1.0 if moving else np.sqrt(max(1.0, float(np.abs(u).max())))
    return Plan(t=tau * sol.duration * s.tu * c, torque=u / c**2 * s.torque_max, q=rot.normalize(x[:, :4]),
                omega=x[:, 4:7] / (s.tu * c), interpolation=Interpolation.LINEAR, method=METHOD,
                stats={"slowed_by": c, "torque_peak": peak})


def _bound_torque(tr: col.Transcription, problem: ManeuverProblem, s: Scaling, bound: float) -> None:
    """``|u| ≤ bound`` (normalised torque) at every node of ``tr`` after the start."""
    lower, upper = (np.array(b, float) for b in _state_bounds(problem, s, smooth=True))
    lower[7:10], upper[7:10] = -bound, bound
    for node in range(1, tr.phases[0].intervals + 1):
        tr.bound_state(0, node, lower, upper)


def plan_smooth_collocation(problem: ManeuverProblem, *, intervals: int = DEFAULT_INTERVALS,
                            torque_accel: float = DEFAULT_TORQUE_ACCEL, cone_margin_deg: float = 0.05,
                            warm_starts: tuple = (), tol: float = 1e-7, max_iter: int = 400) -> Plan:
    """Minimum-time rest-to-rest slew with a C¹ torque among the problem's zones (module docstring).

    Options: ``intervals`` of the first mesh (refined where the truth enters a zone, up to four
    times as many); ``torque_accel`` the bound on the torque's second derivative (T̄ per τ_u²);
    ``cone_margin_deg`` tightening of every zone at the collocation points; ``warm_starts`` plans to
    start from (the first that converges is refined; without any, graph_smooth's plan). Honours
    ``problem.deadline``: the last verified plan (status BUDGET_EXPIRED) — a converged solution's,
    or that of the feasible iterate of least t_f where the deadline stopped IPOPT — or none.
    """
    start = time.monotonic()
    why = no_torque_limit(problem) or blocked_endpoint(problem)
    seeds = [p for p in warm_starts if p.success and len(p.t) > 1]
    if not why and not seeds:
        seeds = [plan_graph_smooth(problem)]
        why = "" if seeds[0].success else f"no plan to start from: {seeds[0].message}"
    if why:
        return Plan(method=METHOD, status=Status.FAILED, message=why, wall_time=time.monotonic() - start)
    s = scaling(problem)
    tf_seed = max(p.duration for p in seeds) / s.tu
    tf_max = 10.0 * tf_seed if not problem.zone_sky().moving else min(10.0 * tf_seed, problem.zone_sky().window / s.tu)
    bounds = (min(1e-2 * tf_seed, 0.5 * tf_max), tf_max)
    mesh, stats, best = meshes.uniform_mesh(intervals), {"meshes": []}, None
    initial = [guess(p, s, col.Phase(rigid_body_dynamics(s.Jn, smooth=True), mesh)) for p in seeds]
    nit = nfev = 0
    moving, torque_bound = problem.goal_motion is not None, 1.0
    for round_ in range(REFINE_ROUNDS + 1):
        tr = transcription(problem, s, mesh, "constant", np.deg2rad(cone_margin_deg), bounds,
                           torque_accel=torque_accel, tol=tol, max_iter=max_iter)
        if torque_bound < 1.0:
            _bound_torque(tr, problem, s, torque_bound)
        w = incumbent = None
        for g in initial:
            res = tr.solve(tr.pack([g]), deadline=problem.deadline)
            nit, nfev = nit + res.nit, nfev + res.nfev
            stats["meshes"].append({"intervals": len(mesh) - 1, "tf": res.objective * s.tu, "status": res.status,
                                    "iterations": res.nit, "seconds": res.wall_time})
            incumbent = incumbent if res.incumbent is None else res.incumbent
            if res.success and res.constraint_violation < CONVERGED_VIOLATION:
                w = res.w
                break
        if w is None and (incumbent is None or not expired_at(problem)):
            break
        # not converged when the deadline came: the feasible iterate of least t_f, if it verifies
        sol = tr.phase_solution(incumbent if w is None else w)
        plan = smooth_plan(sol, s, moving)
        if moving and plan.stats["torque_peak"] > LIMIT_RATIO and w is not None and round_ < REFINE_ROUNDS:
            # the torque bulged past T̄ between the collocation points: solved again on a bound that leaves room
            torque_bound /= (plan.stats["torque_peak"] * (1.0 + TORQUE_ROOM)) ** 2
            initial = [sol.resample(tr.phases[0])]
            continue
        traj = predict(problem, plan)
        plan.verification = measure(problem, plan, traj)
        best = plan if best is None or rejection(plan.verification) is None else best
        # the plan's times are the solution's slowed by c: the truth's samples back on the solution's mesh
        bad = _truth_violation_intervals(replace(traj, t=traj.t / plan.stats["slowed_by"]), sol, s, problem)
        if not len(bad) and problem.goal_motion is not None:    # a missed arrival: the whole mesh is too coarse
            bad = np.arange(sol.phase.intervals)
        if w is None or rejection(plan.verification) is None or not len(bad) or len(mesh) - 1 >= 4 * intervals:
            break
        mesh = meshes.refine_mesh(mesh, bad, 4 * intervals)
        initial = [sol.resample(tr.phases[0].with_mesh(mesh))]
    elapsed = time.monotonic() - start
    expired = expired_at(problem)
    if best is None:
        statuses = sorted({m["status"] for m in stats["meshes"]})
        return Plan(method=METHOD, status=Status.BUDGET_EXPIRED if expired else Status.FAILED,
                    message=f"no start converged{' before the deadline' if expired else ''} "
                            f"(IPOPT: {', '.join(statuses)})", wall_time=elapsed, nit=nit, nfev=nfev, stats=stats)
    why = rejection(best.verification)
    best.status = Status.FAILED if why else Status.BUDGET_EXPIRED if expired else Status.OPTIMAL
    best.message = (f"fails truth verification: {why}" if why else
                    f"t_f = {best.duration:.6g} s, torque C1 (|d2T/dt2| <= {torque_accel:g} T/tu^2), "
                    f"{len(mesh) - 1} intervals")
    stats.update(tf=best.duration, time_unit=s.tu, intervals=len(mesh) - 1, slowed_by=best.stats["slowed_by"])
    best.stats, best.nit, best.nfev, best.wall_time = stats, nit, nfev, elapsed
    return best
