"""The multiple-shooting NLP of a minimum-time schedule for a fixed order of targets (model of
:mod:`att_planner.methods.schedule`): normalisation, one ZOH interval, the multiphase transcription
and its solver cache.

Zones (:mod:`att_planner.zones`, the cones first): every zone is imposed at every node and at the
middle of every interval (the attitude there by one more RK4 step of half the interval from the
node, the propagation itself unchanged), tightened by a margin δ like the time-optimal NLP's:
keep-out ``a_z · R(q) s_z ≤ cos(θ_z + δ)``, keep-in ``≥ cos(θ_z − δ)``. A moving zone is evaluated
at the point's physical time over the whole tour, ``t = t_sat Σ dτ`` of the intervals before it
(so a leg starts at the sum of the earlier legs' durations), through the FittedZones' Chebyshev series
of that CasADi expression: exact in the phase durations. The tour is then bounded by the zones'
window. Without zones nothing is added: the NLP is the zone-free one.

Observations: each target's dwell (τ) is a parameter, in the order's sequence; a target
with one is reached at rest (its x and y rates zero too) and held, torque-free, before the next leg,
so every later node's time moves by it; each arrival time is a constraint row whose bounds are the
target's window (both set per solve); moving zones are kept on a held target through its dwell."""
from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from att_planner.methods import symbolic
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot

SUBSTEPS = 1              # RK4 steps per ZOH interval in the schedule NLPs (default everywhere)


@dataclass(frozen=True)
class _Scaling:
    """Normalised units: wheel momentum h = I_w Ω / h̄ (h̄ = I_w Ω̄), torque
    u = T_u / T̄ ∈ [−1, 1], time τ = t / t_sat with t_sat = h̄ / T̄ (so dh/dτ = u).
    ``rate_matrix`` W maps h to the body rate per unit τ, ω t_sat = W h (equation (1)).
    The NLP's wheel state is the relative speed ν = (Ω − Gᵀω) / Ω̄ = M h, M = 𝟙 + I_w Gᵀ J⁻¹ G
    (by (1)), so the dynamics model's limit |ν| ≤ 1 (att_sim.models.dynamics) is a box on it: a row M h
    next to the box on h, 2.5e-5 inside it for the Olivares spacecraft, left IPOPT nearly
    coincident barriers (in C's fast run one start took 975 iterations to Infeasible_Problem_Detected)."""

    t_sat: float
    h_max: float
    rate_matrix: np.ndarray        # (3, N) rad per τ per unit h
    rate_per_h: np.ndarray         # (3, N) rad/s per unit h: ω = rate_per_h @ h
    relative: np.ndarray           # (N, N) M: ν = M h


def _scaling(sc: dyn.Spacecraft) -> _Scaling:
    if not (np.isfinite(sc.wheel_torque_max) and np.isfinite(sc.wheel_speed_max) and sc.wheel_inertia > 0):
        raise ValueError("spacecraft must have finite wheel_torque_max, wheel_speed_max and a positive wheel_inertia")
    h_max = sc.wheel_inertia * sc.wheel_speed_max
    t_sat = h_max / sc.wheel_torque_max
    rate_per_h = -np.linalg.solve(sc.inertia, sc.wheel_axes) * h_max
    relative = np.eye(sc.n_wheels) - sc.wheel_axes.T @ rate_per_h / sc.wheel_speed_max
    return _Scaling(t_sat, h_max, rate_per_h * t_sat, rate_per_h, relative)


def _interval_map(scale: _Scaling, substeps: int) -> ca.Function:
    """One ZOH interval: (q, ν, u, dτ) -> (q⁺, ν⁺). ν is linear in τ (exact, dν/dτ = M u), q by
    RK4 (:func:`att_sim.models.dynamics.rk4` on the CasADi expressions), ω t_sat = W M⁻¹ ν."""
    n_w = scale.rate_matrix.shape[1]
    q, nu, u, dtau = ca.SX.sym("q", 4), ca.SX.sym("nu", n_w), ca.SX.sym("u", n_w), ca.SX.sym("dtau")
    W = ca.DM(np.linalg.solve(scale.relative.T, scale.rate_matrix.T).T)
    du = ca.DM(scale.relative) @ u
    step = dtau / substeps
    qk, nuk = q, nu
    for _ in range(substeps):
        def qdot(tau, qq, nu0=nuk):
            return 0.5 * symbolic.quat_mul(qq, ca.vertcat(W @ (nu0 + tau * du), 0))
        qk = dyn.rk4(qdot, 0.0, qk, step)
        nuk = nuk + step * du
    return ca.Function("interval", [q, nu, u, dtau], [qk, nuk])


def eigenaxis_rest_to_rest_time(sc: dyn.Spacecraft, q_from: np.ndarray, q_to: np.ndarray) -> float:
    """Duration of the rest-to-rest eigenaxis slew q_from → q_to at the largest rate and torque the
    wheel box allows about that axis (bang–coast–bang; a feasible, so upper-bound, transfer).

    About a unit body axis e, ``J ω̇ = −G T_u`` and ``J ω = −G h`` (equation (1)) limit the rate to
    ``λ = max{s : J s e ∈ G·box(h̄)}`` and the acceleration to ``λ / t_sat``. Used for the initial
    guess of the phase durations.
    """
    axis, angle = rot.to_axis_angle(rot.multiply(rot.conjugate(rot.normalize(q_from)), rot.normalize(q_to)))
    if angle < 1e-12:
        return 0.0
    scale = _scaling(sc)
    need = sc.wheel_axes_pinv @ (sc.inertia @ axis)
    rate = scale.h_max / np.abs(need).max()
    accel = rate / scale.t_sat
    if angle >= rate * rate / accel:
        return float(angle / rate + rate / accel)
    return float(2.0 * np.sqrt(angle / accel))


def node_times(leg_durations: np.ndarray, dwell: np.ndarray, intervals: int) -> np.ndarray:
    """Times (s) of the K+1 nodes of a tour of legs of ``leg_durations`` (s, ``intervals`` equal
    intervals each), each target held for its ``dwell`` (s) before the next leg starts: a node at
    a target is its arrival."""
    held = np.concatenate([[0.0], np.cumsum(dwell)])[:len(leg_durations)]
    return np.concatenate([[0.0], np.cumsum(np.repeat(np.asarray(leg_durations) / intervals, intervals))
                           + np.repeat(held, intervals)])


def _aligned(quats: list[np.ndarray]) -> list[np.ndarray]:
    """Flip signs so consecutive quaternions have a non-negative dot product (nearest sign)."""
    out = [rot.normalize(np.asarray(quats[0], float))]
    for q in quats[1:]:
        q = rot.normalize(np.asarray(q, float))
        out.append(q if np.dot(q, out[-1]) >= 0 else -q)
    return out


@dataclass
class ScheduleSolution:
    """Raw multiphase NLP solution in normalised units (see :class:`_Scaling`)."""

    durations: np.ndarray   # (P,) τ
    q: np.ndarray           # (K+1, 4)
    h: np.ndarray           # (K+1, N) wheel momentum (the NLP's ν = M h, converted)
    u: np.ndarray           # (K, N)
    converged: bool
    return_status: str
    nit: int
    wall_time: float

    @property
    def tau_f(self) -> float:
        return float(self.durations.sum())


class MultiphaseTranscription:
    """Multiple-shooting NLP of the minimum-time schedule for a fixed number of targets.

    Built once per (number of targets, intervals per phase); the target quaternions of an order
    and the end attitude are NLP parameters, so every order of the same set reuses the solver.
    Either end may be at rest (h = 0) or a passage (only ω_z = 0), chosen per solve. ``zones``: a
    :class:`att_planner.zones.FittedZones` (module docstring) with ``zone_margin`` δ (rad), or None.
    """

    def __init__(self, sc: dyn.Spacecraft, n_targets: int, intervals: int = 12, substeps: int = SUBSTEPS,
                 rate_max: float = np.inf, bound_margin: float = 1e-6, tol: float = 1e-7,
                 max_iter: int = 1500, expand: bool | None = None, zones=None, zone_margin: float = 0.0):
        if intervals < 1 or substeps < 1:
            raise ValueError("intervals and substeps must be positive integers")
        self.sc, self.scale = sc, _scaling(sc)
        self.n_targets, self.n_phases, self.intervals = n_targets, n_targets + 1, intervals
        self.zones = zones if zones is not None and zones.zones else None
        n_w = sc.n_wheels
        P, N = self.n_phases, intervals
        K = P * N
        self.n_nodes = K + 1
        T = ca.MX.sym("T", P)
        Q = ca.MX.sym("Q", 4, K + 1)
        V = ca.MX.sym("V", n_w, K + 1)                       # ν, the relative wheel speed
        U = ca.MX.sym("U", n_w, K)
        targets = ca.MX.sym("targets", 4, max(n_targets, 1))
        q_end = ca.MX.sym("q_end", 4)
        dwell = ca.MX.sym("dwell", max(n_targets, 1))      # τ held at each target, in the order's sequence
        dtau = ca.repmat(T.T / N, N, 1).reshape((1, K))  # phase p's dτ on intervals p*N ... p*N+N-1
        # τ of every node along the tour: the intervals before it and the dwells of the targets passed
        held = ca.vertcat(0, ca.cumsum(dwell)[:n_targets]) if n_targets else ca.MX.zeros(1, 1)  # (P,) per phase
        t_nodes = ca.horzcat(0, ca.cumsum(dtau, 1) + ca.repmat(held.T, N, 1).reshape((1, K)))
        step = _interval_map(self.scale, substeps).map(K)
        rows = [self._passage_rows(Q, V, U, dtau, step, targets, q_end),
                self._observation_rows(V, t_nodes, dwell),
                self._wheel_speed_rows(V, bound_margin), self._rate_rows(V, rate_max)]
        if self.zones is not None:
            rows.append(self._zone_rows(T, Q, V, U, dtau, step, zone_margin, t_nodes, dwell))
        g = [expr for block in rows for expr in block[0]]
        start = len(rows[0][1])
        self._observation_rows_at = slice(start, start + len(rows[1][1]))
        self._lbg = np.concatenate([block[1] for block in rows])
        self._ubg = np.concatenate([block[2] for block in rows])
        self._x = ca.vertcat(T, ca.vec(Q), ca.vec(V), ca.vec(U))
        self._split = ca.Function("split", [self._x], [T, Q, V, U])
        nlp = {"x": self._x, "p": ca.vertcat(ca.vec(targets), q_end, dwell), "f": ca.sum1(T), "g": ca.vertcat(*g)}
        self.ipopt_options = {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": tol,
                              "ipopt.max_iter": max_iter, "ipopt.mu_strategy": "adaptive",
                              "ipopt.sb": "yes",
                              # SX expansion: slower to build, faster to evaluate; worth it for
                              # small NLPs (legs) or when one NLP is solved for many orders
                              "expand": n_targets == 0 if expand is None else bool(expand)}
        self._nlp = nlp
        self._solver = ca.nlpsol("schedule", "ipopt", nlp, self.ipopt_options)
        self._solver_wall = None
        self._variable_bounds(bound_margin)

    # -- constraint rows: each block is (expressions, lower bounds, upper bounds) ---------------
    def _per_nu(self, per_h: np.ndarray) -> np.ndarray:
        """A map of h written as a map of ν = M h: ``per_h M⁻¹``."""
        return np.linalg.solve(self.scale.relative.T, per_h.T).T

    def _passage_rows(self, Q, V, U, dtau, step, targets, q_end):
        """Equalities: the shooting defects of every interval, each target reached with ω_z = 0
        at its node, the end attitude, and ω_z = 0 at both ends (implied by rest through the
        ν = 0 bounds, the only condition at a passage)."""
        K, N = self.n_nodes - 1, self.intervals
        q_next, nu_next = step(Q[:, :K], V[:, :K], U, dtau)
        g = [ca.vec(Q[:, 1:] - q_next), ca.vec(V[:, 1:] - nu_next)]
        rate_z = ca.DM(self._per_nu(self.scale.rate_per_h[2:3, :]))
        for p in range(self.n_targets):
            node = (p + 1) * N
            g += [symbolic.error_vector(Q[:, node], targets[:, p]), rate_z @ V[:, node]]
        g.append(symbolic.error_vector(Q[:, K], q_end))
        g += [rate_z @ V[:, 0], rate_z @ V[:, K]]
        n_eq = sum(int(gi.numel()) for gi in g)
        return g, np.zeros(n_eq), np.zeros(n_eq)

    def _observation_rows(self, V, t_nodes, dwell):
        """Per target, in the order's sequence: its body rates about x and y at its node, then its
        passage time τ along the tour (dwells included). Their bounds are set by each solve
        (:meth:`solve`): rates free at a passage, zero where the target is held (a dwell, at rest);
        the passage time within the target's observation window."""
        if not self.n_targets:
            return [], np.zeros(0), np.zeros(0)
        N = self.intervals
        rate_xy = ca.DM(self._per_nu(self.scale.rate_per_h[:2, :]))
        nodes = [(p + 1) * N for p in range(self.n_targets)]
        g = [rate_xy @ V[:, k] for k in nodes] + [t_nodes[:, nodes].T]
        n = 3 * self.n_targets
        return g, np.full(n, -np.inf), np.full(n, np.inf)

    def _wheel_speed_rows(self, V, bound_margin: float):
        """The inertial wheel speed h = M⁻¹ν within the limit too (besides the relative
        speed the dynamics limit), only on the wheels where the box on ν does not already imply it (none
        with wheels on principal axes: M is then diagonal, ≥ 1). Both are linear in ν, so the bounds
        at the nodes hold everywhere."""
        inverse = self._per_nu(np.eye(self.sc.n_wheels))
        wheels = [i for i in range(self.sc.n_wheels) if np.abs(inverse[i]).sum() > 1.0]
        if not wheels:
            return [], np.zeros(0), np.zeros(0)
        n = len(wheels) * self.n_nodes
        limit = 1.0 - bound_margin
        return [ca.vec(ca.DM(inverse[wheels, :]) @ V)], np.full(n, -limit), np.full(n, limit)

    def _rate_rows(self, V, rate_max: float):
        """The body-rate box, only on the axes where the box on ν does not already imply it
        (rates are linear in ν)."""
        per_nu = self._per_nu(self.scale.rate_per_h)
        rate_rows = [i for i in range(3) if np.abs(per_nu[i]).sum() > rate_max]
        if not rate_rows:
            return [], np.zeros(0), np.zeros(0)
        R = ca.DM(per_nu[rate_rows, :] / rate_max)
        n = len(rate_rows) * self.n_nodes
        return [ca.vec(R @ V)], np.full(n, -1.0), np.full(n, 1.0)

    def _zone_rows(self, T, Q, V, U, dtau, step, zone_margin: float, t_nodes, dwell):
        """Every zone at every node and interval midpoint (module docstring), at the point's time
        along the tour (``t_nodes``, τ, dwells included) when a zone moves, and at each target held
        through its dwell (its middle and end: a moving zone must stay off the observation); the
        tour then stays within the zones' window, where their series hold."""
        K, N = self.n_nodes - 1, self.intervals
        q_mid, _ = step(Q[:, :K], V[:, :K], U, dtau / 2)
        zone_g = self._zone_function(zone_margin)
        n_zone = len(self.zones.zones) * (2 * K + 1)
        lbg, ubg = np.full(n_zone, -np.inf), np.zeros(n_zone)
        if not self.zones.moving:
            return [ca.vec(zone_g.map(K + 1)(Q)), ca.vec(zone_g.map(K)(q_mid))], lbg, ubg
        g = [ca.vec(zone_g.map(K + 1)(Q, t_nodes)), ca.vec(zone_g.map(K)(q_mid, t_nodes[:, :K] + dtau / 2))]
        for p in range(self.n_targets):
            node = (p + 1) * N
            g += [zone_g(Q[:, node], t_nodes[:, node] + fraction * dwell[p]) for fraction in (0.5, 1.0)]
        n_held = len(self.zones.zones) * 2 * self.n_targets
        g.append(ca.sum1(T) + ca.sum1(dwell[:self.n_targets]) if self.n_targets else ca.sum1(T))
        return (g, np.concatenate([lbg, np.full(n_held, -np.inf), [0.0]]),
                np.concatenate([ubg, np.zeros(n_held), [self.zones.window / self.scale.t_sat]]))

    def _variable_bounds(self, bound_margin: float) -> None:
        """Box on the decision vector (T, Q, V, U): phase durations in [1e-3, 1e4] τ, quaternion
        components in ±1.5, relative wheel speed ν and torque within the margin of the unit box;
        the indices of q₀, ν₀ and ν_f that a solve pins."""
        P, K, n_w = self.n_phases, self.n_nodes - 1, self.sc.n_wheels
        limit = 1.0 - bound_margin
        lbx = ca.vertcat(np.full(P, 1e-3), np.full(4 * (K + 1), -1.5), np.full(n_w * (K + 1), -limit),
                         np.full(n_w * K, -limit))
        self._lbx = np.array(lbx).ravel()
        self._ubx = -self._lbx
        self._ubx[:P] = 1e4
        iq0, ih0 = P, P + 4 * (K + 1)
        self._index_q0, self._index_h0 = slice(iq0, iq0 + 4), slice(ih0, ih0 + n_w)
        self._index_hf = slice(ih0 + n_w * K, ih0 + n_w * (K + 1))

    def _zone_function(self, margin: float) -> ca.Function:
        """``(q, τ) -> g`` (moving zones, τ the tour's normalised time) or ``q -> g`` (none moving):
        the zone constraints ``g ≤ 0`` of :meth:`att_planner.zones.FittedZones.casadi_constraints`."""
        q, tau = ca.SX.sym("q", 4), ca.SX.sym("tau")
        moving = self.zones.moving
        g = ca.vertcat(*self.zones.casadi_constraints(tau * self.scale.t_sat if moving else 0.0,
                                                      symbolic.dcm_NB(q), margin))
        return ca.Function("zones", [q, tau] if moving else [q], [g])

    # -- guesses ----------------------------------------------------------------------------
    def initial_guess(self, q_start, targets_in_order, q_end, dwell=None, arrivals=None) -> ScheduleSolution:
        """Slerp between consecutive (sign-aligned) attitudes with eigenaxis durations (or the legs
        that reach the targets at ``arrivals``, s, after their ``dwell``: waiting for a window);
        wheel momentum from the slerp rate by (1), clipped to the box; zero torque. With zones, the
        nodes between the passages are pushed out of them (:meth:`_clear_zones`) and the momentum
        follows: each node's from the rotation of the interval before it (else the guess's rates
        cross the pushed attitudes)."""
        P, N, n_w = self.n_phases, self.intervals, self.sc.n_wheels
        chain = _aligned([q_start, *targets_in_order, q_end])
        dur = np.array([max(eigenaxis_rest_to_rest_time(self.sc, a, b), 1.0) for a, b in zip(chain[:-1], chain[1:])])
        dwell = np.zeros(P - 1) if dwell is None else np.asarray(dwell, float)
        if arrivals is not None and P > 1:     # each leg from the end of the previous observation to the arrival
            arrivals = np.asarray(arrivals, float)
            dur[:-1] = np.maximum(arrivals - np.concatenate([[0.0], arrivals[:-1] + dwell[:-1]]), dur[:-1])
        dur = dur / self.scale.t_sat
        qs, hs = [chain[0][None, :]], [np.zeros((1, n_w))]
        for p in range(P):
            s = np.arange(1, N + 1) / N
            qs.append(rot.slerp(chain[p], chain[p + 1], s))
            axis, angle = rot.to_axis_angle(rot.multiply(rot.conjugate(chain[p]), chain[p + 1]))
            w_tau = axis * angle / dur[p]
            h = np.clip(np.linalg.lstsq(self.scale.rate_matrix, w_tau, rcond=None)[0], -0.9, 0.9)
            hs.append(np.tile(h, (N, 1)))
        hs[-1][-1] = 0.0
        q = np.vstack(qs)
        h = np.vstack(hs)
        if self.zones is not None:
            q = self._clear_zones(q, dur, dwell)
            for k in range(P * N - 1):      # the rates of the moved nodes: node k+1 gets interval k's
                axis, angle = rot.to_axis_angle(rot.multiply(rot.conjugate(q[k]), q[k + 1]))
                w_tau = axis * angle / (dur[k // N] / N)
                h[k + 1] = np.clip(np.linalg.lstsq(self.scale.rate_matrix, w_tau, rcond=None)[0], -0.9, 0.9)
        return ScheduleSolution(dur, q, h, np.zeros((P * N, n_w)), False, "guess", 0, 0.0)

    def _clear_zones(self, q: np.ndarray, durations: np.ndarray, dwell: np.ndarray,
                     beyond: float = np.deg2rad(2.0)) -> np.ndarray:
        """The guess's attitudes ``q`` (K+1, 4) with each node between the passages that violates a
        zone (at its time) turned so that its boresight lies ``beyond`` outside the zone
        (keep-out: pushed off the guess's local plane of motion too, so the guess goes round the
        zone, not along its axis; keep-in: pulled in radially). A slerp through a zone's axis
        would give the NLP a zero constraint gradient to start from."""
        N, zs = self.intervals, self.zones
        t = node_times(durations * self.scale.t_sat, dwell, N)
        t = np.minimum(t, zs.window)
        out = q.copy()
        for k in range(1, len(q) - 1):
            if k % N == 0:              # the targets are imposed
                continue
            for z in np.flatnonzero(zs.margins(t[k], out[k])[0] < 0):
                s_z = zs.sensor_axes[z] / np.linalg.norm(zs.sensor_axes[z])
                a, theta = zs.axes(t[k])[z], zs.half_angles(t[k])[z]
                b = rot.dcm_NB(out[k]) @ s_z
                radial = b - (b @ a) * a
                if zs.keep_in[z]:
                    rho, side = theta - beyond, radial
                else:                   # off the plane of b_{k-1}, b_{k+1}: round the zone
                    normal = np.cross(rot.dcm_NB(q[k - 1]) @ s_z, rot.dcm_NB(q[k + 1]) @ s_z)
                    normal = normal - (normal @ a) * a
                    rho = theta + beyond
                    side = radial + (normal / np.linalg.norm(normal) if np.linalg.norm(normal) > 1e-12 else 0.0)
                if np.linalg.norm(side) < 1e-12:
                    side = rot.orthonormal_basis(a)[0]
                side = side / np.linalg.norm(side)
                target = np.cos(rho) * a + np.sin(rho) * side
                axis = np.cross(b, target)
                if np.linalg.norm(axis) > 1e-12:
                    angle = np.arctan2(np.linalg.norm(axis), b @ target)
                    out[k] = rot.multiply(rot.from_axis_angle(axis / np.linalg.norm(axis), angle), out[k])
        return out

    def resample(self, sol: ScheduleSolution) -> ScheduleSolution:
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
        return ScheduleSolution(sol.durations.copy(), q, h, u, False, "resampled", 0, 0.0)

    # -- solve ------------------------------------------------------------------------------
    def solve(self, q_start, targets_in_order, q_end, guess: ScheduleSolution | None = None,
              max_wall_time: float | None = None, start_at_rest: bool = True,
              end_at_rest: bool = True, dwell=None, windows=None, arrivals=None) -> ScheduleSolution:
        """Minimum-time trajectory through ``targets_in_order`` (quaternions, any sign), holding each
        at rest for its ``dwell`` (s, in the same order; none: a passage) and arriving within its
        window (``windows``: (opens, closes) s from the start, the observation ending by ``closes``).
        ``arrivals`` (s): the guess's arrival times (waiting for windows), else eigenaxis legs."""
        if len(targets_in_order) != self.n_targets:
            raise ValueError(f"expected {self.n_targets} targets, got {len(targets_in_order)}")
        n = self.n_targets
        dwell = np.zeros(n) if dwell is None else np.asarray(dwell, float)
        windows = [(-np.inf, np.inf)] * n if windows is None else windows
        if guess is None:
            guess = self.initial_guess(q_start, targets_in_order, q_end, dwell, arrivals)
        solver = self._solver
        if max_wall_time is not None:
            solver = ca.nlpsol("schedule", "ipopt", self._nlp,
                               {**self.ipopt_options, "ipopt.max_wall_time": max(float(max_wall_time), 0.01)})
        relative = self.scale.relative
        x0 = np.concatenate([guess.durations, guess.q.ravel(), (guess.h @ relative.T).ravel(), guess.u.ravel()])
        lbx, ubx = self._lbx.copy(), self._ubx.copy()
        q0 = rot.normalize(np.asarray(q_start, float))
        lbx[self._index_q0] = ubx[self._index_q0] = q0 if np.dot(q0, guess.q[0]) >= 0 else -q0
        if start_at_rest:
            lbx[self._index_h0] = ubx[self._index_h0] = 0.0
        if end_at_rest:
            lbx[self._index_hf] = ubx[self._index_hf] = 0.0
        targets = ([rot.normalize(np.asarray(q, float)) for q in targets_in_order] if self.n_targets
                   else [np.zeros(4)])
        t_sat = self.scale.t_sat
        params = np.concatenate([*targets, rot.normalize(np.asarray(q_end, float)),
                                 dwell / t_sat if n else np.zeros(1)])
        lbg, ubg = self._lbg.copy(), self._ubg.copy()
        rows = np.arange(self._observation_rows_at.start, self._observation_rows_at.stop)
        held = np.repeat(dwell > 0, 2)
        lbg[rows[:2 * n][held]] = ubg[rows[:2 * n][held]] = 0.0
        lbg[rows[2 * n:]] = [w[0] / t_sat for w in windows]
        ubg[rows[2 * n:]] = [(w[1] - d) / t_sat for w, d in zip(windows, dwell)]
        x0 = np.clip(x0, lbx, ubx)
        start = time.perf_counter()
        out = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg, p=params)
        seconds = time.perf_counter() - start
        stats = solver.stats()
        T, Q, V, U = (np.array(v) for v in self._split(out["x"]))
        return ScheduleSolution(T.ravel(), Q.T, np.linalg.solve(relative, V).T, U.T, bool(stats["success"]),
                                str(stats["return_status"]), int(stats.get("iter_count", 0)), seconds)


_TRANSCRIPTIONS: dict = {}


CACHE_SIZE = 64          # NLPs kept (the oldest goes first): zones make an NLP per problem


def cached_transcription(sc: dyn.Spacecraft, n_targets: int, intervals: int, substeps: int,
                         rate_max: float, expand: bool | None = None, zones=None,
                         zone_margin: float = 0.0) -> MultiphaseTranscription:
    """Solver cache: an NLP depends only on the spacecraft, the number of targets, the grid and the
    zones (a FittedZones, by identity: the cached NLP holds it, so its id stays unique)."""
    zone_key = None if zones is None or not zones.zones else (id(zones), float(zone_margin))
    key = (sc.inertia.tobytes(), sc.wheel_axes.tobytes(), sc.wheel_inertia, sc.wheel_torque_max,
           sc.wheel_speed_max, n_targets, intervals, substeps, rate_max, expand, zone_key)
    if key not in _TRANSCRIPTIONS:
        while len(_TRANSCRIPTIONS) >= CACHE_SIZE:
            _TRANSCRIPTIONS.pop(next(iter(_TRANSCRIPTIONS)))
        _TRANSCRIPTIONS[key] = MultiphaseTranscription(sc, n_targets, intervals, substeps, rate_max, expand=expand,
                                                       zones=zones, zone_margin=zone_margin)
    return _TRANSCRIPTIONS[key]
