"""Time-optimal rest-to-rest slews among keep-out and keep-in zones (Melton 2012) by direct collocation.

Problem (normalised: time unit ``τ = sqrt(J0/T̄)``, J0 the largest principal inertia, ``J̃ = J/J0``,
torque ``u = T/T̄``, rate ``ω̃ = ω τ``)::

    min t_f   s.t.  q̇ = ½ q ⊗ [ω̃, 0] + ½ (1 − |q|²) q,    J̃ ω̃̇ = u − ω̃ × J̃ ω̃,    |u_j| ≤ 1,
                    q(0) = q_0,  ω̃(0) = ω̃(t_f) = 0,
                    a_z(t)ᵀ R(q) s_z ≤ cos(θ_z(t) + δ)   (keep-out zone z of sensor s_z, tightened by δ),
                    a_z(t)ᵀ R(q) s_z ≥ cos(θ_z(t) − δ)   (keep-in zone z),
                    final attitude: vec(q_fᶜ ⊗ q(t_f)) = 0     (q(t_f) = ±q_f: q and −q alike),
                    or semi-free: R(q(t_f)) r ⟂ e₁, e₂ and R(q(t_f)) r · s ≥ 0 (sensor on target s),
                    optional |ω_j| ≤ ω̄ and per-wheel momentum |G⁺ J ω|_i ≤ h̄ (the momentum the
                    wheels would store producing the torque with zero total momentum), both
                    tightened by BOUND_MARGIN at the collocation points; with wheels, their speeds
                    relative to the body within their limit (the momentum stored at the start turned
                    with the body plus the slew's share: :func:`.model.wheel_speed_constraints`).

A moving goal (``problem.goal_motion``, a pointing law) replaces the final attitude and
the final rest by ``vec(q_g(t_f)ᶜ ⊗ q(t_f)) = 0`` and ``ω̃(t_f) = ω̃_g(t_f)``, the goal's Chebyshev
series in t_f (:func:`.model.moving_goal_values`), so the slew ends on it at its rate.

The zones are ``problem.zone_sky()`` (:mod:`att_planner.zones`: the keep-out cones as inertial zones of
the sensor ``r``, then Sun, Moon, Earth-limb and inertial zones, each of its own sensor). A zone
that moves is imposed at each collocation point's physical time ``t = τ_k t_f`` through the
FittedZones' Chebyshev series of that CasADi expression, so the NLP's derivatives with respect to t_f
are exact (no frozen snapshot is iterated); ``t_f`` is then bounded by the series' window. Without
motion the constraints are constants and the NLP is the one of fixed cones.

The ``½(1 − |q|²) q`` term vanishes on unit quaternions and makes the unit sphere attracting, so the
discretised norm cannot drift. Transcription: Hermite–Simpson (:mod:`.collocation`, the model in :mod:`.model`)
with one torque per mesh interval (zero-order hold), so that the simulator reproduces the plan
with ``interpolation='zoh'`` and bang-bang switches land on mesh nodes.

Solution process (Melton's two stages, with multi-start because the problem has many local
minima; option ``global_stage``: his particle swarm, :mod:`.swarm`, as the first start): (1) cheap
routes — eigenaxis both ways round, tilted two-leg routes and the cone-riding λ-rotation routes of
:mod:`att_planner.methods.constrained_axis`, optional plans of other methods (:mod:`.routes`) —
each turned into a continuous bang-bang guess and solved on a coarse mesh; (2) the best converged
solution is refined: intervals where the torque switches or a zone constraint fails between
collocation points are split (in quarters, once by default) and the NLP re-solved from the
interpolated solution; (3) the torque is integrated through the prediction model
(:mod:`att_planner.verification`); a failure refines again.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from att_msgs_py.types import Interpolation, Plan, Status
from att_planner.cones import blocked_endpoint
from att_planner.methods.axis_rotations import eigenaxis_leg, goal_attitude, no_torque_limit
from att_planner.methods.lanes import map_in_lanes
from att_planner.methods.time_optimal import collocation as col
from att_planner.methods.time_optimal import mesh as meshes
from att_planner.methods.time_optimal.fastest import fastest_verified, warm_start_answer, with_smooth_seed
from att_planner.methods.time_optimal.model import Scaling, plan_arrays, scaling, transcription
from att_planner.methods.time_optimal.routes import Route, candidate_routes, route_guess, select_routes, zone_margin
from att_planner.methods.time_optimal.swarm import swarm_plan
from att_planner.problem import ManeuverProblem
from att_planner.verification import clearances, measure, predict, rejection
from att_sim.models import rotations as rot

METHOD = "time_optimal"
CONVERGED_VIOLATION = 1e-5      # an IPOPT answer counts as solved below this constraint violation


DEFAULT_INTERVALS, DEFAULT_MAX_INTERVALS = 16, 120


def _mesh_sizes(options: dict) -> tuple[int, int]:
    """(intervals, max_intervals): the refinement cap defaults to 120, or to ``intervals`` above it."""
    intervals = DEFAULT_INTERVALS if options.get("intervals") is None else options["intervals"]
    max_intervals = options.get("max_intervals")
    if max_intervals is None:
        max_intervals = max(DEFAULT_MAX_INTERVALS, intervals)
    return intervals, max_intervals


def option_problem(options: dict) -> str | None:
    """Why the time-optimal ``options`` cannot run (the registry's hook), or None."""
    intervals, max_intervals = _mesh_sizes(options)
    if max_intervals < intervals:
        return f"max_intervals = {max_intervals} is below intervals = {intervals} (the refinement cap)"
    return None


@dataclass
class _Solve:
    """What the three stages of one solve share: the problem, its scaling, NLP settings, budget."""

    problem: ManeuverProblem
    scaling: Scaling
    cone_margin: float
    tf_bounds: tuple
    tol: float
    max_iter: int
    max_intervals: int
    deadline: float | None
    interpolation: str
    lanes: bool = True                # the exploration's starts on two cores (methods.lanes)
    budget_hit: bool = False
    nit: int = 0
    nfev: int = 0

    @property
    def control(self) -> str:
        """The collocation control parametrisation of the plan's interpolation."""
        return "constant" if self.interpolation == Interpolation.ZOH else "linear"

    def expired(self) -> bool:
        if self.deadline is not None and time.monotonic() > self.deadline:
            self.budget_hit = True
        return self.budget_hit

    def solve(self, tr: col.Transcription, guess: col.PhaseGuess) -> col.NlpResult:
        res = tr.solve(tr.pack([guess]), deadline=self.deadline)
        self.nit += res.nit
        self.nfev += res.nfev
        return res

    def transcription(self, mesh: np.ndarray, tol: float | None = None) -> col.Transcription:
        """The built NLP on ``mesh`` (:func:`.model.transcription`: built once per shape)."""
        return transcription(self.problem, self.scaling, mesh, self.control, self.cone_margin, self.tf_bounds,
                             tol=self.tol if tol is None else tol, max_iter=self.max_iter)

    def plan(self, sol: col.PhaseSolution) -> Plan:
        t, torque, q, omega = plan_arrays(sol, self.scaling)
        return Plan(t=t, torque=torque, q=q, omega=omega, interpolation=self.interpolation, method=METHOD)


class _Incumbent:
    """The best solution and its mesh, re-solved on refined meshes (stages 2 and 3)."""

    def __init__(self, run: _Solve, tr: col.Transcription, res: col.NlpResult):
        self.run, self.res = run, res
        self.sol = tr.phase_solution(res.w)
        self.history = [(self.sol, res)]
        self.mesh_log = [{"intervals": tr.phases[0].intervals, "tf": res.objective * run.scaling.tu,
                          "status": res.status, "seconds": res.wall_time}]

    def resolve(self, new_mesh) -> bool:
        """Re-solve on ``new_mesh`` from the interpolated incumbent; keep it if it converged."""
        run = self.run
        new_tr = run.transcription(new_mesh)
        new_res = run.solve(new_tr, self.sol.resample(new_tr.phases[0]))
        self.mesh_log.append({"intervals": new_tr.phases[0].intervals, "tf": new_res.objective * run.scaling.tu,
                              "status": new_res.status, "seconds": new_res.wall_time})
        if new_res.success and new_res.constraint_violation < CONVERGED_VIOLATION:
            self.res = new_res
            self.sol = new_tr.phase_solution(new_res.w)
            self.history.append((self.sol, new_res))
            return True
        return False

    def refine(self, rounds: int, parts: int) -> None:
        """Stage 2: split the intervals where the torque switches or a path constraint fails
        between collocation points into ``parts``, ``rounds`` times at most."""
        for _ in range(rounds):
            if self.run.expired():
                return
            sol = self.sol
            bad, _ = meshes.path_violations(sol, tol=1e-4)
            split = np.union1d(bad, meshes.switch_intervals(sol, limit=max(4, sol.phase.intervals // 2)))
            if not len(split) or sol.phase.intervals >= self.run.max_intervals:
                return
            if not self.resolve(meshes.refine_mesh(sol.phase.mesh, split, self.run.max_intervals, parts)):
                return

    def check(self, sol: col.PhaseSolution):
        """Truth verification of ``sol``: (accepted, plan with its verification, trajectory)."""
        plan = self.run.plan(sol)
        traj = predict(self.run.problem, plan)
        plan.verification = measure(self.run.problem, plan, traj)
        return rejection(plan.verification) is None, plan, traj

    def verified(self, extra: list) -> tuple[bool, Plan]:
        """Stage 3: verify; refine where the dense truth grid enters a zone (``extra`` logs the
        intervals split); fall back to an earlier, coarser solution that passes."""
        run = self.run
        ok, plan, traj = self.check(self.sol)
        while not ok and not run.expired() and self.sol.phase.intervals < run.max_intervals:
            bad = _truth_violation_intervals(traj, self.sol, run.scaling, run.problem)
            if not len(bad):
                bad = np.arange(self.sol.phase.intervals)
            extra.append(len(bad))
            if not self.resolve(meshes.refine_mesh(self.sol.phase.mesh, bad, run.max_intervals)):
                break
            ok, plan, traj = self.check(self.sol)
        run.expired()
        if not ok and len(self.history) > 1:
            # an earlier (coarser) solution may still pass, if there is time to check it
            for s_prev, r_prev in reversed(self.history[:-1]):
                if run.problem.time_left() <= 0:
                    break
                ok_prev, plan_prev, _ = self.check(s_prev)
                if ok_prev:
                    ok, plan, self.res, self.sol = ok_prev, plan_prev, r_prev, s_prev
                    break
        return ok, plan


def _truth_violation_intervals(traj, sol: col.PhaseSolution, s: Scaling, problem) -> np.ndarray:
    """Mesh intervals containing dense truth samples below a zone's clearance floor
    (:func:`att_planner.verification.clearances`: each zone at the sample's time)."""
    m = clearances(problem, traj.t, traj.q_BN, true=False)
    if not m.size:
        return np.array([], int)
    bad_t = traj.t[m.min(axis=1) < 0] / s.tu / sol.duration
    return np.unique(np.clip(np.searchsorted(sol.phase.mesh, bad_t, side="right") - 1, 0, sol.phase.intervals - 1))


def _explore(run: _Solve, routes: list[Route], intervals: int, explore_tol: float):
    """Stage 1: every route solved on the coarse mesh (with ``run.lanes``, every other one by a
    forked child: :func:`att_planner.methods.lanes.map_in_lanes`, the same answers on two cores);
    ``(transcription, solved, log)`` with ``solved`` a list of (t_f, route label, result) of the
    converged ones."""
    tr = run.transcription(meshes.uniform_mesh(intervals), explore_tol)

    def start(rt: Route) -> col.NlpResult | None:
        if run.deadline is not None and time.monotonic() > run.deadline:
            return None
        return tr.solve(tr.pack([route_guess(run.problem, run.scaling, rt, tr.phases[0])]), deadline=run.deadline)

    log, solved = [], []
    for rt, res in zip(routes, map_in_lanes(start, routes) if run.lanes else map(start, routes)):
        if res is None:
            run.budget_hit = True
            continue
        run.nit += res.nit
        run.nfev += res.nfev
        log.append({"route": rt.label, "tf_guess": rt.tf_estimate * run.scaling.tu,
                    "route_min_margin": rt.min_margin, "tf": res.objective * run.scaling.tu,
                    "status": res.status, "iterations": res.nit, "seconds": res.wall_time})
        if res.success and res.constraint_violation < CONVERGED_VIOLATION:
            solved.append((res.objective, rt.label, res))
    return tr, sorted(solved, key=lambda s: s[0]), log


def _routes(problem: ManeuverProblem, s: Scaling, starts: int, warm_starts, smooth_warm_start: bool,
            seconds: dict) -> list[Route]:
    """The cheap routes to solve, then the warm starts (other methods' plans)."""
    if smooth_warm_start:
        lap = time.monotonic()
        share = None if problem.deadline is None else lap + (problem.deadline - lap) / 3
        from att_planner.methods.slepian.planner import plan_slepian  # only here: keeps scipy.signal out

        warm_starts = (*warm_starts, plan_slepian(replace(problem, deadline=share), M=4))   # a failed plan is dropped
        seconds["smooth_warm_start"] = time.monotonic() - lap
    routes = select_routes(candidate_routes(problem, s), starts)
    return routes + [Route(f"warm start: {p.method}", plan=p, tf_estimate=p.duration / s.tu,
                           min_margin=zone_margin(problem, p.t, p.q))
                     for p in warm_starts if len(p.t) > 1]


def _checked_options(intervals: int, max_intervals: int | None, interpolation: str) -> tuple[int, int]:
    """The mesh sizes ``(intervals, max_intervals)`` of valid options; ValueError otherwise."""
    why = option_problem({"intervals": intervals, "max_intervals": max_intervals})
    if why:
        raise ValueError(why)
    if interpolation not in tuple(Interpolation):
        raise ValueError(f"interpolation must be one of {[str(i) for i in Interpolation]}, not {interpolation!r}")
    return _mesh_sizes({"intervals": intervals, "max_intervals": max_intervals})


def _answer_without_solving(problem: ManeuverProblem, interpolation: str, start: float) -> Plan | None:
    """The plan when no NLP is needed (a refused problem, or the start already at the goal), else None."""
    why = no_torque_limit(problem) or blocked_endpoint(problem)
    if why:
        return Plan(method=METHOD, status=Status.FAILED, message=why, wall_time=time.monotonic() - start)
    if eigenaxis_leg(problem.q_initial, goal_attitude(problem)).angle < 1e-9:
        q0 = rot.normalize(np.asarray(problem.q_initial, float))
        return Plan(t=np.zeros(1), torque=np.zeros((1, 3)), q=q0[None], omega=np.zeros((1, 3)),
                    interpolation=interpolation, method=METHOD, status=Status.OPTIMAL, message="already at the goal",
                    wall_time=time.monotonic() - start, stats={"tf": 0.0})
    return None


def _tf_bounds(problem: ManeuverProblem, s: Scaling, routes: list[Route]) -> tuple[float, float]:
    """Bounds on the normalised t_f: up to ten times the slowest route's estimate, and within the
    window of moving zones (their series hold there only)."""
    tf_scale = max(r.tf_estimate for r in routes if np.isfinite(r.tf_estimate))
    tf_max = 10.0 * tf_scale
    if problem.zone_sky().moving:
        tf_max = min(tf_max, problem.zone_sky().window / s.tu)
    return min(1e-2 * tf_scale, 0.5 * tf_max), tf_max


def _verdict(plan: Plan, ok: bool, run: _Solve, incumbent: _Incumbent, best: str) -> tuple[Status, str]:
    """Status and message of the refined, verified plan: failed (why), budget expired, or optimal /
    feasible by IPOPT's last status."""
    if not ok:
        ver = plan.verification
        return Status.FAILED, (f"best solution (t_f = {plan.t[-1]:.4g} s) fails truth verification: {rejection(ver)} "
                               f"(final error {np.rad2deg(ver.final_attitude_error):.3f} deg, min cone margin "
                               f"{np.rad2deg(ver.min_cone_margin):.3f} deg)")
    if run.budget_hit:
        return Status.BUDGET_EXPIRED, "time budget expired; best verified plan returned"
    status = Status.OPTIMAL if incumbent.res.status == "Solve_Succeeded" else Status.FEASIBLE
    return status, f"{best}; {incumbent.sol.phase.intervals} intervals"


def _swarm_start(run: _Solve, routes: list, intervals: int, explore_tol: float, stats: dict):
    """Melton's first stage (:func:`.swarm.swarm_plan`) explored as the one start; its figures to
    ``stats['global_stage']``, its seconds to ``stats['seconds']``."""
    problem, s = run.problem, run.scaling
    lap = time.monotonic()
    swarm = swarm_plan(problem, s, routes[0].tf_estimate)
    stats["seconds"]["global_stage"] = time.monotonic() - lap
    stats["global_stage"] = {"iterations": swarm.nit, "evaluations": swarm.nfev, "cost": swarm.stats["cost"],
                             "tf": swarm.stats["tf"]}
    return _explore(run, [Route("swarm", plan=swarm, tf_estimate=swarm.duration / s.tu,
                                min_margin=zone_margin(problem, swarm.t, swarm.q))], intervals, explore_tol)


class _Fastest:
    """Never slower than a verified warm start (:mod:`.fastest`): the check of the NLP's answer and
    the further starts, logged in ``stats['fastest']``."""

    def __init__(self, run: _Solve, warm_starts: tuple, stats: dict, refine_rounds: int, refine_split: int,
                 start: float):
        self.run, self.warm_starts, self.refine = run, warm_starts, (refine_rounds, refine_split)
        self.stats, self.start = stats, start       # the plan's stats; time.monotonic() at the call
        self.log = stats["fastest"] = {"nlp_tf": None, "checked": [], "further_starts": [], "answer": "nlp"}
        self.why = ""

    def _warm_answer(self, warm: Plan, why: str) -> Plan:
        self.stats["tf"] = float(warm.duration)
        answer = warm_start_answer(warm, METHOD, why, time.monotonic() - self.start, self.stats)
        answer.nit, answer.nfev = self.run.nit, self.run.nfev
        return answer

    def unsolved(self, start_log: list) -> Plan:
        """No start converged: the fastest verified warm start (status FEASIBLE), else FAILED."""
        run, statuses = self.run, sorted({entry["status"] for entry in start_log})
        message = ("no start converged" + (" before the deadline" if run.budget_hit else "")
                   + (f" (IPOPT: {', '.join(statuses)})" if statuses else ""))
        self.log["answer"] = "none"
        warm = fastest_verified(run.problem, self.warm_starts, np.inf, self.log["checked"])
        if warm is not None:
            return self._warm_answer(warm, message)
        return Plan(status=Status.FAILED, message=message, wall_time=time.monotonic() - self.start,
                    nit=run.nit, nfev=run.nfev, method=METHOD, stats=self.stats)

    def answer(self, refined: tuple, tr: col.Transcription, others: list, intervals: int, explore_tol: float) -> Plan:
        """The plan of ``refined`` (incumbent, accepted, plan, truth refinements, label), or of a further
        start when a verified warm start is faster (:meth:`further_starts`), or that warm start."""
        incumbent, ok, plan, extra, label = refined
        lap = time.monotonic()
        warm, further = self.faster_warm_start(plan, ok), None
        if warm is not None:
            further = self.further_starts(tr, others, warm, intervals, explore_tol)
            self.stats["seconds"]["further_starts"] = time.monotonic() - lap
            if further is not None:
                incumbent, ok, plan, extra, label = further
        self.stats.update({"tf": float(plan.t[-1]), "mesh": incumbent.mesh_log, "truth_refinements": extra,
                           "intervals": incumbent.sol.phase.intervals, "ipopt_status": incumbent.res.status})
        if warm is not None and further is None:
            return self._warm_answer(warm, self.why)
        plan.status, plan.message = _verdict(plan, ok, self.run, incumbent, label)
        plan.stats = self.stats
        plan.nit, plan.nfev, plan.wall_time = self.run.nit, self.run.nfev, time.monotonic() - self.start
        return plan

    def faster_warm_start(self, plan: Plan, ok: bool) -> Plan | None:
        """The fastest warm start that verifies and is faster than the NLP's answer (``plan``,
        accepted when ``ok``), or None; ``why`` says how the answer compares."""
        tf = plan.duration if ok else np.inf
        self.log["nlp_tf"] = float(tf) if ok else None
        warm = fastest_verified(self.run.problem, self.warm_starts, tf, self.log["checked"])
        if warm is not None:
            self.why = (f"the NLP's verified plan (t_f = {tf:.6g} s) is slower than the warm start of {warm.method} "
                        f"(t_f = {warm.duration:.6g} s)" if ok else
                        f"the NLP's best plan fails truth verification: {rejection(plan.verification)}")
        return warm

    def _attempt(self, label: str, tr: col.Transcription, res: col.NlpResult):
        incumbent = _Incumbent(self.run, tr, res)
        incumbent.refine(*self.refine)
        extra: list = []
        ok, plan = incumbent.verified(extra)
        self.log["further_starts"].append({"start": label, "tf": float(plan.duration), "verified": ok})
        return incumbent, ok, plan, extra

    def further_starts(self, tr: col.Transcription, others: list, warm: Plan, intervals: int, explore_tol: float):
        """The other converged coarse starts (fastest first), then ``warm`` on a mesh twice as fine,
        each refined and verified until one is as fast as ``warm`` or the budget ends: ``(incumbent,
        ok, plan, truth refinements, label)`` of that one, or None when none is."""
        run = self.run
        attempts = [(f"further start: {label}", lambda res=res: (tr, res)) for _, label, res in others]
        route = Route(f"warm start: {warm.method}", plan=warm, tf_estimate=warm.duration / run.scaling.tu,
                      min_margin=zone_margin(run.problem, warm.t, warm.q))

        def finer():
            fine_tr, solved, _ = _explore(run, [route], 2 * intervals, explore_tol)
            return (fine_tr, solved[0][2]) if solved else None
        attempts.append((f"further start: {route.label} on {2 * intervals} intervals", finer))
        for label, solve in attempts:
            if run.expired():
                break
            started = solve()
            if started is None:
                self.log["further_starts"].append({"start": label, "tf": None, "verified": False})
                continue
            incumbent, ok, plan, extra = self._attempt(label, *started)
            if ok and plan.duration <= warm.duration:
                self.log["answer"] = label
                return incumbent, ok, plan, extra, f"{self.why}; {label}"
        return None


def plan_time_optimal(problem: ManeuverProblem, *, intervals: int = DEFAULT_INTERVALS, max_intervals: int | None = None,
                      starts: int = 3, refine_rounds: int = 1, refine_split: int = 4,
                      interpolation: str = Interpolation.ZOH,
                      cone_margin_deg: float = 0.05, warm_starts: tuple = (),
                      smooth_warm_start: bool = False, global_stage: bool = False, explore_tol: float = 1e-5,
                      tol: float = 1e-7, max_iter: int = 400, verify_reserve: float = 1.0,
                      parallel_starts: bool = True, smooth_seed: bool = False) -> Plan:
    """Minimum-time rest-to-rest slew with per-axis torque limits among the problem's zones.

    Options: ``intervals`` coarse mesh for the multi-start stage; ``max_intervals`` cap on mesh
    refinement (default 120, or ``intervals`` when larger); ``starts`` number of cheap routes solved
    (best kept, all reported in ``stats['starts']``); ``refine_rounds`` refinement rounds around
    switches / between-node cone violations, each splitting those intervals into ``refine_split``
    (one round into quarters: t_f within 0.06 % of three bisection rounds on the speed cases, two
    NLP solves fewer); ``interpolation`` 'zoh' (torque constant per interval)
    or 'linear' (torque linear between nodes); ``cone_margin_deg`` tightening of every zone (keep-out
    and keep-in, moving or not) at the collocation points;
    ``warm_starts`` plans of other methods used as extra starting routes;
    ``smooth_warm_start`` adds the smooth Slepian plan (:func:`att_planner.methods.slepian.plan_slepian`,
    paper basis M = 4, at most a third of the remaining budget) to them;
    ``global_stage`` runs Melton's first stage (:func:`.swarm.swarm_plan`: a particle swarm over a
    Chebyshev torque parametrisation) and solves from its plan alone, the routes too only if that
    start does not converge or ends slower than the bang-bang time of a route that clears every zone
    (``stats['global_stage']``: its iterations, cost, t_f; its seconds under ``seconds``);
    ``explore_tol``/``tol`` IPOPT tolerances of the two stages; ``max_iter`` per solve;
    ``verify_reserve`` seconds kept before ``problem.deadline`` for the final verification;
    ``parallel_starts``: the starts solved on two cores, every other one by a forked child
    (:mod:`att_planner.methods.lanes`: where this process can fork safely; the same answers);
    ``smooth_seed``: the smooth C¹ plan among the warm starts (:func:`.fastest.with_smooth_seed`; the
    registry passes it). Never slower than a verified warm start (:mod:`.fastest`, ``stats['fastest']``):
    further starts within the budget, else that warm start is the answer (status FEASIBLE).
    The bounds ``problem.rate_max`` and ``problem.wheel_momentum_max`` are imposed when finite.
    ``nit`` and ``nfev`` count IPOPT iterations and objective evaluations over every NLP solved.
    """
    start = time.monotonic()
    intervals, max_intervals = _checked_options(intervals, max_intervals, interpolation)
    unsolved = _answer_without_solving(problem, interpolation, start)
    if unsolved is not None:
        return unsolved
    s = scaling(problem)
    seconds: dict = {}
    warm_starts = with_smooth_seed(problem, tuple(warm_starts), seconds) if smooth_seed else tuple(warm_starts)
    lap = time.monotonic()
    routes = _routes(problem, s, starts, warm_starts, smooth_warm_start, seconds)
    run = _Solve(problem, s, np.deg2rad(cone_margin_deg), _tf_bounds(problem, s, routes), tol, max_iter,
                 max_intervals, None if problem.deadline is None else problem.deadline - verify_reserve, interpolation,
                 bool(parallel_starts))
    stats = {"time_unit": s.tu, "seconds": seconds}
    solved = []
    if global_stage:         # Melton's two stages: the swarm's plan is the one start, the routes a fallback
        tr, solved, start_log = _swarm_start(run, routes, intervals, explore_tol, stats)
    clear = [rt.tf_estimate for rt in routes if rt.min_margin >= 0]
    if not solved or (clear and solved[0][0] > min(clear)):     # no swarm, or a start worse than a clear route
        tr_routes, more, more_log = _explore(run, routes, intervals, explore_tol)
        start_log = start_log + more_log if global_stage else more_log
        if not solved or (more and more[0][0] < solved[0][0]):
            tr, solved = tr_routes, more
    stats["starts"] = start_log
    # the smooth warm start has its own entry
    seconds["routes_and_starts"] = (time.monotonic() - lap - seconds.get("smooth_warm_start", 0.0)
                                    - seconds.get("global_stage", 0.0))
    lap = time.monotonic()
    fastest = _Fastest(run, warm_starts, stats, refine_rounds, refine_split, start)
    if not solved:
        return fastest.unsolved(start_log)
    _, best_label, res = solved[0]
    stats["best_start"] = best_label
    incumbent = _Incumbent(run, tr, res)
    incumbent.refine(refine_rounds, refine_split)
    seconds["refinement"], lap = time.monotonic() - lap, time.monotonic()
    extra: list = []
    ok, plan = incumbent.verified(extra)
    seconds["verification"] = time.monotonic() - lap
    return fastest.answer((incumbent, ok, plan, extra, f"best of {len(start_log)} starts: {best_label}"),
                          tr, solved[1:], intervals, explore_tol)
