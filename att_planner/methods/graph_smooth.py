"""The constructive first plan: the quickest sequence of rest-to-rest λ-rotations that
takes the sensors round every zone, found on a graph of sensor directions and flown with a C¹ torque.

**Graph.** Nodes are directions of ``problem.sensor_axis``: its start and goal directions (the
``sensor_target`` of a semi-free goal) and :data:`NODES_PER_ZONE` directions on a circle
:data:`RIDE_MARGIN` outside each keep-out zone of that sensor (a zone that moves: about the zone as it
is at :data:`SNAPSHOTS` × the eigenaxis slew time). Edges are legs, each a rest-to-rest rotation
about an axis fixed in inertial space (and so in the body): the great circle between two nodes, a
ride round a zone's circle about the zone's axis, and into the goal attitude the eigenaxis rotation
from a node's attitude (from the goal direction it is the roll about it).

**Exact checks on every leg, not only at its ends.** A rotation by ϑ ∈ [0, φ] about the unit
axis n takes a direction b to ``b(ϑ) = (n·b) n + cos ϑ b⊥ + sin ϑ n × b⊥`` (``b⊥ = b − (n·b) n``),
so for a zone axis a::

    a·b(ϑ) = (n·b)(n·a) + A cos ϑ + B sin ϑ,   A = a·b⊥,  B = a·(n × b⊥)

whose extremes over [0, φ] are at the ends or at ϑ* = atan2(B, A) (the maximum ``(n·b)(n·a) + √(A²+B²)``)
and ϑ* + π (the minimum), in closed form (:func:`arc_cosines`). Every zone of every sensor is
checked on every leg with :data:`EDGE_MARGIN` (each sensor's direction follows from the attitude
the leg starts from), but a leg from the start or to the goal only with −BOUNDARY_TOLERANCE from a
zone that end lies on (an end on a boundary, :mod:`att_planner.cones`). A zone that moves is checked in
:data:`PIECES` time pieces of the leg, each as the cap about its axis at mid-piece widened by how
far it can move in half a piece (its largest speed over the window).

**Search.** Dijkstra on the arrival time: a node keeps the attitude and time of its first arrival,
so the duration of every leg leaving it, and the time window of its moving-zone check, are exact.

**Profile.** Each leg turns by ``ϑ(t) = φ p(t/T)`` about its axis (body axis e), with
``p(s) = 35s⁴ − 84s⁵ + 70s⁶ − 20s⁷``: rate, acceleration and jerk vanish at both ends, so the torque
``τ = J e ϑ̈ + ϑ̇² e × J e`` is C¹ and zero at every leg's ends (the plan's torque is C¹ throughout).
T is the shortest duration within T̄ on the leg's :data:`KNOTS_PER_LEG` knots,
``T² = φ max_{s,j} |(J e p''(s) + φ p'(s)² e × J e)_j| / T̄``, or longer for the problem's rate
and wheel-momentum bounds. The knots hold the torque (linear interpolation) and the exact
reference attitude and rate of the rotation.

**A moving goal** (``problem.goal_motion``: the slew ends on a pointing law at its rate) has no
rest-to-rest legs: its first plan is :func:`att_planner.methods.onto_moving_goal.plan_onto_moving_goal`.
"""
from __future__ import annotations

import math
import time

import numpy as np

from att_msgs_py.types import Interpolation, Plan, Status
from att_planner.cones import BOUNDARY_TOLERANCE, boundary_end_zones
from att_planner.methods.axis_rotations import eigenaxis_leg, no_torque_limit
from att_planner.methods.onto_moving_goal import plan_onto_moving_goal
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot

METHOD = "graph_smooth"
NODES_PER_ZONE = 16               # directions round each keep-out zone of the main sensor
RIDE_MARGIN = math.radians(0.5)   # how far outside a zone its circle of nodes lies
EDGE_MARGIN = math.radians(0.1)   # every leg clears every zone by this (the knots' interpolation stays out)
KNOTS_PER_LEG = 64
SNAPSHOTS = (0.0, 0.5, 1.0)       # moving zones: circles about the zone at these × the eigenaxis slew time
SWEEP_SAMPLES = 5                 # times a moving zone is sampled at within a leg
BOUND_MARGIN = 1e-3               # relative room kept below the problem's rate and momentum bounds
PIECES = 12                       # a leg is checked against a moving zone in this many time pieces
SPEED_SAMPLES = 513               # times the zones' speed is bounded at, over their window


def septic(s):
    """``(p, p', p'')`` of ``p(s) = 35s⁴ − 84s⁵ + 70s⁶ − 20s⁷`` (module docstring)."""
    return (35 * s**4 - 84 * s**5 + 70 * s**6 - 20 * s**7, 140 * s**3 * (1 - s) ** 3,
            420 * s**2 * (1 - s) ** 2 * (1 - 2 * s))


_S = np.linspace(0.0, 1.0, KNOTS_PER_LEG)
_P, _DP, _DDP = septic(_S)
_PIECE_ANGLES = septic(np.linspace(0.0, 1.0, PIECES + 1))[0]


def arc_cosines(b: np.ndarray, n: np.ndarray, phi: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(min, max)`` of ``a·b(ϑ)`` over ϑ ∈ [0, φ], b rotated about the unit ``n`` (module docstring);
    arrays broadcast over their leading axes (vectors last)."""
    c = np.sum(n * b, axis=-1, keepdims=True)
    perp = b - c * n
    A, B = np.sum(a * perp, axis=-1), np.sum(a * rot.cross(n, perp), axis=-1)
    base = c[..., 0] * np.sum(a * n, axis=-1)
    rho, star = np.hypot(A, B), np.mod(np.arctan2(B, A), 2 * np.pi)
    first, last = base + A, base + A * np.cos(phi) + B * np.sin(phi)
    high = np.where(star <= phi, base + rho, np.maximum(first, last))
    low = np.where(np.mod(star + np.pi, 2 * np.pi) <= phi, base - rho, np.minimum(first, last))
    return low, high


def _rotated(v: np.ndarray, n: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """``v`` rotated about the unit ``n`` by ``angle`` (Rodrigues), broadcasting (vectors last)."""
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    return v * c + rot.cross(n, v) * s + n * (np.sum(n * v, axis=-1, keepdims=True) * (1 - c))


class _Zones:
    """The zones of a problem as the search checks them: fixed ones exactly, each moving one per
    time piece of a leg as the cap about its axis at mid-piece widened by how far it can move in half
    a piece (its largest speed, axis and half-angle, over the window)."""

    def __init__(self, problem: ManeuverProblem):
        self.sky = problem.zone_sky()
        self.sensors = self.sky.sensor_axes / np.linalg.norm(self.sky.sensor_axes, axis=-1, keepdims=True)
        self.keep_in = self.sky.keep_in
        self.moving = np.array([z.body != "inertial" for z in self.sky.zones], bool)
        r = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
        self.main = np.array([np.allclose(s, r, atol=1e-12) for s in self.sensors], bool)
        self.axes, self.half = self.sky.at(0.0)
        self.ends = boundary_end_zones(problem, EDGE_MARGIN)      # zones an end lies (nearly) on
        self.speed = np.zeros(len(self.sensors))
        if self.moving.any():
            t = np.linspace(0.0, self.sky.window, SPEED_SAMPLES)
            a_dot, th_dot = self.sky.rates_at(t)
            # the rates change little between samples (orbit and ephemeris periods are far longer): 5 % more
            self.speed = 1.05 * (np.linalg.norm(a_dot, axis=-1) + np.abs(th_dot)).max(axis=0)

    @staticmethod
    def _ok(low, high, keep_in, half, margin):
        with np.errstate(invalid="ignore"):       # NaN (beyond the zones' window) is never clear
            return np.where(keep_in, low >= np.cos(np.maximum(half - margin, 0.0)), high <= np.cos(half + margin))

    def clear(self, q: np.ndarray, n: np.ndarray, phi: np.ndarray, t0: float, durations: np.ndarray,
              ending: np.ndarray) -> np.ndarray:
        """Which legs (rotations about ``n`` (E, 3) by ``phi`` (E,) from attitude ``q``, leaving at
        ``t0`` for ``durations``) keep every sensor clear of every zone by :data:`EDGE_MARGIN`; a leg
        from the start or to the goal (``ending``) only −BOUNDARY_TOLERANCE from a zone an end lies on."""
        ok = np.ones(len(phi), bool)
        margin = np.where(ending[:, None] & self.ends[None], -BOUNDARY_TOLERANCE, EDGE_MARGIN)    # (E, Z)
        b = rot.dcm_NB(q) @ self.sensors.T                                   # (3, Z) sensor directions at q
        fixed = ~self.moving
        if fixed.any():
            low, high = arc_cosines(b.T[fixed][None], n[:, None], phi[:, None], self.axes[fixed])
            ok &= self._ok(low, high, self.keep_in[fixed], self.half[fixed], margin[:, fixed]).all(axis=1)
        if self.moving.any():
            m = self.moving
            angles = phi[:, None] * _PIECE_ANGLES[None]                      # (E, PIECES + 1)
            start = _rotated(b.T[m][None, None], n[:, None, None], angles[:, :-1, None])    # (E, K, Zm, 3)
            mid = t0 + durations[:, None] * (np.arange(PIECES) + 0.5) / PIECES
            beyond = mid + 0.5 * durations[:, None] / PIECES > self.sky.window
            axes, half = self.sky.at(np.minimum(mid, self.sky.window))
            widen = self.speed[m] * (0.5 * durations[:, None, None] / PIECES)
            half = np.where(self.keep_in[m], half[..., m] - widen, half[..., m] + widen)
            half[beyond] = np.nan
            low, high = arc_cosines(start, n[:, None, None], np.diff(angles, axis=1)[..., None], axes[..., m, :])
            ok &= self._ok(low, high, self.keep_in[m], half, margin[:, None, m]).all(axis=(1, 2))
        return ok


def _nodes(problem: ManeuverProblem, zones: _Zones, start: np.ndarray, goal: np.ndarray, t_ref: float):
    """Directions (N, 3) of the main sensor: start, goal, then the circles round its keep-out zones
    (those clear of every zone of that sensor by half :data:`RIDE_MARGIN` at the circle's time); and
    per node its circle (−1: none), that circle's axis and the node's azimuth about it."""
    circles = [(z, min(f * t_ref, zones.sky.window)) for z in np.flatnonzero(zones.main & ~zones.keep_in)
               for f in (SNAPSHOTS if zones.moving[z] else (0.0,))]
    psi = 2 * np.pi * np.arange(NODES_PER_ZONE) / NODES_PER_ZONE
    times = np.array([t for _, t in circles])
    axes, half = zones.sky.at(times)
    rho = np.array([half[c, z] for c, (z, _) in enumerate(circles)]) + RIDE_MARGIN
    w = np.array([axes[c, z] for c, (z, _) in enumerate(circles)]).reshape(-1, 3)
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    u = np.array([rot.orthonormal_basis(a)[0] for a in w]).reshape(-1, 3)
    v = rot.cross(w, u)
    points = (np.cos(rho)[:, None, None] * w[:, None] + np.sin(rho)[:, None, None] *
              (np.cos(psi)[None, :, None] * u[:, None] + np.sin(psi)[None, :, None] * v[:, None]))   # (C, K, 3)
    m = zones.sky.margins(np.repeat(times, NODES_PER_ZONE), _pointing(problem.sensor_axis, points.reshape(-1, 3)))
    keep = (m[:, zones.main] > 0.5 * RIDE_MARGIN).all(axis=1).reshape(len(circles), NODES_PER_ZONE)
    keep &= (rho < np.pi / 2)[:, None]
    c, k = np.nonzero(keep)
    return (np.vstack([start, goal, points[c, k]]), np.concatenate([[-1, -1], c]),
            np.vstack([np.zeros((2, 3)), w[c]]), np.concatenate([[0.0, 0.0], psi[k]]))


def _pointing(sensor: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Attitudes (K, 4) that point ``sensor`` along each of ``directions`` (the shortest rotation from
    the identity; any roll serves to judge zones of that sensor)."""
    s = np.asarray(sensor, float) / np.linalg.norm(sensor)
    cross = np.cross(s, directions)
    angle = np.arctan2(np.linalg.norm(cross, axis=-1), directions @ s)
    axis = np.where(np.linalg.norm(cross, axis=-1, keepdims=True) > 1e-12, cross, rot.orthonormal_basis(s)[0])
    return rot.from_axis_angle(axis, angle)


def leg_durations(problem: ManeuverProblem, q: np.ndarray, n: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Durations (s) of legs about the inertial axes ``n`` (E, 3) by ``phi`` (E,) from attitude ``q``
    (module docstring: within T̄ on the knots, and the rate and momentum bounds)."""
    sc = problem.spacecraft
    e = n @ rot.dcm_NB(q)                                   # body axes: Rᵀ n
    Je = e @ sc.inertia.T
    gyro = rot.cross(e, Je)[:, None]
    shape = Je[:, None] * _DDP[None, :, None] + (phi[:, None, None] * _DP[None, :, None] ** 2) * gyro
    T = np.sqrt(phi * np.abs(shape).max(axis=(1, 2)) / sc.body_torque_max)
    peak_rate = phi * _DP.max()
    if math.isfinite(problem.rate_max):
        T = np.maximum(T, peak_rate * np.abs(e).max(axis=1) / (problem.rate_max * (1 - BOUND_MARGIN)))
    if math.isfinite(problem.wheel_momentum_max) and sc.n_wheels:
        per_rate = np.abs(e @ (sc.wheel_axes_pinv @ sc.inertia).T).max(axis=1)
        T = np.maximum(T, peak_rate * per_rate / (problem.wheel_momentum_max * (1 - BOUND_MARGIN)))
    return T


class _Graph:
    """The nodes (:func:`_nodes`) and the great circles between every two of them."""

    def __init__(self, problem: ManeuverProblem, zones: _Zones, start: np.ndarray, goal: np.ndarray, t_ref: float):
        self.dirs, self.circle, self.axis, self.azimuth = _nodes(problem, zones, start, goal, t_ref)
        cross = rot.cross(self.dirs[:, None], self.dirs[None])
        norm = np.linalg.norm(cross, axis=-1)
        self.great = norm > 1e-9                                # not the same (or the opposite) direction
        self.normal = cross / np.where(self.great, norm, 1.0)[..., None]
        self.angle = np.arctan2(norm, self.dirs @ self.dirs.T)

    def legs_from(self, u: int, q: np.ndarray, q_goal: np.ndarray | None):
        """Candidate legs leaving node ``u`` at attitude ``q``: (target nodes, axes, angles); target
        ``len(dirs)`` is the goal attitude ``q_goal`` (None: a semi-free goal, none)."""
        great = np.flatnonzero(self.great[u])
        targets, axes, angles = [great], [self.normal[u, great]], [self.angle[u, great]]
        if self.circle[u] >= 0:
            same = np.flatnonzero((self.circle == self.circle[u]) & (np.arange(len(self.dirs)) != u))
            turn = np.mod(self.azimuth[same] - self.azimuth[u], 2 * np.pi)
            for sign, angle in ((1.0, turn), (-1.0, 2 * np.pi - turn)):
                targets.append(same)
                axes.append(np.broadcast_to(sign * self.axis[u], (len(same), 3)))
                angles.append(angle)
        if q_goal is not None:
            leg = eigenaxis_leg(q, q_goal)
            if leg.angle > 1e-9:
                targets.append(np.array([len(self.dirs)]))
                axes.append(leg.axis[None])
                angles.append(np.array([leg.angle]))
        return np.concatenate(targets), np.concatenate(axes), np.concatenate(angles)


def search(problem: ManeuverProblem, zones: _Zones, q0: np.ndarray, q_goal: np.ndarray | None,
           goal_dir: np.ndarray, t_ref: float):
    """A* on arrival time (module docstring): ``(legs, stats)`` with ``legs`` a list of
    ``(axis, angle, duration)`` ending at ``q_goal`` (semi-free: ``goal_dir``), or None. The
    heuristic, the shortest single leg through the angle left to the goal direction
    (T² ≥ φ λ_min max|p''| / (√3 T̄): e × J e ⟂ J e, so |shape| ≥ |J e| |p''|), never overestimates."""
    sensor = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
    graph = _Graph(problem, zones, rot.dcm_NB(q0) @ sensor, goal_dir, t_ref)
    N = len(graph.dirs)
    end = N if q_goal is not None else 1
    scale = np.linalg.eigvalsh(problem.spacecraft.inertia)[0] * np.abs(_DDP).max()
    ahead = np.append(np.sqrt(scale * graph.angle[:, 1] / (math.sqrt(3) * problem.spacecraft.body_torque_max)), 0.0)
    arrival = np.full(N + 1, np.inf)
    arrival[0] = 0.0
    attitude = np.zeros((N + 1, 4))
    attitude[0] = q0
    parent: dict = {}
    settled = np.zeros(N + 1, bool)
    while True:
        waiting = np.where(settled, np.inf, arrival + ahead)
        u = int(np.argmin(waiting))
        if not np.isfinite(waiting[u]) or u == end:
            break
        settled[u] = True
        targets, n, phi = graph.legs_from(u, attitude[u], q_goal)
        keep = ~settled[targets]
        targets, n, phi = targets[keep], n[keep], phi[keep]
        T = leg_durations(problem, attitude[u], n, phi)
        ending = (u == 0) | (targets == end) | (targets == 1)
        ok = zones.clear(attitude[u], n, phi, arrival[u], T, ending) & (arrival[u] + T < arrival[targets])
        if not ok.any():
            continue
        targets, n, phi, T = targets[ok], n[ok], phi[ok], T[ok]
        reached = rot.multiply(rot.from_axis_angle(n, phi), attitude[u])
        for k in np.argsort(-T):             # the quickest leg to a node last, so that it is the one kept
            v = targets[k]
            arrival[v], attitude[v], parent[v] = arrival[u] + T[k], reached[k], (u, n[k], phi[k], T[k])
    stats = {"nodes": N, "settled": int(settled.sum())}
    if not np.isfinite(arrival[end]):
        return None, stats
    legs, v = [], end
    while v != 0:
        u, n_v, phi_v, T_v = parent[v]
        legs.append((n_v, float(phi_v), float(T_v)))
        v = u
    return legs[::-1], stats


def legs_profile(problem: ManeuverProblem, q0: np.ndarray, legs: list):
    """Knots ``(t, torque, q, omega)`` of the legs flown in turn from ``q0`` (module docstring)."""
    J = problem.spacecraft.inertia
    ts, taus, qs, ws = [np.zeros(1)], [np.zeros((1, 3))], [q0[None]], [np.zeros((1, 3))]
    q, t0 = q0, 0.0
    for n, phi, T in legs:
        e = rot.dcm_BN(q) @ n
        Je = J @ e
        rate, accel = phi * _DP / T, phi * _DDP / T**2
        ts.append(t0 + T * _S[1:])
        taus.append((np.outer(accel, Je) + np.outer(rate**2, np.cross(e, Je)))[1:])
        qs.append(rot.multiply(rot.from_axis_angle(np.broadcast_to(n, (len(_S), 3)), phi * _P), q)[1:])
        ws.append(np.outer(rate, e)[1:])
        q, t0 = qs[-1][-1], t0 + T
    return np.concatenate(ts), np.concatenate(taus), np.concatenate(qs), np.concatenate(ws)


def plan_graph_smooth(problem: ManeuverProblem) -> Plan:
    """The constructive plan (module docstring); FAILED when the graph holds no way round the zones."""
    if problem.goal_motion is not None:
        plan = plan_onto_moving_goal(problem)
        plan.method = METHOD
        return plan
    start = time.perf_counter()
    why = no_torque_limit(problem)      # an end inside a zone: no leg leaves or reaches it (FAILED below)
    if why:
        return Plan(method=METHOD, status=Status.FAILED, message=why, wall_time=time.perf_counter() - start)
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    sensor = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
    if problem.sensor_target is None:
        q_goal = rot.normalize(np.asarray(problem.q_final, float))
        goal_dir = rot.dcm_NB(q_goal) @ sensor
    else:
        q_goal, goal_dir = None, np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
    zones = _Zones(problem)
    legs, stats = search(problem, zones, q0, q_goal, goal_dir, problem.slew_time_bound())
    if legs is None:
        return Plan(method=METHOD, status=Status.FAILED, stats=stats, wall_time=time.perf_counter() - start,
                    message=f"no sequence of legs on the graph of {stats['nodes']} sensor directions clears every zone")
    if not legs:
        legs = [(np.array([0.0, 0.0, 1.0]), 0.0, 1.0)]                  # at the goal already: rest
    t, torque, q, omega = legs_profile(problem, q0, legs)
    stats.update(tf=float(t[-1]), legs=[{"axis": n.tolist(), "angle": phi, "duration": T} for n, phi, T in legs])
    return Plan(t=t, torque=torque, q=q, omega=omega, interpolation=Interpolation.LINEAR, method=METHOD,
                status=Status.FEASIBLE, message=f"{len(legs)} rest-to-rest legs round the zones, t_f = {t[-1]:.4g} s",
                wall_time=time.perf_counter() - start, stats=stats)
