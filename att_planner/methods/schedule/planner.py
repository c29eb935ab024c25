"""The schedule planner: :func:`plan_schedule` (see :mod:`att_planner.methods.schedule`)."""
from __future__ import annotations

import time

import numpy as np

from att_msgs_py.types import ControlKind, Passage, Plan, Status
from att_planner.methods.schedule.order_search import OrderSolver, Solved, search_orders
from att_planner.methods.schedule.transcription import SUBSTEPS
from att_planner.problem import ManeuverProblem
from att_planner.verification import verify as verify_plan
from att_sim import rotations as rot

METHOD = "schedule"


def _plan(solver: OrderSolver, final: Solved) -> Plan:
    """The plan of a solved order in SI units: knot times, ZOH wheel torques (last row zero),
    predicted q and ω at the knots, the passages; the predicted wheel speeds in ``stats``."""
    tr, sol = final.transcription, final.sol
    sc, scale, N = tr.sc, tr.scale, tr.intervals
    t = np.concatenate([[0.0], np.cumsum(np.repeat(sol.durations / N, N) * scale.t_sat)])
    passages = [Passage(name, float(tp), solver.targets[name])
                for name, tp in zip(final.order, t[N::N][:tr.n_targets])]
    return Plan(t=t, torque=np.vstack([sol.u * sc.wheel_torque_max, np.zeros((1, sc.n_wheels))]),
                q=rot.normalize(sol.q), omega=sol.h @ scale.rate_per_h.T, control_kind=ControlKind.WHEEL_TORQUE,
                method=METHOD, nit=sol.nit, passages=passages, stats={"wheel_speed": sol.h * sc.wheel_speed_max})


def _finish(plan: Plan, status: Status, message: str, t_begin: float, cpu_begin: float, stats: dict) -> Plan:
    """Fill status and timing: ``wall_time`` is wall time, ``stats['cpu_seconds']`` the process CPU
    time (the fairer figure on a shared machine)."""
    plan.status, plan.message = status, message
    plan.stats = {**stats, **plan.stats, "cpu_seconds": time.process_time() - cpu_begin}
    plan.wall_time = time.perf_counter() - t_begin
    return plan


def plan_schedule(problem: ManeuverProblem, *, order=None, search_intervals: int = 8, intervals: int = 24,
                  substeps: int = SUBSTEPS, candidates: int = 2, prove: bool = False, max_order_solves: int = 1000,
                  second_start_margin: float = 0.01, verify: bool = True) -> Plan:
    """Fastest rest-to-rest schedule through every target of ``problem.targets``, in the best order found.

    Targets are quaternions [x, y, z, w] (either sign). Start at rest at ``problem.q_initial`` with
    the wheels stopped, end at rest at ``problem.q_final``, ω_z = 0 at each target; the spacecraft
    gives the wheel axes, inertia and torque/speed limits, ``problem.rate_max`` the body-rate bound
    per axis (rad/s). When ``problem.deadline`` passes, the best schedule so far is returned with
    status BUDGET_EXPIRED.

    Search (:mod:`.order_search`): leg lower bounds on ``search_intervals`` intervals per phase;
    orders in increasing bound order; the first ``candidates`` solved as multiphase problems; with
    ``prove`` every further order whose bound is below the incumbent is solved too (up to
    ``max_order_solves``), which proves the incumbent optimal on that grid when the enumeration is
    exhausted. When the start and end attitudes coincide, an order and its reverse have the same
    minimum time (time reversal t → t_f − t, Ω → −Ω, T_u(t) → T_u(t_f − t) maps one schedule onto
    the other), so only one of each pair is solved, and the winner (with ``prove``: every order
    within ``second_start_margin`` of it) is solved once more reversed (a second start: the NLP is
    not convex). ``order`` (list of names) skips the search. The winner is re-solved on
    ``intervals`` per phase (warm start) and verified (:mod:`att_planner.verification`, every
    passage included). The plan's ``passages`` give the order and the passage times.
    """
    t_begin, cpu_begin = time.perf_counter(), time.process_time()
    names = list(problem.targets)
    if order is not None and sorted(order) != sorted(names):
        raise ValueError("order must list every target name exactly once")
    if candidates < 1 or search_intervals < 1 or intervals < 1:
        raise ValueError("candidates, search_intervals and intervals must be positive")
    solver = OrderSolver.of(problem, substeps)
    stats: dict = {"orders_solved": 0, "search_intervals": search_intervals, "intervals": intervals,
                   "substeps": substeps}
    empty = Plan(torque=np.zeros((0, problem.spacecraft.n_wheels)), control_kind=ControlKind.WHEEL_TORQUE,
                 method=METHOD)
    try:
        if order is not None:
            solved = [solver.solve(order, search_intervals)]
            stats["orders_solved"] = 1
        else:
            solved = search_orders(solver, names, search_intervals, candidates, prove, max_order_solves,
                                   second_start_margin, stats)
        if not solved:
            return _finish(empty, Status.FAILED, "deadline passed before any order was solved", t_begin, cpu_begin,
                           stats)
        best = min(solved, key=lambda s: s.tf)
        if not np.isfinite(best.tf):
            return _finish(empty, Status.FAILED, "no order converged: " + best.sol.return_status, t_begin,
                           cpu_begin, stats)
        stats["tf_search"] = best.tf
        final = best
        if intervals != search_intervals and not solver.expired():
            fine = solver.solve(best.order, intervals, guess=best)
            if fine.tf <= best.tf * (1 + 1e-6):
                final = fine
            stats["refine_status"] = fine.sol.return_status
        plan = _plan(solver, final)
        stats.update(iterations=final.sol.nit, ipopt_status=final.sol.return_status,
                     intervals_used=final.transcription.intervals)
        status = Status.OPTIMAL if final.sol.converged else Status.FEASIBLE
        message = f"order {''.join(final.order) if all(len(k) == 1 for k in final.order) else final.order}" \
                  f" t_f = {plan.duration:.2f} s"
        if solver.expired():
            status, message = Status.BUDGET_EXPIRED, message + " (deadline reached: best so far)"
        plan = _finish(plan, status, message, t_begin, cpu_begin, stats)
        if verify:
            plan.verification = verify_plan(problem, plan)
        return plan
    except RuntimeError as exc:  # CasADi/IPOPT failures are reported, not raised
        return _finish(empty, Status.FAILED, f"solver error: {exc}", t_begin, cpu_begin, stats)
