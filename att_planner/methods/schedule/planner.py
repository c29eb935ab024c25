"""The schedule planner: :func:`plan_schedule` (see :mod:`att_planner.methods.schedule`)."""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from att_msgs_py.types import ControlKind, Passage, Plan, Status
from att_planner.methods.schedule.order_search import OrderSolver, Solved, search_orders
from att_planner.methods.schedule.transcription import SUBSTEPS, eigenaxis_rest_to_rest_time, node_times
from att_planner.problem import ManeuverProblem
from att_planner.verification import rejection
from att_planner.verification import verify as verify_plan
from att_sim.models import rotations as rot

METHOD = "schedule"
MAX_SUBSTEPS = 8                  # RK4 steps per ZOH interval a refinement may reach
OBSERVATION_LOOKAHEAD = 7200.0    # s more of moving zones when targets are observed: a target covered now
                                  # (by the Earth, most often) may be observable an orbit later


def _plan(solver: OrderSolver, final: Solved) -> Plan:
    """The plan of a solved order in SI units: knot times, ZOH wheel torques (last row zero),
    predicted q and ω at the knots, the passages; the predicted wheel speeds in ``stats``. A target
    with a dwell gets one more knot at the end of its observation: held, zero torque."""
    tr, sol = final.transcription, final.sol
    sc, scale, N = tr.sc, tr.scale, tr.intervals
    dwell = solver.dwells(final.order)
    t = node_times(sol.durations * scale.t_sat, dwell, N)
    torque = np.vstack([sol.u * sc.wheel_torque_max, np.zeros((1, sc.n_wheels))])
    q, h = rot.normalize(sol.q), sol.h
    passages = [Passage(name, float(tp), solver.targets[name], float(d))
                for name, tp, d in zip(final.order, t[N::N][:tr.n_targets], dwell)]
    held = [(p + 1) * N for p in range(tr.n_targets) if dwell[p] > 0]
    if held:       # the observation: the node repeated at its end, a zero-torque interval before it
        at = np.array(held)
        t = np.insert(t, at + 1, t[at] + dwell[dwell > 0])
        torque = np.insert(torque, at, 0.0, axis=0)
        q, h = np.insert(q, at + 1, q[at], axis=0), np.insert(h, at + 1, h[at], axis=0)
    return Plan(t=t, torque=torque, q=q, omega=h @ scale.rate_per_h.T, control_kind=ControlKind.WHEEL_TORQUE,
                method=METHOD, nit=sol.nit, passages=passages, stats={"wheel_speed": h * sc.wheel_speed_max})


def _finished(solver: OrderSolver, final: Solved, stats: dict, t_begin: float, cpu_begin: float) -> Plan:
    """The plan of ``final`` with its status, message and timing."""
    plan = _plan(solver, final)
    stats.update(iterations=final.sol.nit, ipopt_status=final.sol.return_status,
                 intervals_used=final.transcription.intervals)
    status = Status.OPTIMAL if final.sol.converged else Status.FEASIBLE
    message = f"order {''.join(final.order) if all(len(k) == 1 for k in final.order) else final.order}" \
              f" t_f = {plan.duration:.2f} s"
    if solver.expired():
        status, message = Status.BUDGET_EXPIRED, message + " (deadline reached: best so far)"
    return _finish(plan, status, message, t_begin, cpu_begin, stats)


def _refine_zones(problem: ManeuverProblem, solver: OrderSolver, final: Solved, plan: Plan, rounds: int,
                  stats: dict, t_begin: float, cpu_begin: float) -> Plan:
    """While the verified ``plan`` enters a zone between the NLP's points or the truth strays from
    the NLP's own integration (a long leg's intervals: minutes), double the intervals per phase and
    the RK4 substeps per interval (up to :data:`MAX_SUBSTEPS`) and re-solve its order from it
    (``rounds`` times at most, within the deadline); the grids tried go to
    ``stats['zone_refinements']``."""
    tried = stats["zone_refinements"] = []
    while _refinable(plan) and len(tried) < rounds and not solver.expired():
        solver = replace(solver, substeps=min(2 * solver.substeps, MAX_SUBSTEPS))
        finer = solver.solve(final.order, 2 * final.transcription.intervals, guess=final)
        tried.append({"intervals": finer.transcription.intervals, "substeps": solver.substeps})
        if not np.isfinite(finer.tf):
            break
        final = finer
        plan = _finished(solver, final, stats, t_begin, cpu_begin)
        plan.verification = verify_plan(problem, plan)
    return plan


def _refinable(plan: Plan) -> bool:
    """A rejection a finer grid can mend: a zone entered, or the final or a passage attitude missed."""
    why = rejection(plan.verification)
    return why is not None and why.startswith(("enters", "leaves", "final attitude", "passage"))


def _finish(plan: Plan, status: Status, message: str, t_begin: float, cpu_begin: float, stats: dict) -> Plan:
    """Fill status and timing: ``wall_time`` is wall time, ``stats['cpu_seconds']`` the process CPU
    time (the fairer figure on a shared machine)."""
    plan.status, plan.message = status, message
    plan.stats = {**stats, **plan.stats, "cpu_seconds": time.process_time() - cpu_begin}
    plan.wall_time = time.perf_counter() - t_begin
    return plan


def zone_window(problem: ManeuverProblem) -> float | None:
    """The span (s) the zones are fitted over for a tour, or None (the problem's default) when no
    zone moves: twice (targets + 1) legs of the longest eigenaxis rest-to-rest transfer between
    any two of the tour's attitudes, with the observations' dwells and :data:`OBSERVATION_LOOKAHEAD`
    when there are any, beyond the last window's close, at least the problem's default window."""
    if all(z.body == "inertial" for z in problem.zones):
        return None
    nodes = [problem.q_initial, *problem.targets.values(), problem.q_final]
    longest = max(eigenaxis_rest_to_rest_time(problem.spacecraft, a, b) for a in nodes for b in nodes)
    observing = sum(problem.target_dwell.values())
    closes = [w[1] for w in problem.target_windows.values() if np.isfinite(w[1])]
    lookahead = OBSERVATION_LOOKAHEAD if problem.target_dwell else 0.0
    return max(problem.zone_sky().window, 2.0 * len(nodes[1:]) * longest + observing + lookahead,
               max(closes, default=0.0) + 2.0 * longest)


def _check_options(names: list, order, candidates: int, search_intervals: int, intervals: int,
                   cone_margin_deg: float, zone_refinements: int) -> None:
    """ValueError naming the first bad option of :func:`plan_schedule`."""
    if order is not None and sorted(order) != sorted(names):
        raise ValueError("order must list every target name exactly once")
    if candidates < 1 or search_intervals < 1 or intervals < 1:
        raise ValueError("candidates, search_intervals and intervals must be positive")
    if not (np.isfinite(cone_margin_deg) and 0.0 <= cone_margin_deg <= 5.0) or zone_refinements < 0:
        raise ValueError("cone_margin_deg must be in [0, 5] and zone_refinements >= 0")


def plan_schedule(problem: ManeuverProblem, *, order=None, search_intervals: int = 8, intervals: int = 24,
                  substeps: int = SUBSTEPS, candidates: int = 2, prove: bool = False, max_order_solves: int = 1000,
                  second_start_margin: float = 0.01, cone_margin_deg: float = 0.05, zone_refinements: int = 3,
                  verify: bool = True) -> Plan:
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

    Zones (``problem.zone_sky()``: the cones, then the zones, moving or not, keep-out or keep-in,
    each of its own sensor): every leg keeps every zone at the nodes and interval midpoints, at
    their physical time along the whole tour (:mod:`.transcription`), tightened by
    ``cone_margin_deg``; moving zones are fitted over :func:`zone_window` and break the time
    reversal (both directions of an order are then solved as distinct orders). When the verified
    plan still enters a zone between those points, or the truth strays from the NLP's integration (a
    leg that waits for a window lasts minutes), the intervals per phase and the RK4 substeps per
    interval are doubled and the order re-solved from it, ``zone_refinements`` times at most.
    """
    t_begin, cpu_begin = time.perf_counter(), time.process_time()
    names = list(problem.targets)
    _check_options(names, order, candidates, search_intervals, intervals, cone_margin_deg, zone_refinements)
    solver = OrderSolver.of(problem, substeps, np.deg2rad(cone_margin_deg), zone_window(problem))
    stats: dict = {"orders_solved": 0, "search_intervals": search_intervals, "intervals": intervals,
                   "substeps": substeps, "visibility": solver.visible}
    empty = Plan(torque=np.zeros((0, problem.spacecraft.n_wheels)), control_kind=ControlKind.WHEEL_TORQUE,
                 method=METHOD)
    never = [k for k in names if not any(b - a >= problem.target_dwell.get(k, 0.0) for a, b in solver.visible[k])]
    if never:
        return _finish(empty, Status.FAILED, f"target {never[0]!r} can never be observed: its window, less the "
                       "times a zone covers it, holds no span as long as its dwell", t_begin, cpu_begin, stats)
    try:
        if order is not None:
            solved = [solver.solve(order, search_intervals)]
            stats["orders_solved"] = 1
        else:
            solved = search_orders(solver, names, search_intervals, candidates, prove, max_order_solves,
                                   second_start_margin, stats)
        if not solved:
            why = ("no order observes every target within its window" if stats.get("orders_infeasible")
                   and not solver.expired() else "deadline passed before any order was solved")
            return _finish(empty, Status.FAILED, why, t_begin, cpu_begin, stats)
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
        plan = _finished(solver, final, stats, t_begin, cpu_begin)
        if verify:
            plan.verification = verify_plan(problem, plan)
            if zone_refinements and _refinable(plan):
                plan = _refine_zones(problem, solver, final, plan, zone_refinements, stats, t_begin, cpu_begin)
            why = rejection(plan.verification)
            if why is not None:          # never a success the truth does not confirm
                plan.status, plan.message = Status.FAILED, f"{plan.message}; fails truth verification: {why}"
        return plan
    except RuntimeError as exc:  # CasADi/IPOPT failures are reported, not raised
        return _finish(empty, Status.FAILED, f"solver error: {exc}", t_begin, cpu_begin, stats)
