"""Time-optimal rest-to-rest slews among keep-out cones (Melton 2012) by direct collocation.

Problem (normalised: time unit ``τ = sqrt(J0/T̄)``, J0 the largest principal inertia, ``J̃ = J/J0``,
torque ``u = T/T̄``, rate ``ω̃ = ω τ``)::

    min t_f   s.t.  q̇ = ½ q ⊗ [ω̃, 0] + ½ (1 − |q|²) q,    J̃ ω̃̇ = u − ω̃ × J̃ ω̃,    |u_j| ≤ 1,
                    q(0) = q_0,  ω̃(0) = ω̃(t_f) = 0,
                    wᵢᵀ R(q) r ≤ cos(θᵢ + δ)        (keep-out cone i, tightened by δ),
                    final attitude: vec(q_fᶜ ⊗ q(t_f)) = 0     (q(t_f) = ±q_f: q and −q alike),
                    or semi-free: R(q(t_f)) r ⟂ e₁, e₂ and R(q(t_f)) r · s ≥ 0 (sensor on target s),
                    optional |ω_j| ≤ ω̄ and per-wheel momentum |G⁺ J ω|_i ≤ h̄ (the momentum the
                    wheels would store producing the torque with zero total momentum), both
                    tightened by BOUND_MARGIN at the collocation points.

The ``½(1 − |q|²) q`` term vanishes on unit quaternions and makes the unit sphere attracting, so the
discretised norm cannot drift. Transcription: Hermite–Simpson (:mod:`att_planner.collocation`)
with one torque per mesh interval (zero-order hold), so that the simulator reproduces the plan
with ``interpolation='zoh'`` and bang-bang switches land on mesh nodes.

Solution process (Melton's two stages, with multi-start because the problem has many local
minima): (1) cheap routes — eigenaxis both ways round, tilted two-leg routes and the cone-riding
λ-rotation routes of :mod:`att_planner.baselines`, optional plans of other methods — each turned
into a continuous bang-bang guess and solved on a coarse mesh; (2) the best converged solution is
refined: intervals where the torque switches or a cone constraint fails between collocation points
are bisected and the NLP re-solved from the interpolated solution; (3) the torque is integrated
through the truth dynamics (:func:`att_planner.verify.verify_profile`); a failure refines again.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import casadi as ca
import numpy as np

from att_planner import baselines
from att_planner import collocation as col
from att_planner.cones import margins
from att_planner.problem import (STATUS_BUDGET, STATUS_FAILED, STATUS_FEASIBLE, STATUS_OPTIMAL,
                                 ManeuverPlan, ManeuverProblem)
from att_sim import rotations as rot

METHOD = "time_optimal"
# Relative tightening of the rate and wheel-momentum bounds at the collocation points, so that
# the truth trajectory between them stays within the bound itself.
BOUND_MARGIN = 2e-3


@dataclass
class _Scaling:
    tu: float            # s per time unit
    J0: float            # kg m²
    Jn: np.ndarray       # J / J0
    torque_max: float    # N m


@dataclass
class _Route:
    """A cheap route used as a warm start: a sequence of λ-rotations or another method's plan."""

    label: str
    legs: list | None = None
    plan: ManeuverPlan | None = None
    tf_estimate: float = np.inf       # TU
    min_margin: float = np.inf        # rad, along the route


# -- symbolic model --------------------------------------------------------------------------------

def _dcm_sx(q):
    x, y, z, w = q[0], q[1], q[2], q[3]
    return ca.vertcat(
        ca.horzcat(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        ca.horzcat(2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        ca.horzcat(2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


def _quat_mul_sx(p, q):
    pv, pw, qv, qw = p[:3], p[3], q[:3], q[3]
    return ca.vertcat(pw * qv + qw * pv + ca.cross(pv, qv), pw * qw - ca.dot(pv, qv))


def rigid_body_dynamics(Jn: np.ndarray) -> ca.Function:
    """Normalised ``ẋ = f(x, u)`` with ``x = [q (xyzw), ω̃]`` (module docstring)."""
    x, u = ca.SX.sym("x", 7), ca.SX.sym("u", 3)
    q, w = x[:4], x[4:]
    Jn_dm = ca.DM(Jn)
    q_dot = 0.5 * _quat_mul_sx(q, ca.vertcat(w, 0)) + 0.5 * (1 - ca.dot(q, q)) * q
    w_dot = ca.solve(Jn_dm, u - ca.cross(w, ca.mtimes(Jn_dm, w)))
    return ca.Function("rigid_body", [x, u], [ca.vertcat(q_dot, w_dot)])


def _path_function(problem: ManeuverProblem, scaling: _Scaling, cone_margin: float,
                   wheel_momentum_max: float | None):
    """Path constraints ``g(x, u) ≤ 0`` (cones, wheel momentum) or None when there are none."""
    x, u = ca.SX.sym("x", 7), ca.SX.sym("u", 3)
    r = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
    g = []
    if problem.cones:
        b = ca.mtimes(_dcm_sx(x[:4]), ca.DM(r))
        for c in problem.cones:
            g.append(ca.dot(ca.DM(c.direction), b) - np.cos(c.half_angle + cone_margin))
    if wheel_momentum_max is not None:
        G = problem.spacecraft.wheel_axes
        h_per_rate = scaling.J0 / scaling.tu / (wheel_momentum_max * (1 - BOUND_MARGIN))
        h_w = ca.mtimes(ca.DM(np.linalg.pinv(G) @ scaling.Jn * h_per_rate), x[4:])
        g += [h_w - 1, -h_w - 1]
    if not g:
        return None
    return ca.Function("path", [x, u], [ca.vertcat(*g)])


def _perpendicular_basis(s: np.ndarray) -> np.ndarray:
    a = np.array([1.0, 0.0, 0.0]) if abs(s[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(s, a)
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, np.cross(s, e1)])


def _transcription(problem: ManeuverProblem, scaling: _Scaling, mesh: np.ndarray, opts: dict,
                   tf_bounds: tuple[float, float]) -> col.Transcription:
    rate_bound = np.inf if opts["rate_max"] is None else opts["rate_max"] * scaling.tu * (1 - BOUND_MARGIN)
    path = _path_function(problem, scaling, opts["cone_margin"], opts["wheel_momentum_max"])
    phase = col.Phase(rigid_body_dynamics(scaling.Jn), mesh, control=opts["control"],
                      state_bounds=([-1.1] * 4 + [-rate_bound] * 3, [1.1] * 4 + [rate_bound] * 3),
                      control_bounds=(-1.0, 1.0), duration_bounds=tf_bounds, path=path,
                      path_bounds=(-np.inf, 0.0), name="slew")
    tr = col.Transcription([phase])
    v = tr.variables(0)
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    tr.bound_state(0, 0, np.concatenate([q0, np.zeros(3)]))
    tr.bound_state(0, -1, [-1.1] * 4 + [0.0] * 3, [1.1] * 4 + [0.0] * 3)
    q_end = v.x_end[:4]
    if problem.sensor_target is None:
        qf = rot.normalize(np.asarray(problem.q_final, float))
        err = _quat_mul_sx(ca.DM(rot.conjugate(qf)), q_end)
        tr.add_constraint(err[:3], 0.0, 0.0)
    else:
        s = np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
        r = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
        b = ca.mtimes(_dcm_sx(q_end), ca.DM(r))
        tr.add_constraint(ca.mtimes(ca.DM(_perpendicular_basis(s)), b), 0.0, 0.0)
        tr.add_constraint(ca.dot(ca.DM(s), b), 0.0, np.inf)
    tr.minimize(v.duration)
    return tr


# -- warm starts -----------------------------------------------------------------------------------

def _leg_route_functions(problem: ManeuverProblem, scaling: _Scaling, legs):
    """Continuous bang-bang motion along a leg sequence: path angle s(t) accelerates for half the
    time and brakes for the other half with the smallest per-leg axis acceleration.
    Returns (tf, state(t), control(t)) in normalised units."""
    legs = [l for l in legs if l.angle > 1e-9] or [baselines.AxisLeg(np.array([0.0, 0.0, 1.0]), 1e-6)]
    q = rot.normalize(np.asarray(problem.q_initial, float))
    starts, axes_body, cum = [], [], [0.0]
    total = sum(l.angle for l in legs)
    alpha = np.inf
    for l in legs:
        e = rot.dcm(q).T @ l.axis
        alpha = min(alpha, baselines.axis_acceleration(scaling.Jn, e, total, 1.0))
        starts.append(q)
        axes_body.append(e)
        q = rot.multiply(rot.from_axis_angle(l.axis, l.angle), q)
        cum.append(cum[-1] + l.angle)
    tf = 2.0 * np.sqrt(total / alpha)
    cum = np.array(cum)

    def law(t):
        t = np.clip(t, 0.0, tf)
        first = t <= tf / 2
        s = np.where(first, 0.5 * alpha * t**2, total - 0.5 * alpha * (tf - t) ** 2)
        sd = np.where(first, alpha * t, alpha * (tf - t))
        sdd = np.where(first, alpha, -alpha)
        k = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(legs) - 1)
        return s, sd, sdd, k

    axes = np.array([l.axis for l in legs])
    starts = np.array(starts)
    axes_body = np.array(axes_body)

    def state(t):
        s, sd, _, k = law(np.asarray(t, float))
        q = rot.multiply(rot.from_axis_angle(axes[k], s - cum[k]), starts[k])
        return np.concatenate([q, axes_body[k] * sd[:, None]], axis=1)

    def control(t):
        _, sd, sdd, k = law(np.asarray(t, float))
        E = axes_body[k]
        JE = E @ scaling.Jn.T
        u = JE * sdd[:, None] + sd[:, None] ** 2 * np.cross(E, JE)
        return np.clip(u, -1.0, 1.0)

    return tf, state, control


def _plan_route_functions(plan: ManeuverPlan, scaling: _Scaling):
    """Warm start from another method's plan (its reference states and torques, normalised)."""
    tn = np.asarray(plan.t, float) / scaling.tu
    tf = float(tn[-1])

    def state(t):
        q = np.stack([np.interp(t, tn, plan.q[:, j]) for j in range(4)], axis=-1)
        w = np.stack([np.interp(t, tn, plan.omega[:, j]) for j in range(3)], axis=-1) * scaling.tu
        return np.concatenate([rot.normalize(q), w], axis=-1)

    def control(t):
        u = np.stack([np.interp(t, tn, plan.torque[:, j]) for j in range(3)], axis=-1)
        return np.clip(u / scaling.torque_max, -1.0, 1.0)

    return tf, state, control


def _route_guess(problem, scaling, route: _Route, phase: col.Phase) -> col.PhaseGuess:
    if route.plan is not None:
        tf, state, control = _plan_route_functions(route.plan, scaling)
    else:
        tf, state, control = _leg_route_functions(problem, scaling, route.legs)
    return col.guess_from_functions(phase, tf, state, control)


def candidate_routes(problem: ManeuverProblem, scaling: _Scaling, tilt_deg: float = 45.0,
                     ride_margin_deg: float = 2.0) -> list[_Route]:
    """Cheap, diverse routes: eigenaxis both ways, the eigenaxis midpoint tilted about two axes
    perpendicular to it (±), and every cone-riding λ-rotation sequence. Each gets its bang-bang
    duration estimate and its minimum cone margin.

    With a semi-free target whose ``q_final`` also points the sensor at it, the routes to
    ``q_final`` are added (labelled "full goal"): every fully specified plan is feasible for the
    semi-free problem, so they seed the semi-free search with the fully specified optima."""
    routes = _goal_routes(problem, scaling, tilt_deg, ride_margin_deg)
    if problem.sensor_target is not None:
        r = np.asarray(problem.sensor_axis, float)
        b = rot.dcm(rot.normalize(np.asarray(problem.q_final, float))) @ r
        s = np.asarray(problem.sensor_target, float)
        if b @ s / np.linalg.norm(b) / np.linalg.norm(s) > np.cos(np.deg2rad(0.5)):
            full = replace(problem, sensor_target=None)
            for rt in _goal_routes(full, scaling, tilt_deg, ride_margin_deg):
                rt.label += " (full goal)"
                routes.append(rt)
    return routes


def _goal_routes(problem: ManeuverProblem, scaling: _Scaling, tilt_deg: float,
                 ride_margin_deg: float) -> list[_Route]:
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    q_goal = baselines.goal_attitude(problem)
    eig = baselines.eigenaxis_leg(q0, q_goal)
    routes = [_Route("eigenaxis", [eig])]
    if eig.angle < np.pi - 1e-3:
        routes.append(_Route("eigenaxis long way", [baselines.AxisLeg(-eig.axis, 2 * np.pi - eig.angle)]))
    a = eig.axis
    n1 = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    n1 /= np.linalg.norm(n1)
    n2 = np.cross(a, n1)
    q_half = rot.multiply(rot.from_axis_angle(a, eig.angle / 2), q0)
    for name, n in (("n1", n1), ("n2", n2)):
        for sign in (+1, -1):
            q_mid = rot.multiply(rot.from_axis_angle(n, sign * np.deg2rad(tilt_deg)), q_half)
            routes.append(_Route(f"tilted {'+' if sign > 0 else '-'}{name}",
                                 [baselines.eigenaxis_leg(q0, q_mid), baselines.eigenaxis_leg(q_mid, q_goal)]))
    for c in range(len(problem.cones)):
        for side in (+1, -1):
            for finish in ("eigenaxis", "roll"):
                legs = baselines.cone_riding_legs(problem, c, side, np.deg2rad(ride_margin_deg), finish)
                if legs is not None:
                    name = problem.cones[c].name or str(c)
                    routes.append(_Route(f"ride {name} {'+' if side > 0 else '-'} {finish}", legs))
    for rt in routes:
        tf, state, _ = _leg_route_functions(problem, scaling, rt.legs)
        rt.tf_estimate = tf
        m = margins(state(np.linspace(0.0, tf, 400))[:, :4], problem.sensor_axis, problem.cones)
        rt.min_margin = float(m.min()) if m.size else np.inf
    return routes


def select_routes(routes: list[_Route], count: int) -> list[_Route]:
    """``count`` routes: those clearing the cones by increasing duration, then the least violating."""
    clear = sorted([r for r in routes if r.min_margin >= 0], key=lambda r: r.tf_estimate)
    blocked = sorted([r for r in routes if r.min_margin < 0], key=lambda r: -r.min_margin)
    return (clear + blocked)[:count]


# -- the planner -----------------------------------------------------------------------------------

def _scaling(problem: ManeuverProblem) -> _Scaling:
    J = problem.spacecraft.inertia
    J0 = float(np.linalg.eigvalsh(J).max())
    return _Scaling(baselines.time_unit(problem), J0, J / J0, float(problem.spacecraft.body_torque_max))


def _plan_arrays(sol: col.PhaseSolution, scaling: _Scaling):
    t = sol.t * scaling.tu
    torque = np.clip(sol.control_samples() * scaling.torque_max, -scaling.torque_max, scaling.torque_max)
    q = rot.normalize(sol.x[:, :4])
    omega = sol.x[:, 4:] / scaling.tu
    return t, torque, q, omega


def _truth_violation_intervals(traj, sol: col.PhaseSolution, scaling: _Scaling, problem) -> np.ndarray:
    """Mesh intervals containing dense truth samples with a negative cone margin."""
    m = margins(traj.q, problem.sensor_axis, problem.cones)
    if not m.size:
        return np.array([], int)
    bad_t = traj.t[m.min(axis=1) < 0] / scaling.tu / sol.duration
    return np.unique(np.clip(np.searchsorted(sol.phase.mesh, bad_t, side="right") - 1, 0, sol.phase.intervals - 1))


def _blocked_endpoints(problem: ManeuverProblem) -> str:
    """Why no plan can exist when the sensor starts or must end inside a keep-out cone, else ''."""
    r = np.asarray(problem.sensor_axis, float)
    ends = {"initial": rot.dcm(rot.normalize(np.asarray(problem.q_initial, float))) @ r}
    if problem.sensor_target is None:
        ends["final"] = rot.dcm(rot.normalize(np.asarray(problem.q_final, float))) @ r
    else:
        ends["target"] = np.asarray(problem.sensor_target, float)
    for name, b in ends.items():
        b = b / np.linalg.norm(b)
        for i, c in enumerate(problem.cones):
            if np.arccos(np.clip(b @ c.direction, -1, 1)) < c.half_angle:
                return f"infeasible request: the {name} sensor direction is inside keep-out cone {c.name or i}"
    return ""


def _failed(message: str, start: float, stats: dict | None = None) -> ManeuverPlan:
    return ManeuverPlan(METHOD, np.zeros(1), np.zeros((1, 3)), np.zeros((1, 4)), np.zeros((1, 3)),
                        status=STATUS_FAILED, message=message, solve_seconds=time.monotonic() - start,
                        stats=stats or {})


def plan_time_optimal(problem: ManeuverProblem, *, intervals: int = 30, max_intervals: int = 120,
                      starts: int = 6, refine_rounds: int = 3, interpolation: str = "zoh",
                      cone_margin_deg: float = 0.05, rate_max: float | None = None,
                      wheel_momentum_max: float | None = None, warm_starts: tuple = (),
                      smooth_warm_start: bool = False, explore_tol: float = 1e-5, tol: float = 1e-7, max_iter: int = 400,
                      attitude_tol_deg: float = 0.5, verify_reserve: float = 1.0) -> ManeuverPlan:
    """Minimum-time rest-to-rest slew with per-axis torque limits and keep-out cones.

    Options: ``intervals`` coarse mesh for the multi-start stage; ``max_intervals`` cap on mesh
    refinement; ``starts`` number of cheap routes solved (best kept, all reported in
    ``stats['starts']``); ``refine_rounds`` bisection rounds around switches / between-node cone
    violations; ``interpolation`` 'zoh' (torque constant per interval) or 'linear' (torque linear
    between nodes); ``cone_margin_deg`` tightening of every cone at the collocation points;
    ``rate_max`` body-rate bound (rad/s per axis); ``wheel_momentum_max`` per-wheel momentum bound
    (N m s); ``warm_starts`` plans of other methods used as extra starting routes;
    ``smooth_warm_start`` adds the smooth Slepian plan (:func:`att_planner.slepian.plan_slepian`,
    paper basis M = 4, at most a third of the remaining budget) to them;
    ``explore_tol``/``tol`` IPOPT tolerances of the two stages; ``max_iter`` per solve;
    ``attitude_tol_deg`` verification tolerance; ``verify_reserve`` seconds kept before
    ``problem.deadline`` for the final verification.
    """
    start = time.monotonic()
    if interpolation not in ("zoh", "linear"):
        raise ValueError("interpolation must be 'zoh' or 'linear'")
    if intervals < 4 or max_intervals < intervals:
        raise ValueError("intervals must be ≥ 4 and max_intervals ≥ intervals")
    if starts < 1:
        raise ValueError("starts must be ≥ 1")
    if rate_max is not None and not rate_max > 0:
        raise ValueError("rate_max must be positive (rad/s) or None")
    if wheel_momentum_max is not None and not wheel_momentum_max > 0:
        raise ValueError("wheel_momentum_max must be positive (N m s) or None")
    T = problem.spacecraft.body_torque_max
    if not np.isfinite(T) or T <= 0:
        return _failed("the spacecraft has no finite body torque limit (body_torque_max)", start)
    blocked = _blocked_endpoints(problem)
    if blocked:
        return _failed(blocked, start)
    if baselines.eigenaxis_leg(problem.q_initial, baselines.goal_attitude(problem)).angle < 1e-9:
        q0 = rot.normalize(np.asarray(problem.q_initial, float))
        return ManeuverPlan(METHOD, np.zeros(1), np.zeros((1, 3)), q0[None], np.zeros((1, 3)), interpolation,
                            STATUS_OPTIMAL, "already at the goal", time.monotonic() - start, {"tf": 0.0})
    scaling = _scaling(problem)
    opts = {"rate_max": rate_max, "wheel_momentum_max": wheel_momentum_max,
            "cone_margin": np.deg2rad(cone_margin_deg),
            "control": "constant" if interpolation == "zoh" else "linear"}
    solve_deadline = None if problem.deadline is None else problem.deadline - verify_reserve
    budget_hit = False

    def expired():
        return solve_deadline is not None and time.monotonic() > solve_deadline

    phase_seconds = {}
    lap = time.monotonic()
    if smooth_warm_start:
        share = None if problem.deadline is None else time.monotonic() + (problem.deadline - time.monotonic()) / 3
        from att_planner.slepian import plan_slepian   # only here: keeps scipy.signal out of plain solves

        smooth = plan_slepian(replace(problem, deadline=share), M=4)
        warm_starts = (*warm_starts, smooth)           # a failed plan is empty and dropped below
        phase_seconds["smooth_warm_start"] = time.monotonic() - lap
        lap = time.monotonic()
    routes = select_routes(candidate_routes(problem, scaling), starts)
    routes += [_Route(f"warm start: {p.method}", plan=p, tf_estimate=p.duration / scaling.tu,
                      min_margin=float(margins(p.q, problem.sensor_axis, problem.cones).min(initial=np.inf)))
               for p in warm_starts if len(p.t) > 1]
    tf_scale = max(r.tf_estimate for r in routes if np.isfinite(r.tf_estimate))
    tf_bounds = (1e-2 * tf_scale, 10.0 * tf_scale)

    # Stage 1: every route on the coarse mesh.
    mesh = col.uniform_mesh(intervals)
    # expand=True (SX evaluation) costs ~0.5 s to build but halves every solve: worth it for the
    # several starts of this stage, not for the single solve per refined mesh below.
    tr = _transcription(problem, scaling, mesh, opts, tf_bounds).build(
        tol=explore_tol, max_iter=max_iter, nlpsol_options={"expand": len(routes) > 2})
    start_log, solved = [], []
    for rt in routes:
        if expired():
            budget_hit = True
            break
        guess = _route_guess(problem, scaling, rt, tr.phases[0])
        res = tr.solve(tr.pack([guess]), deadline=solve_deadline)
        start_log.append({"route": rt.label, "tf_guess": rt.tf_estimate * scaling.tu,
                          "route_min_margin": rt.min_margin, "tf": res.objective * scaling.tu,
                          "status": res.status, "iterations": res.iterations, "seconds": res.seconds})
        if res.success and res.constraint_violation < 1e-5:
            solved.append((res.objective, rt.label, res))
    stats = {"starts": start_log, "time_unit": scaling.tu, "seconds": phase_seconds}
    phase_seconds["routes_and_starts"], lap = time.monotonic() - lap, time.monotonic()
    if not solved:
        statuses = sorted({s["status"] for s in start_log})
        return _failed("no start converged" + (" before the deadline" if budget_hit else "")
                       + (f" (IPOPT: {', '.join(statuses)})" if statuses else ""), start, stats)
    solved.sort(key=lambda s: s[0])
    _, best_label, res = solved[0]
    stats["best_start"] = best_label

    # Stage 2: refine the best solution around switches and between-node cone violations.
    sol = tr.phase_solution(res.w)
    history = [(sol, res)]
    mesh_log = [{"intervals": tr.phases[0].intervals, "tf": res.objective * scaling.tu,
                 "status": res.status, "seconds": res.seconds}]
    extra = []

    def resolve(new_mesh):
        nonlocal tr, sol, res
        new_tr = _transcription(problem, scaling, new_mesh, opts, tf_bounds).build(tol=tol, max_iter=max_iter)
        new_res = new_tr.solve(new_tr.pack([sol.resample(new_tr.phases[0])]), deadline=solve_deadline)
        mesh_log.append({"intervals": new_tr.phases[0].intervals, "tf": new_res.objective * scaling.tu,
                         "status": new_res.status, "seconds": new_res.seconds})
        if new_res.success and new_res.constraint_violation < 1e-5:
            tr, res = new_tr, new_res
            sol = tr.phase_solution(res.w)
            history.append((sol, res))
            return True
        return False

    for _ in range(refine_rounds):
        if expired():
            budget_hit = True
            break
        bad, _ = col.path_violations(sol, tol=1e-4)
        split = np.union1d(bad, col.switch_intervals(sol, limit=max(4, sol.phase.intervals // 4)))
        if not len(split) or sol.phase.intervals >= max_intervals:
            break
        if not resolve(col.refine_mesh(sol.phase.mesh, split, max_intervals)):
            break

    phase_seconds["refinement"], lap = time.monotonic() - lap, time.monotonic()

    # Stage 3: truth verification; refine where the dense truth grid leaves a cone.
    def verify(s: col.PhaseSolution):
        t, torque, q, omega = _plan_arrays(s, scaling)
        goal = None if problem.sensor_target is None else q[-1]
        ok, info, traj = baselines.verify_plan(problem, t, torque, interpolation, goal,
                                               attitude_tol=np.deg2rad(attitude_tol_deg))
        # the optional bounds, on the truth trajectory (relative tolerance 1e-3)
        if rate_max is not None:
            info["body_rate_ratio"] = float(np.abs(traj.omega).max() / rate_max)
            ok = ok and info["body_rate_ratio"] <= 1 + 1e-3
        if wheel_momentum_max is not None:
            h_w = traj.omega @ (np.linalg.pinv(problem.spacecraft.wheel_axes) @ problem.spacecraft.inertia).T
            info["wheel_momentum_ratio"] = float(np.abs(h_w).max() / wheel_momentum_max)
            ok = ok and info["wheel_momentum_ratio"] <= 1 + 1e-3
        return ok, info, traj, (t, torque, q, omega)

    ok, info, traj, arrays = verify(sol)
    while not ok and not expired() and sol.phase.intervals < max_intervals:
        bad = _truth_violation_intervals(traj, sol, scaling, problem)
        if not len(bad):
            bad = np.arange(sol.phase.intervals)
        extra.append(len(bad))
        if not resolve(col.refine_mesh(sol.phase.mesh, bad, max_intervals)):
            break
        ok, info, traj, arrays = verify(sol)
    if expired():
        budget_hit = True
    if not ok and len(history) > 1:
        # an earlier (coarser) solution may still pass, if there is time to check it
        for s_prev, r_prev in reversed(history[:-1]):
            if problem.time_left() <= 0:
                break
            ok_p, info_p, _, arrays_p = verify(s_prev)
            if ok_p:
                ok, info, arrays, res, sol = ok_p, info_p, arrays_p, r_prev, s_prev
                break

    phase_seconds["verification"] = time.monotonic() - lap
    t, torque, q, omega = arrays
    stats.update({"tf": float(t[-1]), "mesh": mesh_log, "truth_refinements": extra,
                  "intervals": sol.phase.intervals, "verification": info,
                  "ipopt_status": res.status})
    if not ok:
        status = STATUS_FAILED
        message = (f"best solution (t_f = {t[-1]:.4g} s) fails truth verification: final error "
                   f"{np.rad2deg(info['final_attitude_error']):.3f} deg, min cone margin "
                   f"{np.rad2deg(info['min_cone_margin']):.3f} deg")
    elif budget_hit:
        status, message = STATUS_BUDGET, "time budget expired; best verified plan returned"
    else:
        status = STATUS_OPTIMAL if res.status == "Solve_Succeeded" else STATUS_FEASIBLE
        message = f"best of {len(start_log)} starts: {best_label}; {sol.phase.intervals} intervals"
    return ManeuverPlan(METHOD, t, torque, q, omega, interpolation, status, message,
                        time.monotonic() - start, stats)
