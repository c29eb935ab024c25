"""The time-optimal slew as a collocation NLP (see :mod:`.planner` for the problem statement):
normalisation, the CasADi rigid-body model, path constraints and the Hermite–Simpson transcription."""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from att_planner.cones import ARC_TOLERANCE, BOUNDARY_TOLERANCE, END_RAMP, SMOOTH_END_RAMP, boundary_end_zones, end_ramp
from att_planner.methods import symbolic
from att_planner.methods.axis_rotations import time_unit
from att_planner.methods.time_optimal import collocation as col
from att_planner.problem import ManeuverProblem
from att_planner.zones import clenshaw
from att_sim.models import rotations as rot

# Relative tightening of the rate and wheel-momentum bounds at the collocation points, so that
# the truth trajectory between them stays within the bound itself.
BOUND_MARGIN = 2e-3
# The band (rad) outside its boundary in which the collocation points of a forced boundary arc lie:
# half the verification's ARC_TOLERANCE, the other half for the truth between the points.
ARC_BAND = 0.5 * ARC_TOLERANCE


@dataclass
class Scaling:
    tu: float            # s per time unit
    J0: float            # kg m²
    Jn: np.ndarray       # J / J0
    torque_max: float    # N m


def scaling(problem: ManeuverProblem) -> Scaling:
    J = problem.spacecraft.inertia
    J0 = float(np.linalg.eigvalsh(J).max())
    return Scaling(time_unit(problem), J0, J / J0, float(problem.spacecraft.body_torque_max))


def rigid_body_dynamics(Jn: np.ndarray, smooth: bool = False) -> ca.Function:
    """Normalised ``ẋ = f(x, u)`` with ``x = [q (xyzw), ω̃]`` and the torque ``u`` (:mod:`.planner`
    docstring); ``smooth``: ``x = [q, ω̃, u, u̇]`` and the control the torque's second derivative
    (:mod:`.smooth`)."""
    x, c = ca.SX.sym("x", 13 if smooth else 7), ca.SX.sym("c", 3)
    q, w = x[:4], x[4:7]
    u = x[7:10] if smooth else c
    Jn_dm = ca.DM(Jn)
    q_dot = 0.5 * symbolic.quat_mul(q, ca.vertcat(w, 0)) + 0.5 * (1 - ca.dot(q, q)) * q
    w_dot = ca.solve(Jn_dm, u - ca.cross(w, ca.mtimes(Jn_dm, w)))
    rates = ca.vertcat(q_dot, w_dot, x[10:], c) if smooth else ca.vertcat(q_dot, w_dot)
    return ca.Function("smooth_rigid_body" if smooth else "rigid_body", [x, c], [rates])


ZONE_PARAMETERS = 8      # per fixed zone: σ (+1 keep-out, -1 keep-in), sensor (3), axis (3), cos(θ + σ δ)
MOTION_DEGREES = (8, 16)   # a moving zone fitted by one Chebyshev series of at most such a degree is a parameter


def motion_parameters(degree: int) -> int:
    """Parameters per moving zone: σ, sensor (3), α, β, the series' coefficients (axis, θ + σ δ)."""
    return 6 + 4 * (degree + 1)


def motion_degree(zones) -> int | None:
    """The smallest of :data:`MOTION_DEGREES` that holds every moving zone's fit when each is one
    series, else None (no moving zone: the smallest)."""
    fits = [zones.series(z) for z, zone in enumerate(zones.zones) if zone.body != "inertial"]
    if any(len(f) > 1 for f in fits):
        return None
    needed = max((len(f[0]) - 1 for f in fits), default=0)
    return next((d for d in MOTION_DEGREES if d >= needed), None)


def wheel_rows(problem: ManeuverProblem) -> int:
    """Wheels whose speeds the plan keeps within their limit (none without wheels or a finite limit)."""
    sc = problem.spacecraft
    return sc.n_wheels if sc.n_wheels and sc.wheel_inertia > 0 and math.isfinite(sc.wheel_speed_max) else 0


def wheel_speed_values(problem: ManeuverProblem, s: Scaling) -> np.ndarray:
    """The data of :func:`wheel_speed_constraints`: ``M₁ = G⁺ / (I_w Ω̄)``, ``M₂ = (G⁺ J / I_w + Gᵀ) / (τ_u Ω̄)``
    (column-major), ``a = (Ω₀ − G⁺ G Ω₀) / Ω̄`` and ``H_N`` (N m s), ``Ω̄`` the limit tightened by
    :data:`BOUND_MARGIN`: the relative speeds over ``Ω̄`` are ``a + M₁ Rᵀ H_N − M₂ ω̃``
    (:func:`att_planner.verification.body_plan_wheel_speeds`)."""
    sc = problem.spacecraft
    limit = sc.wheel_speed_max * (1 - BOUND_MARGIN)
    speeds0 = np.zeros(sc.n_wheels) if problem.wheel_speeds is None else np.asarray(problem.wheel_speeds, float)
    h0_B = sc.wheel_axes @ (sc.wheel_inertia * speeds0)
    M1 = sc.wheel_axes_pinv / (sc.wheel_inertia * limit)
    M2 = (sc.wheel_axes_pinv @ sc.inertia / sc.wheel_inertia + sc.wheel_axes.T) / (s.tu * limit)
    a = (speeds0 - sc.wheel_axes_pinv @ h0_B / sc.wheel_inertia) / limit
    H_N = rot.dcm_NB(rot.normalize(np.asarray(problem.q_initial, float))) @ h0_B
    return np.concatenate([M1.ravel(order="F"), M2.ravel(order="F"), a, H_N])


def wheel_speed_constraints(R, w, p, n: int) -> list:
    """``g ≤ 0`` keeping ``n`` wheels' relative speeds within ``±Ω̄`` at attitude ``R`` and normalised
    rate ``w`` (``p``: :func:`wheel_speed_values`)."""
    M1, M2 = ca.reshape(p[:3 * n], n, 3), ca.reshape(p[3 * n:6 * n], n, 3)
    a, H_N = p[6 * n:7 * n], p[7 * n:7 * n + 3]
    v = a + ca.mtimes(M1, ca.mtimes(R.T, H_N)) - ca.mtimes(M2, w)
    return [v - 1, -v - 1]


def path_function(problem: ManeuverProblem, s: Scaling, n_state: int = 7, cone_margin: float = 0.0):
    """``(path, degree)``: the path constraints ``g ≤ 0`` (zones, wheel speeds, wheel momentum) as a CasADi
    Function ``(x, u[, t][, p]) -> g`` (``x`` has ``n_state`` rows, the attitude and rate first;
    None when there are none), the data of the problem in ``p`` (:func:`path_values`), and the
    degree of the moving zones' series in ``p`` (:func:`motion_degree`; None: they are constants).

    Every zone of ``problem.zone_sky()`` (:mod:`att_planner.zones`: the cones, then the zones, each
    with its own sensor axis ``s_z``, ``b_z = R(q) s_z``) is tightened by ``δ``: keep-out
    ``a_z · b_z ≤ cos(θ_z + δ)``, keep-in ``a_z · b_z ≥ cos(θ_z − δ)``, i.e.
    ``σ_z (a_z · b_z − cos(θ_z + σ_z δ)) ≤ 0``. A fixed zone's data are in ``p``
    (:data:`ZONE_PARAMETERS`). When a zone moves, ``t`` is the normalised time from the start and
    ``a_z``, ``θ_z`` are the FittedZones' Chebyshev series of ``t τ_u``, so the collocation couples them
    exactly to ``t_f``: their coefficients are in ``p`` too (:func:`motion_parameters`, the series in
    ``x = α t + β``) when every moving zone is one series of a degree of :data:`MOTION_DEGREES`,
    otherwise the series are constants of the function (tightened by ``cone_margin``). The wheels'
    momentum bound takes its scale from ``p`` (its last value). So the function depends on the
    problem's shape only, but for moving zones of many pieces. The wheels' speeds relative to the body
    stay within their limit (:func:`wheel_speed_constraints`, their data in ``p`` too: the momentum
    stored at the start and the slew's)."""
    zones = problem.zone_sky()
    fixed = [z.body == "inertial" for z in zones.zones]
    degree = motion_degree(zones)
    moving = 0 if degree is None else len(fixed) - sum(fixed)
    momentum = math.isfinite(problem.wheel_momentum_max) and problem.spacecraft.n_wheels > 0   # no wheels: none
    wheels = wheel_rows(problem)
    x, u, t = ca.SX.sym("x", n_state), ca.SX.sym("u", 3), ca.SX.sym("t")
    per_zone = 0 if degree is None else motion_parameters(degree)
    p = ca.SX.sym("p", ZONE_PARAMETERS * sum(fixed) + per_zone * moving + 7 * wheels + 3 * bool(wheels) + momentum)
    R = symbolic.dcm_NB(x[:4])
    g = []
    for k in range(sum(fixed)):
        sign, sensor, axis, cos = (p[ZONE_PARAMETERS * k], p[ZONE_PARAMETERS * k + 1:ZONE_PARAMETERS * k + 4],
                                   p[ZONE_PARAMETERS * k + 4:ZONE_PARAMETERS * k + 7], p[ZONE_PARAMETERS * k + 7])
        g.append(sign * (ca.dot(axis, ca.mtimes(R, sensor)) - cos))
    for k in range(moving):
        o = ZONE_PARAMETERS * sum(fixed) + per_zone * k
        sign, sensor, alpha, beta = p[o], p[o + 1:o + 4], p[o + 4], p[o + 5]
        rows = [p[o + 6 + 4 * i:o + 10 + 4 * i] for i in range(degree + 1)]
        value = clenshaw(alpha * t + beta, rows)
        g.append(sign * (ca.dot(value[:3], ca.mtimes(R, sensor)) - ca.cos(value[3])))
    if zones.moving and degree is None:
        g += [c for c, f in zip(zones.casadi_constraints(t * s.tu, R, cone_margin), fixed) if not f]
    if wheels:
        o = ZONE_PARAMETERS * sum(fixed) + per_zone * moving
        g += wheel_speed_constraints(R, x[4:7], p[o:o + 7 * wheels + 3], wheels)
    if momentum:
        h_w = ca.mtimes(ca.DM(problem.spacecraft.wheel_axes_pinv @ s.Jn), x[4:7]) * p[-1]
        g += [h_w - 1, -h_w - 1]
    if not g:
        return None, degree
    inputs = [x, u] + ([t] if zones.moving else []) + ([p] if p.numel() else [])
    return ca.Function("path", inputs, [ca.vertcat(*g)]), degree


def path_values(problem: ManeuverProblem, s: Scaling, cone_margin: float) -> np.ndarray:
    """The values of :func:`path_function`'s ``p``: each fixed zone's σ, unit sensor axis, axis and
    ``cos(θ + σ δ)`` (``δ = cone_margin``); each moving zone's σ, unit sensor axis, α = 2 τ_u/(b − a)
    and β = −(a + b)/(b − a) of its series on [a, b] and the coefficients (zero-padded to
    :func:`motion_degree`, θ's first one raised by σ δ), when they are parameters; then the
    wheels' data (:func:`wheel_speed_values`) and the momentum bound's scale."""
    zones = problem.zone_sky()
    degree = motion_degree(zones)
    axes, half = zones.at(0.0)
    fixed, moving = [], []
    for z, zone in enumerate(zones.zones):
        sign = -1.0 if zone.keep_in else 1.0
        sensor = zones.sensor_axes[z] / np.linalg.norm(zones.sensor_axes[z])
        if zone.body == "inertial":
            fixed += [[sign], sensor, axes[z], [math.cos(half[z] + sign * cone_margin)]]
        elif degree is not None:
            (coef,), (a, b) = zones.series(z), zones.pieces
            padded = np.zeros((degree + 1, 4))
            padded[:len(coef)] = coef
            padded[0, 3] += sign * cone_margin
            moving += [[sign], sensor, [2 * s.tu / (b - a), -(a + b) / (b - a)], padded.ravel()]
    values = fixed + moving + ([wheel_speed_values(problem, s)] if wheel_rows(problem) else [])
    if math.isfinite(problem.wheel_momentum_max) and problem.spacecraft.n_wheels:
        values.append([s.J0 / s.tu / (problem.wheel_momentum_max * (1 - BOUND_MARGIN))])
    return np.concatenate(values) if values else np.zeros(0)


def goal_kind(problem: ManeuverProblem) -> str:
    """'moving' (a pointing law's attitude and rate at t_f), 'fixed' (``q_final`` at rest) or 'semi' (semi-free)."""
    if problem.goal_motion is not None:
        return f"moving {len(problem.goal_motion.coefficients)}"
    return "fixed" if problem.sensor_target is None else "semi"


def goal_values(problem: ManeuverProblem, s: Scaling) -> np.ndarray:
    """The final-attitude constraint's data: ``q_final``, or the semi-free goal's unit
    ``sensor_target``, the two rows of a basis normal to it and the unit sensor axis, or a moving
    goal's series (:func:`moving_goal_values`)."""
    if problem.goal_motion is not None:
        return moving_goal_values(problem, s)
    if problem.sensor_target is None:
        return rot.normalize(np.asarray(problem.q_final, float))
    target = np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
    r = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
    return np.concatenate([target, *rot.orthonormal_basis(target), r])


def moving_goal_values(problem: ManeuverProblem, s: Scaling) -> np.ndarray:
    """A moving goal (:class:`att_planner.problem.MovingGoal`) as parameters:
    ``α = 2 τ_u / W``, ``β = −1`` and its series' coefficients of the attitude and the normalised
    rate ``ω τ_u`` in ``x = α t̃ + β`` (``t̃`` the normalised time) over its window ``[0, W]``."""
    goal = problem.goal_motion
    coefficients = goal.coefficients * np.r_[np.ones(4), np.full(3, s.tu)]
    return np.concatenate([[2.0 * s.tu / goal.window, -1.0], coefficients.ravel()])


def chebyshev_derivative(rows: list) -> list:
    """The coefficient rows of the derivative ``d/dx`` of the Chebyshev series of ``rows`` (c_0 first;
    numpy or CasADi): ``d_{k−1} = d_{k+1} + 2k c_k`` from the top, ``d_0`` halved."""
    n = len(rows) - 1
    if n < 1:
        return [0.0 * rows[0]]
    d = [0.0 * rows[0] for _ in range(n + 2)]
    for k in range(n, 0, -1):
        d[k - 1] = d[k + 1] + 2 * k * rows[k]
    d[0] = 0.5 * d[0]
    return d[:n]


def ties_end_torque(problem: ManeuverProblem) -> bool:
    """Whether a smooth plan onto ``problem``'s moving goal ends at the torque that tracks it
    (``J ω̇_g + ω_g × J ω_g`` at t_f): when that torque stays within the per-axis bound (less
    :data:`BOUND_MARGIN`) over the goal's whole window (else, near a ground pass of a slow
    spacecraft, no end could meet it: the end torque is left free)."""
    goal = problem.goal_motion
    if goal is None:
        return False
    _, omega, omega_dot = goal.series(np.linspace(0.0, goal.window, 4 * len(goal.coefficients) + 1))
    J = problem.spacecraft.inertia
    torque = omega_dot @ J.T + np.cross(omega, omega @ J.T)
    return bool(np.abs(torque).max() <= problem.spacecraft.body_torque_max * (1 - BOUND_MARGIN))


CACHE_SIZE = 64          # built NLPs kept (the oldest goes first)
_NLPS: dict = {}


def _state_bounds(problem: ManeuverProblem, s: Scaling, smooth: bool):
    """Bounds of the state: the quaternion's box, the rate bound (tightened by :data:`BOUND_MARGIN`)
    and, smooth, ``|u| ≤ 1``."""
    rate = problem.rate_max * s.tu * (1 - BOUND_MARGIN)
    if not smooth:
        return [-1.1] * 4 + [-rate] * 3, [1.1] * 4 + [rate] * 3
    return [-1.1] * 4 + [-rate] * 3 + [-1.0] * 3 + [-np.inf] * 3, [1.1] * 4 + [rate] * 3 + [1.0] * 3 + [np.inf] * 3


def _end_bounds(smooth: bool):
    """Bounds of the last node: at rest (and, smooth, no torque and no torque rate)."""
    rest = 9 if smooth else 3
    return [-1.1] * 4 + [0.0] * rest, [1.1] * 4 + [0.0] * rest


def weighted_path_function(problem: ManeuverProblem, s: Scaling, cone_margin: float, n_state: int = 7,
                           ramp: float = END_RAMP):
    """The path constraints of a problem with a boundary end or a forced boundary arc
    (:func:`boundary_case`): ``g ≤ 0`` (zones, wheel momentum) and the weight function of the phase
    (:class:`~.collocation.Phase` ``path_weight``), or None when there are none; ``x`` has
    ``n_state`` rows, the attitude and rate first. The problem's data are constants of the function.

    Every zone of ``problem.zone_sky()`` (:mod:`att_planner.zones`: the cones, then the zones, each
    with its own sensor axis ``s_z``, ``b_z = R(q) s_z``) is tightened by ``δ = cone_margin``: keep-out
    ``a_z · b_z ≤ cos(θ_z + δ)``, keep-in ``a_z · b_z ≥ cos(θ_z − δ)``. A zone with an end on its
    boundary (:func:`att_planner.cones.boundary_end_zones`) is tightened by ``−tol + (δ + tol) w(τ)``
    instead, ``w`` the end ramp (:func:`att_planner.cones.end_ramp` over ``ramp`` of the maneuver,
    the path's last input: a smooth plan leaves its ends more slowly than a bang-bang one). The
    forced boundary arc's cone is the band ``0 ≤ margin ≤ ε`` (:data:`ARC_BAND`): ``a · b ≤ cos θ`` and
    ``a · b ≥ cos(θ + ε)`` (an equality there would repeat the fixed start and the final pointing,
    which IPOPT cannot solve: rank-deficient constraints). When a zone moves,
    the function is ``(x, u, t[, w]) -> g`` with ``t`` the normalised time from the start: ``a_z(t τ_u)``
    and ``θ_z(t τ_u)`` are the FittedZones' Chebyshev series of that CasADi expression, so the
    collocation couples them exactly to ``t_f``. Without motion it is ``(x, u[, w]) -> g`` with the
    zones constant (no time dependence is built)."""
    x, u, t, w = ca.SX.sym("x", n_state), ca.SX.sym("u", 3), ca.SX.sym("t"), ca.SX.sym("w")
    zones = problem.zone_sky()
    ramped = boundary_end_zones(problem, cone_margin)
    margins = [-BOUNDARY_TOLERANCE + (cone_margin + BOUNDARY_TOLERANCE) * w if near else cone_margin
               for near in ramped]
    R = symbolic.dcm_NB(x[:4])
    if problem.boundary_cone is not None:
        margins[problem.boundary_cone] = 0.0
    g = zones.casadi_constraints(t * s.tu if zones.moving else 0.0, R, margins)
    if problem.boundary_cone is not None:           # the band 0 ≤ margin ≤ ARC_BAND of the arc's cone
        cone = problem.cones[problem.boundary_cone]
        r = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
        g.append(ca.cos(cone.half_angle + ARC_BAND) - ca.dot(ca.DM(cone.direction), ca.mtimes(R, ca.DM(r))))
    if wheel_rows(problem):
        g += wheel_speed_constraints(R, x[4:7], ca.DM(wheel_speed_values(problem, s)), wheel_rows(problem))
    if math.isfinite(problem.wheel_momentum_max) and problem.spacecraft.n_wheels:   # no wheels: no momentum
        h_per_rate = s.J0 / s.tu / (problem.wheel_momentum_max * (1 - BOUND_MARGIN))
        h_w = ca.mtimes(ca.DM(problem.spacecraft.wheel_axes_pinv @ s.Jn * h_per_rate), x[4:7])
        g += [h_w - 1, -h_w - 1]
    if not g:
        return None
    inputs = [x, u] + ([t] if zones.moving else []) + ([w] if ramped.any() else [])
    weight = functools.partial(end_ramp, length=ramp) if ramped.any() else None
    return ca.Function("path", inputs, [ca.vertcat(*g)]), weight


def boundary_case(problem: ManeuverProblem, cone_margin: float) -> bool:
    """Whether the problem has an end on a zone's boundary (ramped tightening) or a forced boundary
    arc: its path constraints are :func:`weighted_path_function`'s, built for it alone."""
    return problem.boundary_cone is not None or bool(boundary_end_zones(problem, cone_margin).any())


def transcription(problem: ManeuverProblem, s: Scaling, mesh: np.ndarray, control: str, cone_margin: float,
                  tf_bounds: tuple[float, float], *, torque_accel: float | None = None, tol: float = 1e-7,
                  max_iter: int = 400, expand: bool = True) -> col.Transcription:
    """The minimum-time NLP on ``mesh``, built (``control``: 'constant' for ZOH torques, 'linear';
    ``torque_accel``: the smooth NLP of :mod:`.smooth`, its bound on the torque's second derivative).

    The NLP is built once per shape and kept (:data:`CACHE_SIZE`): the spacecraft's inertia, the
    number of intervals, the zones' count and series degree (moving zones of many pieces: their
    FittedZones), the bounds on the
    rate and momentum, the kind of goal and the settings. The mesh, the zones' data, the goal and the
    momentum scale are its parameters, the start and the duration's bounds its variables' bounds
    (set here), so a second problem of that shape only copies it (:meth:`.collocation.Transcription.copy`).
    Moving zones (timed path constraints) keep one t_f; fixed ones chain copies of it per interval
    (a banded KKT system, far fewer iterations; with moving zones the copies took more). A problem
    with a boundary end or a forced boundary arc (:func:`boundary_case`) gets an NLP of its
    own, with :func:`weighted_path_function`'s constraints."""
    smooth = torque_accel is not None
    zones = problem.zone_sky()
    options = dict(tol=tol, max_iter=max_iter, nlpsol_options={"expand": expand},   # only the smooth plan is anytime
                   ipopt_options=None if smooth else col.MUMPS_OPTIONS, incumbents=smooth)
    if boundary_case(problem, cone_margin):            # its path constraints are built for it alone
        path, weight = weighted_path_function(problem, s, cone_margin, 13 if smooth else 7,
                                              SMOOTH_END_RAMP if smooth else END_RAMP) or (None, None)
        tr = _build(problem, s, mesh, control, path, torque_accel, not zones.moving, weight).build(**options)
        return _start(tr.copy(mesh, extra_values=goal_values(problem, s)), problem, s, smooth, tf_bounds)
    degree = motion_degree(zones)
    momentum = math.isfinite(problem.wheel_momentum_max)
    moving = sum(z.body != "inertial" for z in zones.zones)
    key = (smooth, torque_accel, s.Jn.tobytes(), len(mesh) - 1, control, sum(z.body == "inertial" for z in zones.zones),
           (moving, degree) if degree is not None else (id(zones), cone_margin),
           problem.spacecraft.wheel_axes.tobytes() if momentum else None, wheel_rows(problem), problem.rate_max,
           goal_kind(problem), smooth and ties_end_torque(problem), tol, max_iter, expand)
    if key not in _NLPS:
        while len(_NLPS) >= CACHE_SIZE:
            _NLPS.pop(next(iter(_NLPS)))
        path, _ = path_function(problem, s, 13 if smooth else 7, cone_margin)      # built only for a new shape
        _NLPS[key] = (_build(problem, s, mesh, control, path, torque_accel, not zones.moving,
                             path_parameters=path_values(problem, s, 0.0)).build(**options), zones)  # zones: kept alive
    tr = _NLPS[key][0].copy(mesh, path_values(problem, s, cone_margin), goal_values(problem, s))
    return _start(tr, problem, s, smooth, tf_bounds)


def _start(tr: col.Transcription, problem: ManeuverProblem, s: Scaling, smooth: bool, tf_bounds) -> col.Transcription:
    """``tr`` from the problem's start at rest, its duration within ``tf_bounds`` (and a moving
    goal's window)."""
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    tr.bound_state(0, 0, np.concatenate([q0, np.zeros(9 if smooth else 3)]))
    lower, upper = tf_bounds
    if problem.goal_motion is not None:
        upper = min(upper, problem.goal_motion.window / s.tu)
    tr.set_duration_bounds(0, min(lower, 0.5 * upper), upper)
    return tr


def _build(problem: ManeuverProblem, s: Scaling, mesh: np.ndarray, control: str, path, torque_accel,
           duration_copies: bool, weight=None, path_parameters=()) -> col.Transcription:
    """The parametric NLP of :func:`transcription` (not built): the mesh and the goal its parameters,
    and ``path_parameters`` the path's (``weight``: the path's weight of the mesh fractions)."""
    smooth = torque_accel is not None
    controls = (-torque_accel, torque_accel) if smooth else (-1.0, 1.0)
    phase = col.Phase(rigid_body_dynamics(s.Jn, smooth), mesh, control=control,
                      state_bounds=_state_bounds(problem, s, smooth), control_bounds=controls, path=path,
                      path_bounds=(-np.inf, 0.0), path_weight=weight, name="slew", path_parameters=path_parameters)
    goal = goal_values(problem, s)
    tr = col.Transcription([phase], duration_copies=duration_copies, parametric=True, extra_parameters=len(goal))
    v = tr.variables(0)
    q_end = v.x_end[:4]
    if problem.goal_motion is not None:            # on the moving goal at t_f, at its rate
        rows = [tr.extra[2 + 7 * i:9 + 7 * i] for i in range((len(goal) - 2) // 7)]
        x_f = tr.extra[0] * v.duration + tr.extra[1]
        target = clenshaw(x_f, rows)
        tr.add_constraint(symbolic.error_vector(q_end, target[:4]), 0.0, 0.0)
        tr.add_constraint(v.x_end[4:7] - target[4:7], 0.0, 0.0)
        if smooth and ties_end_torque(problem):     # and at the torque that tracks it
            rate, rate_dot = target[4:7], tr.extra[0] * clenshaw(x_f, chebyshev_derivative(rows))[4:7]
            Jn = ca.DM(s.Jn)
            tr.add_constraint(v.x_end[7:10] - ca.mtimes(Jn, rate_dot) - ca.cross(rate, ca.mtimes(Jn, rate)), 0.0, 0.0)
        tr.minimize(v.duration)
        return tr
    tr.bound_state(0, -1, *_end_bounds(smooth))
    if problem.sensor_target is None:
        tr.add_constraint(symbolic.error_vector(q_end, tr.extra), 0.0, 0.0)
    else:
        target, e1, e2, r = (tr.extra[3 * k:3 * k + 3] for k in range(4))
        b = ca.mtimes(symbolic.dcm_NB(q_end), r)
        tr.add_constraint(ca.vertcat(ca.dot(e1, b), ca.dot(e2, b)), 0.0, 0.0)
        tr.add_constraint(ca.dot(target, b), 0.0, np.inf)
    tr.minimize(v.duration)
    return tr


def plan_arrays(sol: col.PhaseSolution, s: Scaling):
    """SI arrays ``(t, torque, q, omega)`` of a normalised solution."""
    t = sol.t * s.tu
    torque = np.clip(sol.control_samples() * s.torque_max, -s.torque_max, s.torque_max)
    q = rot.normalize(sol.x[:, :4])
    omega = sol.x[:, 4:] / s.tu
    return t, torque, q, omega
