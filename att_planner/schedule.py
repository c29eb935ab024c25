"""Time-optimal attitude scheduling with reaction wheels through unordered targets.

Olivares & Staffetti (2018): visit every target attitude once, in the fastest order, starting and
ending at rest, with wheel torques ``|T_u,i| ≤ T̄`` and wheel speeds ``|Ω_i| ≤ Ω̄``; at each target
the body rate about z is zero (the other rates are free and carry over).

Model (the truth model of :mod:`att_sim.dynamics`, J = I_s the total inertia, G the wheel axes)::

    q̇ = ½ q ⊗ [ω, 0],   J ω̇ = −ω × (J ω + G I_w Ω) − G T_u,   I_w Ω̇ = T_u.

No external torque acts, so the inertial angular momentum is conserved; starting at rest with the
wheels stopped it is zero for ever, hence in body axes ``J ω + G I_w Ω = 0`` and

    ω = −J⁻¹ G I_w Ω                                                              (1)

exactly. The transcription uses this reduced state (q, Ω): nothing is approximated, the gyroscopic
term vanishes identically, and ``I_w Ω̇ = T_u`` is integrated exactly for zero-order-hold torques.

Transcription (for a given order): direct multiple shooting, one phase per leg with a free
duration, N equal intervals per phase, wheel torque held constant over an interval (the plan is a
ZOH profile, exactly what the verification integrates), attitude propagated by RK4 with the rate
(1), which is linear in time within an interval. Because Ω (hence ω) is piecewise linear, the speed
and rate bounds imposed at the nodes hold everywhere. Phases share their boundary nodes (continuity
of the full state); the passage constraints are ``vec(q_target* ⊗ q) = 0`` (sign-free: q and −q are
the same attitude, the solver takes whichever is nearer) and ``ω_z = 0``.

Order search (:func:`plan_schedule`): a lower bound for every leg (:func:`leg_bound_matrix`: the
minimum-time transfer between two attitudes with only what the schedule imposes at its ends, so
the sum along an order bounds that order from below), orders enumerated in increasing bound by a
best-first search whose heuristic is the exact Held–Karp completion cost
(:func:`orders_by_lower_bound`), multiphase solves of the first orders on a coarse grid, and a fine
solve of the winner. With ``prove=True`` every order whose bound is below the incumbent is solved:
when the enumeration stops on the bound, no unsolved order can beat the incumbent (on that grid,
and given that the NLPs reach their global minima). :func:`exhaustive_order_search` solves all n!
orders as an independent check (time reversal maps a schedule of an order onto one of the
reversed order with the same duration, so pairs must agree).

Note on the paper's dynamics: ``|Ω| ≤ 710 rad/s`` with ``I_w = 1.69e-4`` gives h̄ = 0.12 N m s and
t_sat = h̄ / T̄ = 11.9 s; the body-rate bound 0.04 rad/s is implied by the wheel box (|ω_i| ≤ h̄ /
I_i ≤ 0.018 rad/s) and never binds.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import asdict, dataclass, field

import casadi as ca
import numpy as np

from att_planner.problem import STATUS_BUDGET, STATUS_FAILED, STATUS_FEASIBLE, STATUS_OPTIMAL
from att_planner.verify import verify_profile
from att_sim import dynamics as dyn
from att_sim import rotations as rot

# ---------------------------------------------------------------------------------------------
# Experiment data (Olivares & Staffetti 2018, section 5)
# ---------------------------------------------------------------------------------------------

_TARGETS_SCALAR_LAST = {
    "a": (0.13002, 0.01137, 0.08641, 0.98767), "b": (0.19616, 0.09147, 0.41260, 0.88482),
    "c": (0.05516, 0.11829, 0.89855, 0.41900), "d": (0.01886, 0.21561, 0.97258, 0.08508),
    "e": (-0.07486, 0.10692, 0.81214, -0.56866), "f": (-0.17729, 0.12414, 0.55998, -0.79973),
    "g": (0.34071, 0.02980, 0.08189, 0.93611), "h": (0.38302, 0.17860, 0.38302, 0.82139),
    "i": (0.14454, 0.30997, 0.85165, 0.39713), "j": (0.03683, 0.42101, 0.90285, 0.07898),
    "k": (-0.19617, 0.28016, 0.76975, -0.53898), "l": (-0.34618, 0.24240, 0.51983, -0.74240),
    "m": (0.67301, 0.05888, 0.06425, 0.73447), "n": (0.66820, 0.31158, 0.28551, 0.61229),
    "o": (0.28551, 0.61229, 0.66820, 0.31158), "p": (0.06425, 0.73447, 0.67301, 0.05888),
    "q": (-0.38750, 0.55341, 0.60394, -0.42288), "r": (-0.60394, 0.42288, 0.38750, -0.55341),
}

#: Published results (4 GHz i7, BONMIN + 5th-degree Gauss–Lobatto collocation, 2 intervals/phase).
PUBLISHED = {
    "A": {"tf": 592.49, "solve_seconds": 5.48, "order": list("afedcb")},
    "B": {"tf": 744.03, "solve_seconds": 23.27, "order": None},
    "C": {"tf": 897.46, "solve_seconds": 35.50, "order": None},
}
PUBLISHED_REST_TO_REST_AB = {"collocation": 57.05, "dido": 57.59}


def olivares_spacecraft() -> dyn.Spacecraft:
    """The experiments' spacecraft: I_s = diag(6.63, 8.90, 9.63) kg m², three wheels on the body
    axes, I_w = 1.69e-4 kg m², |T_u| ≤ 0.0101 N m, |Ω| ≤ 710 rad/s (body rate bound: 0.04 rad/s,
    see :data:`OLIVARES_RATE_MAX`)."""
    return dyn.Spacecraft(inertia=np.diag([6.63, 8.90, 9.63]), wheel_axes=np.eye(3),
                          wheel_inertia=0.000169, wheel_torque_max=0.0101, wheel_speed_max=710.0)


OLIVARES_RATE_MAX = 0.04  # rad/s per body axis
SUBSTEPS = 1              # RK4 steps per ZOH interval in the schedule NLPs (default everywhere)


def olivares_targets(experiment: str = "C") -> dict[str, np.ndarray]:
    """Targets of experiment 'A' (a–f), 'B' (a–l) or 'C' (a–r) as quaternions [x, y, z, w]."""
    count = {"A": 6, "B": 12, "C": 18}.get(str(experiment).upper())
    if count is None:
        raise ValueError(f"experiment must be 'A', 'B' or 'C', not {experiment!r}")
    names = sorted(_TARGETS_SCALAR_LAST)[:count]
    return {n: rot.normalize(np.array(_TARGETS_SCALAR_LAST[n])) for n in names}


# ---------------------------------------------------------------------------------------------
# Result types
# ---------------------------------------------------------------------------------------------

@dataclass
class ScheduleVerification:
    """A schedule integrated through the truth dynamics (:func:`att_sim.dynamics.simulate_profile`)."""

    passage_attitude_errors: list   # rad, per target in visiting order, at its passage time
    passage_rate_z: list            # rad/s, |ω_z| at each passage
    final_attitude_error: float     # rad
    final_rate: float               # rad/s, ‖ω(t_f)‖
    torque_ratio: float             # max |T_u,i| / T̄
    wheel_speed_ratio: float        # max |Ω_i| / Ω̄ over the dense grid
    rate_ratio: float               # max |ω_i| / rate bound over the dense grid
    passed: bool                    # every figure within the tolerances below
    attitude_tol: float
    rate_tol: float

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass
class ScheduleResult:
    """Order, passage times and wheel-torque plan of a schedule, scipy.optimize style.

    ``wheel_torque[k]`` (N m, one column per wheel) is held from ``t[k]`` to ``t[k+1]``
    (zero-order hold; the last row is zero). ``q``, ``omega``, ``wheel_speed`` are the planner's
    predicted states at ``t``. ``passage_times[i]`` is when ``order[i]`` is reached.
    """

    order: list
    passage_times: np.ndarray
    t: np.ndarray
    wheel_torque: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    wheel_speed: np.ndarray
    interpolation: str = "zoh"
    status: str = STATUS_FAILED
    message: str = ""
    solve_seconds: float = 0.0
    stats: dict = field(default_factory=dict)
    verification: ScheduleVerification | None = None

    @property
    def tf(self) -> float:
        return float(self.t[-1]) if len(self.t) else float("nan")

    @property
    def success(self) -> bool:
        return self.status in (STATUS_OPTIMAL, STATUS_FEASIBLE) and len(self.t) > 0


# ---------------------------------------------------------------------------------------------
# Model helpers
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class _Scaling:
    """Normalised units: wheel momentum h = I_w Ω / h̄ ∈ [−1, 1] (h̄ = I_w Ω̄), torque
    u = T_u / T̄ ∈ [−1, 1], time τ = t / t_sat with t_sat = h̄ / T̄ (so dh/dτ = u).
    ``rate_matrix`` W maps h to the body rate per unit τ, ω t_sat = W h (equation (1))."""

    t_sat: float
    h_max: float
    rate_matrix: np.ndarray        # (3, N) rad per τ per unit h
    rate_per_h: np.ndarray         # (3, N) rad/s per unit h: ω = rate_per_h @ h


def _scaling(sc: dyn.Spacecraft) -> _Scaling:
    if not (np.isfinite(sc.wheel_torque_max) and np.isfinite(sc.wheel_speed_max) and sc.wheel_inertia > 0):
        raise ValueError("spacecraft must have finite wheel_torque_max, wheel_speed_max and a positive wheel_inertia")
    h_max = sc.wheel_inertia * sc.wheel_speed_max
    t_sat = h_max / sc.wheel_torque_max
    rate_per_h = -np.linalg.solve(sc.inertia, sc.wheel_axes) * h_max
    return _Scaling(t_sat, h_max, rate_per_h * t_sat, rate_per_h)


def _quat_mul_ca(p, q):
    pv, pw, qv, qw = p[:3], p[3], q[:3], q[3]
    return ca.vertcat(pw * qv + qw * pv + ca.cross(pv, qv), pw * qw - ca.dot(pv, qv))


def _error_vector_ca(q_ref, q):
    """Vector part of q_ref* ⊗ q: zero iff q = ±q_ref (unit quaternions)."""
    return q_ref[3] * q[:3] - q[3] * q_ref[:3] - ca.cross(q_ref[:3], q[:3])


def _interval_map(scale: _Scaling, substeps: int) -> ca.Function:
    """One ZOH interval: (q, h, u, dτ) -> (q⁺, h⁺). h is linear in τ (exact), q by RK4."""
    n_w = scale.rate_matrix.shape[1]
    q, h, u, dtau = ca.SX.sym("q", 4), ca.SX.sym("h", n_w), ca.SX.sym("u", n_w), ca.SX.sym("dtau")
    W = ca.DM(scale.rate_matrix)
    step = dtau / substeps

    def qdot(qq, hh):
        return 0.5 * _quat_mul_ca(qq, ca.vertcat(W @ hh, 0))

    qk, hk = q, h
    for _ in range(substeps):
        h_mid, h_end = hk + 0.5 * step * u, hk + step * u
        k1 = qdot(qk, hk)
        k2 = qdot(qk + 0.5 * step * k1, h_mid)
        k3 = qdot(qk + 0.5 * step * k2, h_mid)
        k4 = qdot(qk + step * k3, h_end)
        qk = qk + step / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        hk = h_end
    return ca.Function("interval", [q, h, u, dtau], [qk, hk])


def eigenaxis_rest_to_rest_time(sc: dyn.Spacecraft, q_from: np.ndarray, q_to: np.ndarray) -> float:
    """Duration of the rest-to-rest eigenaxis slew q_from → q_to at the largest rate and torque the
    wheel box allows about that axis (bang–coast–bang; a feasible, so upper-bound, transfer).

    About a unit body axis e, ``J ω̇ = −G T_u`` and ``J ω = −G h`` (equation (1)) limit the rate to
    ``λ = max{s : J s e ∈ G·box(h̄)}`` and the acceleration to ``λ / t_sat``. Used for the initial
    guess of the phase durations.
    """
    axis, angle = _relative_rotation(q_from, q_to)
    if angle < 1e-12:
        return 0.0
    scale = _scaling(sc)
    need = np.linalg.pinv(sc.wheel_axes) @ (sc.inertia @ axis)
    rate = scale.h_max / np.abs(need).max()
    accel = rate / scale.t_sat
    if angle >= rate * rate / accel:
        return float(angle / rate + rate / accel)
    return float(2.0 * np.sqrt(angle / accel))


def _relative_rotation(q_from, q_to) -> tuple[np.ndarray, float]:
    """Body axis and angle (≤ π, the shortest rotation) of q_from* ⊗ q_to."""
    rel = rot.multiply(rot.conjugate(rot.normalize(q_from)), rot.normalize(q_to))
    if rel[3] < 0:
        rel = -rel
    s = np.linalg.norm(rel[:3])
    axis = rel[:3] / s if s > 1e-15 else np.array([0.0, 0.0, 1.0])
    return axis, float(2.0 * np.arctan2(s, rel[3]))


def _aligned(quats: list[np.ndarray]) -> list[np.ndarray]:
    """Flip signs so consecutive quaternions have a non-negative dot product (nearest sign)."""
    out = [rot.normalize(np.asarray(quats[0], float))]
    for q in quats[1:]:
        q = rot.normalize(np.asarray(q, float))
        out.append(q if np.dot(q, out[-1]) >= 0 else -q)
    return out


def _slerp(q0: np.ndarray, q1: np.ndarray, s: np.ndarray) -> np.ndarray:
    d = float(np.clip(np.dot(q0, q1), -1.0, 1.0))
    theta = np.arccos(d)
    if theta < 1e-9:
        return np.tile(q0, (len(s), 1))
    s = np.asarray(s)[:, None]
    return (np.sin((1 - s) * theta) * q0 + np.sin(s * theta) * q1) / np.sin(theta)


@dataclass
class _PhaseSolution:
    """Raw multiphase NLP solution in normalised units (see :class:`_Scaling`)."""

    durations: np.ndarray   # (P,) τ
    q: np.ndarray           # (K+1, 4)
    h: np.ndarray           # (K+1, N)
    u: np.ndarray           # (K, N)
    converged: bool
    return_status: str
    iterations: int
    seconds: float

    @property
    def tau_f(self) -> float:
        return float(self.durations.sum())


class MultiphaseTranscription:
    """Multiple-shooting NLP of the minimum-time schedule for a fixed number of targets.

    Built once per (number of targets, intervals per phase); the target quaternions of an order
    and the end attitude are NLP parameters, so every order of the same set reuses the solver.
    Either end may be at rest (h = 0) or a passage (only ω_z = 0), chosen per solve.
    """

    def __init__(self, sc: dyn.Spacecraft, n_targets: int, intervals: int = 12, substeps: int = SUBSTEPS,
                 rate_max: float = np.inf, bound_margin: float = 1e-6, tol: float = 1e-7,
                 max_iter: int = 1500, expand: bool | None = None):
        if intervals < 1 or substeps < 1:
            raise ValueError("intervals and substeps must be positive integers")
        self.sc, self.scale = sc, _scaling(sc)
        self.n_targets, self.n_phases, self.intervals = n_targets, n_targets + 1, intervals
        n_w = sc.n_wheels
        P, N = self.n_phases, intervals
        K = P * N
        self.n_nodes = K + 1
        T = ca.MX.sym("T", P)
        Q = ca.MX.sym("Q", 4, K + 1)
        H = ca.MX.sym("H", n_w, K + 1)
        U = ca.MX.sym("U", n_w, K)
        targets = ca.MX.sym("targets", 4, max(n_targets, 1))
        q_end = ca.MX.sym("q_end", 4)
        dtau = ca.repmat(T.T / N, N, 1).reshape((1, K))  # phase p's dτ on intervals p*N ... p*N+N-1
        step = _interval_map(self.scale, substeps).map(K)
        q_next, h_next = step(Q[:, :K], H[:, :K], U, dtau)
        g = [ca.vec(Q[:, 1:] - q_next), ca.vec(H[:, 1:] - h_next)]
        rate_z = ca.DM(self.scale.rate_per_h[2:3, :])
        for p in range(n_targets):
            node = (p + 1) * N
            g += [_error_vector_ca(targets[:, p], Q[:, node]), rate_z @ H[:, node]]
        g.append(_error_vector_ca(q_end, Q[:, K]))
        # ω_z = 0 at both ends: implied by rest (h = 0 bounds), the only condition at a passage
        g += [rate_z @ H[:, 0], rate_z @ H[:, K]]
        n_eq = sum(int(gi.numel()) for gi in g)
        lbg, ubg = [0.0] * n_eq, [0.0] * n_eq
        # body-rate box, only where the wheel box does not already imply it (rates are linear in h)
        rate_rows = [i for i in range(3) if np.abs(self.scale.rate_per_h[i]).sum() > rate_max]
        if rate_rows:
            R = ca.DM(self.scale.rate_per_h[rate_rows, :] / rate_max)
            g.append(ca.vec(R @ H))
            lbg += [-1.0] * (len(rate_rows) * (K + 1))
            ubg += [1.0] * (len(rate_rows) * (K + 1))
        self._x = ca.vertcat(T, ca.vec(Q), ca.vec(H), ca.vec(U))
        self._split = ca.Function("split", [self._x], [T, Q, H, U])
        self._lbg, self._ubg = np.array(lbg), np.array(ubg)
        nlp = {"x": self._x, "p": ca.vertcat(ca.vec(targets), q_end), "f": ca.sum1(T), "g": ca.vertcat(*g)}
        self.ipopt_options = {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": tol,
                              "ipopt.max_iter": max_iter, "ipopt.mu_strategy": "adaptive",
                              "ipopt.sb": "yes",
                              # SX expansion: slower to build, faster to evaluate; worth it for
                              # small NLPs (legs) or when one NLP is solved for many orders
                              "expand": n_targets == 0 if expand is None else bool(expand)}
        self._nlp = nlp
        self._solver = ca.nlpsol("schedule", "ipopt", nlp, self.ipopt_options)
        self._solver_wall = None
        limit = 1.0 - bound_margin
        lbx = ca.vertcat(np.full(P, 1e-3), np.full(4 * (K + 1), -1.5), np.full(n_w * (K + 1), -limit),
                         np.full(n_w * K, -limit))
        self._lbx = np.array(lbx).ravel()
        self._ubx = -self._lbx
        self._ubx[:P] = 1e4
        iq0, ih0 = P, P + 4 * (K + 1)
        self._index_q0, self._index_h0 = slice(iq0, iq0 + 4), slice(ih0, ih0 + n_w)
        self._index_hf = slice(ih0 + n_w * K, ih0 + n_w * (K + 1))

    # -- guesses ----------------------------------------------------------------------------
    def initial_guess(self, q_start, targets_in_order, q_end) -> _PhaseSolution:
        """Slerp between consecutive (sign-aligned) attitudes with eigenaxis durations; wheel
        momentum from the slerp rate by (1), clipped to the box; zero torque."""
        P, N, n_w = self.n_phases, self.intervals, self.sc.n_wheels
        chain = _aligned([q_start, *targets_in_order, q_end])
        dur = np.array([max(eigenaxis_rest_to_rest_time(self.sc, a, b), 1.0) for a, b in zip(chain[:-1], chain[1:])])
        dur = dur / self.scale.t_sat
        qs, hs = [chain[0][None, :]], [np.zeros((1, n_w))]
        for p in range(P):
            s = np.arange(1, N + 1) / N
            qs.append(_slerp(chain[p], chain[p + 1], s))
            axis, angle = _relative_rotation(chain[p], chain[p + 1])
            w_tau = axis * angle / dur[p]
            h = np.clip(np.linalg.lstsq(self.scale.rate_matrix, w_tau, rcond=None)[0], -0.9, 0.9)
            hs.append(np.tile(h, (N, 1)))
        hs[-1][-1] = 0.0
        return _PhaseSolution(dur, np.vstack(qs), np.vstack(hs), np.zeros((P * N, n_w)), False, "guess", 0, 0.0)

    def resample(self, sol: _PhaseSolution) -> _PhaseSolution:
        """Interpolate a solution with another number of intervals per phase onto this grid."""
        P, N = self.n_phases, self.intervals
        N0 = (len(sol.q) - 1) // P
        s_old = np.concatenate([[0.0], np.concatenate([p + np.arange(1, N0 + 1) / N0 for p in range(P)])])
        s_new = np.concatenate([[0.0], np.concatenate([p + np.arange(1, N + 1) / N for p in range(P)])])
        q = np.column_stack([np.interp(s_new, s_old, sol.q[:, j]) for j in range(4)])
        q = rot.normalize(q)
        h = np.column_stack([np.interp(s_new, s_old, sol.h[:, j]) for j in range(sol.h.shape[1])])
        mid_old = np.concatenate([p + (np.arange(N0) + 0.5) / N0 for p in range(P)])
        mid_new = np.concatenate([p + (np.arange(N) + 0.5) / N for p in range(P)])
        u = np.column_stack([np.interp(mid_new, mid_old, sol.u[:, j]) for j in range(sol.u.shape[1])])
        return _PhaseSolution(sol.durations.copy(), q, h, u, False, "resampled", 0, 0.0)

    # -- solve ------------------------------------------------------------------------------
    def solve(self, q_start, targets_in_order, q_end, guess: _PhaseSolution | None = None,
              max_wall_time: float | None = None, start_at_rest: bool = True,
              end_at_rest: bool = True) -> _PhaseSolution:
        """Minimum-time trajectory through ``targets_in_order`` (quaternions, any sign)."""
        if len(targets_in_order) != self.n_targets:
            raise ValueError(f"expected {self.n_targets} targets, got {len(targets_in_order)}")
        if guess is None:
            guess = self.initial_guess(q_start, targets_in_order, q_end)
        solver = self._solver
        if max_wall_time is not None:
            solver = ca.nlpsol("schedule", "ipopt", self._nlp,
                               {**self.ipopt_options, "ipopt.max_wall_time": max(float(max_wall_time), 0.01)})
        x0 = np.concatenate([guess.durations, guess.q.ravel(), guess.h.ravel(), guess.u.ravel()])
        lbx, ubx = self._lbx.copy(), self._ubx.copy()
        q0 = rot.normalize(np.asarray(q_start, float))
        lbx[self._index_q0] = ubx[self._index_q0] = q0 if np.dot(q0, guess.q[0]) >= 0 else -q0
        if start_at_rest:
            lbx[self._index_h0] = ubx[self._index_h0] = 0.0
        if end_at_rest:
            lbx[self._index_hf] = ubx[self._index_hf] = 0.0
        params = np.concatenate([np.concatenate([rot.normalize(np.asarray(q, float)) for q in targets_in_order]) if self.n_targets else np.zeros(4),
                                 rot.normalize(np.asarray(q_end, float))])
        x0 = np.clip(x0, lbx, ubx)
        start = time.perf_counter()
        out = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=self._lbg, ubg=self._ubg, p=params)
        seconds = time.perf_counter() - start
        stats = solver.stats()
        T, Q, H, U = (np.array(v) for v in self._split(out["x"]))
        return _PhaseSolution(T.ravel(), Q.T, H.T, U.T, bool(stats["success"]), str(stats["return_status"]),
                              int(stats.get("iter_count", 0)), seconds)


_TRANSCRIPTIONS: dict = {}


def _transcription(sc: dyn.Spacecraft, n_targets: int, intervals: int, substeps: int,
                   rate_max: float, expand: bool | None = None) -> MultiphaseTranscription:
    """Solver cache: an NLP depends only on the spacecraft, the number of targets and the grid."""
    key = (sc.inertia.tobytes(), sc.wheel_axes.tobytes(), sc.wheel_inertia, sc.wheel_torque_max,
           sc.wheel_speed_max, n_targets, intervals, substeps, rate_max, expand)
    if key not in _TRANSCRIPTIONS:
        _TRANSCRIPTIONS[key] = MultiphaseTranscription(sc, n_targets, intervals, substeps, rate_max, expand=expand)
    return _TRANSCRIPTIONS[key]


# ---------------------------------------------------------------------------------------------
# Lower bounds and the order search
# ---------------------------------------------------------------------------------------------

def leg_bound_matrix(sc: dyn.Spacecraft, q_start, targets: list[np.ndarray], q_end, *, intervals: int = 12,
                     substeps: int = SUBSTEPS, rate_max: float = np.inf, deadline: float | None = None) -> np.ndarray:
    """Minimum leg times with the boundary rates relaxed, as a (n+2)×(n+2) matrix.

    Node 0 is the start (at rest), 1..n the targets, n+1 the end (at rest). Entry (i, j) is the
    minimum time from attitude i to j when only what the schedule imposes at i and j is kept
    (rest at the start/end, ω_z = 0 at a target; other rates and wheel speeds free). Any schedule
    restricted to one leg is feasible for that leg problem, so the sum of the entries along an
    order is a lower bound on that order's schedule time (on the same grid, if the leg NLPs reach
    their global minima). Free–free legs are symmetric under time reversal, so each pair is
    solved once. Entries not computed (deadline, solver failure) are 0 (still a valid bound).
    """
    n = len(targets)
    nodes = [q_start, *targets, q_end]
    same_ends = rot.angle_between(q_start, q_end) < 1e-9
    legs = [(0, j) for j in range(1, n + 1)] + [(i, j) for i in range(1, n + 1) for j in range(i + 1, n + 1)]
    if not same_ends:
        legs += [(n + 1, j) for j in range(1, n + 1)]   # solved reversed: from the end at rest
    C = np.zeros((n + 2, n + 2))
    tr = _transcription(sc, 0, intervals, substeps, rate_max)
    for i, j in legs:
        if deadline is not None and time.monotonic() > deadline:
            break
        sol = tr.solve(nodes[i], [], nodes[j], start_at_rest=i in (0, n + 1), end_at_rest=False)
        value = sol.tau_f * tr.scale.t_sat if sol.converged else 0.0
        if i == n + 1:
            C[j, i] = value
        else:
            C[i, j] = value
            if i > 0:
                C[j, i] = value
        if i == 0 and same_ends:
            C[j, n + 1] = value
    return C


def _completion_costs(C: np.ndarray) -> np.ndarray:
    """Held–Karp over the targets: ``G[S, j]`` = cheapest way from target j through the targets of
    bitmask S (j not in S) to the end node, with costs ``C`` (nodes as in :func:`leg_bound_matrix`).
    Exact dynamic programming, vectorised over subsets of equal size."""
    n = C.shape[0] - 2
    G = np.full((1 << n, n), np.inf)
    G[0, :] = C[1:n + 1, n + 1]
    masks = np.arange(1 << n)
    popcount = sum((masks >> b) & 1 for b in range(n))
    bits = 1 << np.arange(n)
    cost = C[1:n + 1, 1:n + 1]
    for size in range(1, n):
        for S in np.array_split(masks[popcount == size], max(1, (popcount == size).sum() // 4096)):
            inside = (S[:, None] & bits[None, :]) != 0                       # k ∈ S
            # M[s, k] = G[S \ {k}, k] for k ∈ S, +inf otherwise; G[S, j] = min_k cost[j, k] + M[s, k]
            M = np.where(inside, G[S[:, None] ^ bits[None, :], np.arange(n)[None, :]], np.inf)
            Gs = np.full(M.shape, np.inf)
            for k in range(n):
                np.minimum(Gs, M[:, k:k + 1] + cost[None, :, k], out=Gs)
            G[S] = np.where(inside, np.inf, Gs)                              # j ∉ S only
    return G


def orders_by_lower_bound(C: np.ndarray):
    """Yield ``(bound, order)`` for every order of the targets, in increasing order of the leg
    bound sum (best-first search with the exact Held–Karp completion cost as heuristic, so each
    complete order is reached by a direct descent)."""
    import heapq
    n = C.shape[0] - 2
    if n == 0:
        yield float(C[0, 1]), []
        return
    G = _completion_costs(C)
    full = (1 << n) - 1
    heap = [(float(C[0, j + 1] + G[full ^ (1 << j), j]), float(C[0, j + 1]), (j,)) for j in range(n)]
    heapq.heapify(heap)
    while heap:
        f, g, path = heapq.heappop(heap)
        if len(path) == n:
            yield f, list(path)
            continue
        visited = 0
        for j in path:
            visited |= 1 << j
        last = path[-1]
        for j in range(n):
            if not visited >> j & 1:
                rest = full ^ visited ^ (1 << j)
                g2 = g + C[last + 1, j + 1]
                f2 = g2 + (C[j + 1, n + 1] if rest == 0 else G[rest, j])
                heapq.heappush(heap, (float(f2), float(g2), path + (j,)))


# ---------------------------------------------------------------------------------------------
# Plans, verification and the planner entry point
# ---------------------------------------------------------------------------------------------

def _plan_arrays(tr: MultiphaseTranscription, sol: _PhaseSolution) -> dict:
    """SI arrays of a normalised solution: knot times, ZOH wheel torques (last row zero),
    predicted q, ω, Ω at the knots and the passage times."""
    sc, scale, N = tr.sc, tr.scale, tr.intervals
    dt = np.repeat(sol.durations / N, N) * scale.t_sat
    t = np.concatenate([[0.0], np.cumsum(dt)])
    torque = np.vstack([sol.u * sc.wheel_torque_max, np.zeros((1, sc.n_wheels))])
    return {"t": t, "wheel_torque": torque, "q": rot.normalize(sol.q), "omega": sol.h @ scale.rate_per_h.T,
            "wheel_speed": sol.h * sc.wheel_speed_max, "passage_times": t[N::N][:tr.n_targets]}


def verify_schedule(sc: dyn.Spacecraft, q_start, q_end, targets_in_order: list[np.ndarray],
                    passage_times, t, wheel_torque, *, rate_max: float = np.inf,
                    attitude_tol: float = np.radians(0.5), rate_tol: float = 1e-3,
                    interpolation: str = "zoh", dense_step: float = 0.5) -> ScheduleVerification:
    """Integrate the wheel torques from rest at ``q_start`` through the truth dynamics
    (:func:`att_planner.verify.verify_profile`) and check every passage (attitude, |ω_z|), the
    end (attitude, ‖ω‖) and the torque, wheel-speed and body-rate bounds. ``dense_step`` (s) is
    the longest RK4 step (rates are below 0.05 rad/s, so 0.5 s steps are accurate to ~1e-10 rad)."""
    ver, traj = verify_profile(sc, q_start, q_end, t, wheel_torque, kind="wheel_torque",
                               interpolation=interpolation, dense_step=dense_step)
    att_err, rate_z = [], []
    for q_target, tp in zip(targets_in_order, passage_times):
        k = int(np.argmin(np.abs(traj.t - tp)))
        att_err.append(float(rot.angle_between(traj.q[k], q_target)))
        rate_z.append(float(abs(traj.omega[k, 2])))
    rate_ratio = float(np.abs(traj.omega).max() / rate_max) if np.isfinite(rate_max) else 0.0
    ratio_ok = max(ver.torque_ratio, ver.wheel_speed_ratio, rate_ratio) <= 1.0 + 1e-9
    passed = (ratio_ok and ver.final_attitude_error <= attitude_tol and ver.final_rate <= rate_tol
              and all(e <= attitude_tol for e in att_err) and all(r <= rate_tol for r in rate_z))
    return ScheduleVerification(att_err, rate_z, ver.final_attitude_error, ver.final_rate, ver.torque_ratio,
                                ver.wheel_speed_ratio, rate_ratio, bool(passed), attitude_tol, rate_tol)


@dataclass
class _Solved:
    order: tuple
    tf: float
    sol: _PhaseSolution
    transcription: MultiphaseTranscription


def _solve_order(sc, q_start, q_end, targets: dict, order, intervals, substeps, rate_max,
                 guess: _Solved | None = None, deadline=None, expand: bool | None = None) -> _Solved:
    tr = _transcription(sc, len(order), intervals, substeps, rate_max, expand)
    wall = None if deadline is None else deadline - time.monotonic()
    start_guess = tr.resample(guess.sol) if guess is not None else None
    sol = tr.solve(q_start, [targets[k] for k in order], q_end, guess=start_guess, max_wall_time=wall)
    tf = sol.tau_f * tr.scale.t_sat if sol.converged else np.inf
    return _Solved(tuple(order), tf, sol, tr)


def plan_schedule(targets: dict, spacecraft: dyn.Spacecraft, q_start=rot.IDENTITY, q_end=None,
                  deadline: float | None = None, *, rate_max: float = np.inf, order=None,
                  search_intervals: int = 8, intervals: int = 24, substeps: int = SUBSTEPS,
                  candidates: int = 2, prove: bool = False, max_order_solves: int = 1000,
                  second_start_margin: float = 0.01,
                  verify: bool = True) -> ScheduleResult:
    """Fastest rest-to-rest schedule through every target attitude, in the best order found.

    ``targets``: name → quaternion [x, y, z, w] (either sign). Start at rest at ``q_start`` with
    the wheels stopped, end at rest at ``q_end`` (default ``q_start``), ω_z = 0 at each target.
    ``spacecraft``: inertia, wheel axes and inertia, wheel torque/speed limits; ``rate_max``: body
    rate bound per axis (rad/s). ``deadline``: ``time.monotonic()`` instant; when it passes the
    best schedule so far is returned with status ``budget_expired``.

    Search: leg lower bounds (:func:`leg_bound_matrix`) on ``search_intervals`` intervals per
    phase; orders in increasing bound order (:func:`orders_by_lower_bound`); the first
    ``candidates`` solved as multiphase problems; with ``prove`` every further order whose bound is
    below the incumbent is solved too (up to ``max_order_solves``), which proves the incumbent
    optimal on that grid when the enumeration is exhausted. When the start and end attitudes
    coincide, an order and its reverse have the same minimum time (time reversal t → t_f − t,
    Ω → −Ω, T_u(t) → T_u(t_f − t) maps one schedule onto the other), so only one of each pair is
    solved, and the winner (with ``prove``: every order within ``second_start_margin`` of it) is
    solved once more reversed (a second start: the NLP is not convex).
    ``order`` (list of names) skips the
    search. The winner is re-solved on ``intervals`` per phase (warm start) and verified.
    """
    t_begin, cpu_begin = time.perf_counter(), time.process_time()
    names = list(targets)
    if order is not None and sorted(order) != sorted(names):
        raise ValueError("order must list every target name exactly once")
    if candidates < 1 or search_intervals < 1 or intervals < 1:
        raise ValueError("candidates, search_intervals and intervals must be positive")
    q_start = rot.normalize(np.asarray(q_start, float))
    q_end = q_start if q_end is None else rot.normalize(np.asarray(q_end, float))
    quats = {k: rot.normalize(np.asarray(v, float)) for k, v in targets.items()}
    stats: dict = {"orders_solved": 0, "search_intervals": search_intervals, "intervals": intervals, "substeps": substeps,
                   "_cpu_begin": cpu_begin}
    expired = lambda: deadline is not None and time.monotonic() > deadline  # noqa: E731
    empty = ScheduleResult([], np.zeros(0), np.zeros(0), np.zeros((0, spacecraft.n_wheels)), np.zeros((0, 4)),
                           np.zeros((0, 3)), np.zeros((0, spacecraft.n_wheels)))
    try:
        solved: list[_Solved] = []
        if order is not None:
            solved.append(_solve_order(spacecraft, q_start, q_end, quats, order, search_intervals, substeps,
                                       rate_max, deadline=deadline))
            stats["orders_solved"] = 1
        else:
            t0 = time.perf_counter()
            C = leg_bound_matrix(spacecraft, q_start, [quats[k] for k in names], q_end, intervals=search_intervals,
                                 substeps=substeps, rate_max=rate_max, deadline=deadline)
            stats["leg_bound_seconds"] = time.perf_counter() - t0
            stats["leg_bounds"] = C
            incumbent = np.inf
            unsolved_bound = np.inf   # smallest leg bound among the orders not solved
            reversible = rot.angle_between(q_start, q_end) < 1e-9
            for bound, idx in orders_by_lower_bound(C):
                if bound >= incumbent or len(solved) >= (max_order_solves if prove else candidates) or expired():
                    unsolved_bound = bound
                    break
                if reversible and tuple(names[i] for i in reversed(idx)) in {s.order for s in solved}:
                    continue  # time reversal: same schedule duration as an order already solved
                s = _solve_order(spacecraft, q_start, q_end, quats, [names[i] for i in idx], search_intervals,
                                 substeps, rate_max, deadline=deadline, expand=prove or None)
                solved.append(s)
                incumbent = min(incumbent, s.tf)
            if reversible and solved:
                # second start: an order's reverse has the same optimum but IPOPT may land in another
                # local minimum from the reversed initial guess. For the winner, and with ``prove``
                # for every order within ``second_start_margin`` of it (near-ties), keep the better.
                best_tf = min(s.tf for s in solved)
                margin = second_start_margin if prove else 0.0
                seen = {s.order for s in solved}
                for s in [s for s in solved if s.tf <= best_tf * (1 + margin)]:
                    if s.order[::-1] not in seen and not expired():
                        seen.add(s.order[::-1])
                        solved.append(_solve_order(spacecraft, q_start, q_end, quats, s.order[::-1],
                                                   search_intervals, substeps, rate_max, deadline=deadline,
                                                   expand=prove or None))
            # every order not solved costs at least unsolved_bound on the search grid
            incumbent = min(s.tf for s in solved) if solved else np.inf
            stats.update(orders_solved=len(solved), lower_bound=min(unsolved_bound, incumbent),
                         unsolved_orders_bound=unsolved_bound,
                         order_proven=bool(unsolved_bound >= incumbent), search_seconds=time.perf_counter() - t0,
                         candidates=[{"order": list(s.order), "tf": s.tf} for s in solved])
        if not solved:
            return _finish(empty, STATUS_FAILED, "deadline passed before any order was solved", t_begin, stats)
        best = min(solved, key=lambda s: s.tf)
        if not np.isfinite(best.tf):
            return _finish(empty, STATUS_FAILED, "no order converged: " + best.sol.return_status,
                           t_begin, stats)
        stats["tf_search"] = best.tf
        final = best
        if intervals != search_intervals and not expired():
            fine = _solve_order(spacecraft, q_start, q_end, quats, best.order, intervals, substeps, rate_max,
                                guess=best, deadline=deadline)
            if fine.tf <= best.tf * (1 + 1e-6) or not np.isfinite(best.tf):
                final = fine
            stats["refine_status"] = fine.sol.return_status
        arrays = _plan_arrays(final.transcription, final.sol)
        result = ScheduleResult(order=list(final.order), interpolation="zoh", **arrays)
        stats.update(iterations=final.sol.iterations, ipopt_status=final.sol.return_status,
                     intervals_used=final.transcription.intervals)
        status = STATUS_OPTIMAL if final.sol.converged else STATUS_FEASIBLE
        message = f"order {''.join(final.order) if all(len(k) == 1 for k in final.order) else final.order}" \
                  f" t_f = {result.tf:.2f} s"
        if expired():
            status, message = STATUS_BUDGET, message + " (deadline reached: best so far)"
        result = _finish(result, status, message, t_begin, stats)
        if verify:
            result.verification = verify_schedule(spacecraft, q_start, q_end, [quats[k] for k in result.order],
                                                  result.passage_times, result.t, result.wheel_torque,
                                                  rate_max=rate_max)
        return result
    except RuntimeError as exc:  # CasADi/IPOPT failures are reported, not raised
        return _finish(empty, STATUS_FAILED, f"solver error: {exc}", t_begin, stats)


def _finish(result: ScheduleResult, status: str, message: str, t_begin: float, stats: dict) -> ScheduleResult:
    """Fill status and timing: ``solve_seconds`` is wall time, ``stats['cpu_seconds']`` the
    process CPU time (the fairer figure on a shared machine)."""
    result.status, result.message, result.stats = status, message, stats
    result.solve_seconds = time.perf_counter() - t_begin
    stats["cpu_seconds"] = time.process_time() - stats.pop("_cpu_begin", time.process_time())
    return result


def exhaustive_order_search(targets: dict, spacecraft: dyn.Spacecraft, q_start=rot.IDENTITY, q_end=None, *,
                            rate_max: float = np.inf, intervals: int = 8, substeps: int = SUBSTEPS,
                            progress=None) -> list[dict]:
    """Solve the multiphase problem of every order (all n! of them, reversals included, as an
    independent check of the time-reversal symmetry and of the NLP's local minima) and return
    ``[{"order", "tf", "bound", "converged"}]`` sorted by ``tf``; ``bound`` is the leg lower bound
    of :func:`leg_bound_matrix` on the same grid (so ``bound ≤ tf`` must hold for every order)."""
    names = list(targets)
    q_start = rot.normalize(np.asarray(q_start, float))
    q_end = q_start if q_end is None else rot.normalize(np.asarray(q_end, float))
    quats = {k: rot.normalize(np.asarray(v, float)) for k, v in targets.items()}
    C = leg_bound_matrix(spacecraft, q_start, [quats[k] for k in names], q_end, intervals=intervals,
                         substeps=substeps, rate_max=rate_max)
    index = {k: i + 1 for i, k in enumerate(names)}
    rows = []
    for perm in itertools.permutations(names):
        s = _solve_order(spacecraft, q_start, q_end, quats, perm, intervals, substeps, rate_max, expand=True)
        chain = [0] + [index[k] for k in perm] + [len(names) + 1]
        bound = float(sum(C[a, b] for a, b in zip(chain[:-1], chain[1:])))
        rows.append({"order": list(perm), "tf": float(s.tf), "bound": bound, "converged": s.sol.converged})
        if progress is not None:
            progress(len(rows), rows[-1])
    return sorted(rows, key=lambda r: r["tf"])
