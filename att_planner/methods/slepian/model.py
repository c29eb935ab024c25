"""The discretised smooth maneuver and its exact derivatives (see the package docstring)."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy.signal.windows import dpss

from att_planner.cones import BOUNDARY_TOLERANCE, SMOOTH_END_RAMP, boundary_end_zones, end_ramp
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot

PAPER_M, PAPER_N, PAPER_W = 4, 500, 0.015
METHODS = ("slepian_minimum_time", "mssa", "dfsp")
DEFAULT_METHOD = "slepian_minimum_time"


# -- SO(3) helpers (stacked) -------------------------------------------------------------------

def _vee(S: np.ndarray) -> np.ndarray:
    return np.stack([S[..., 2, 1], S[..., 0, 2], S[..., 1, 0]], axis=-1)


def _log_so3(R: np.ndarray) -> np.ndarray:
    """Rotation vector of a single rotation matrix (angle in [0, π))."""
    c = np.clip(0.5 * (np.trace(R) - 1.0), -1.0, 1.0)
    th = float(np.arccos(c))
    w = 0.5 * _vee(R - R.T)                   # sin θ · axis
    if th < 1e-6:
        return w * (1.0 + th * th / 6.0)
    if th > np.pi - 1e-6:                     # θ ≈ π: axis from the symmetric part
        axis = rot.to_axis_angle(rot.from_dcm_NB(R))[0]
        return axis * th
    return w * (th / np.sin(th))


def _right_jacobian(phi: np.ndarray) -> np.ndarray:
    """J_r(φ) = I − (1 − cos θ)/θ² φ× + (θ − sin θ)/θ³ (φ×)², stacked, series near θ = 0."""
    th2 = np.sum(phi * phi, axis=-1)
    th = np.sqrt(th2)
    small = th < 1e-4
    ths = np.where(small, 1.0, th)
    a = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    b = np.where(small, 1.0 / 6.0 - th2 / 120.0, (ths - np.sin(ths)) / ths**3)
    P = rot.hat(phi)
    return np.eye(3) - a[..., None, None] * P + b[..., None, None] * (P @ P)


def _left_jacobian_inv(phi: np.ndarray) -> np.ndarray:
    """J_l⁻¹(φ) = I − ½ φ× + (1/θ² − (1 + cos θ)/(2 θ sin θ)) (φ×)² (single vector, θ < π)."""
    th = float(np.linalg.norm(phi))
    P = rot.hat(phi)
    c = 1.0 / 12.0 + th**2 / 720.0 if th < 1e-4 else 1.0 / th**2 - (1.0 + np.cos(th)) / (2.0 * th * np.sin(th))
    return np.eye(3) - 0.5 * P + c * (P @ P)


def _expm_stack(phi: np.ndarray) -> np.ndarray:
    """exp(φ×) for a stack of rotation vectors (Rodrigues, series near 0)."""
    th2 = np.sum(phi * phi, axis=-1)
    th = np.sqrt(th2)
    small = th < 1e-4
    ths = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th2 / 6.0, np.sin(ths) / ths)
    b = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    P = rot.hat(phi)
    return np.eye(3) + a[..., None, None] * P + b[..., None, None] * (P @ P)


def _cumulative_product(E: np.ndarray) -> np.ndarray:
    """P_n = E_0 E_1 … E_n for a stack of matrices (Hillis–Steele scan: log2 N batched products)."""
    P = E.copy()
    shift = 1
    while shift < len(P):
        P[shift:] = P[:-shift] @ P[shift:]
        shift *= 2
    return P


# -- the discretised problem -------------------------------------------------------------------

def slepian_basis(N: int, W: float, M: int) -> np.ndarray:
    """(N, M) matrix of the first M unit-energy DPSS of length N, half-bandwidth W."""
    return np.atleast_2d(dpss(N, N * W, Kmax=M)).T.copy()


@dataclass(frozen=True)
class SmoothManeuver:
    """Discretised smooth maneuver (all arrays ready for evaluation).

    ``inertia`` is J divided by ``inertia_scale`` (the largest principal inertia): the optimal α
    does not depend on that scale, and t_f = sqrt(inertia_scale · T*_scaled / T̄).

    Zones z = 1..Z (the problem's cones first, then its zones): body sensor axis
    ``zone_sensors[zone_sensor_index[z]]`` (one row per distinct axis), sign σ_z = ``zone_sign``
    (+1 keep-out, −1 keep-in) and constraint c_kz = σ_z (a_z(t_k)·R_k s_z − cos(θ_z(t_k) + σ_z m)) ≤ 0
    at t_k = τ_k t_f. The optimiser keeps the angular margin m = ``zone_margin`` (outside a
    keep-out zone, inside a keep-in one) so that the predicted trajectory of the ZOH torque (which
    lags the model by half a sample) stays clear; a zone with an end on its boundary
    (``zone_ramp``, :func:`att_planner.cones.boundary_end_zones`) gets ``−tol + (m + tol) w(τ_k)``
    instead, w the end ramp of a smooth plan (:func:`att_planner.cones.end_ramp`, ``SMOOTH_END_RAMP``).
    Static zones (``zone_sky`` None): constant axes
    ``cone_dirs`` and ``cone_cos`` = cos(θ_z + σ_z m). Moving zones: ``zone_sky``
    (:class:`att_planner.zones.FittedZones`) gives a_z(t), θ_z(t) and their rates, and ``cone_dirs``,
    ``cone_cos`` hold the values at t = 0.
    """

    basis: np.ndarray            # (N, M) unit-energy DPSS
    inertia: np.ndarray          # (3, 3) scaled
    inertia_scale: float
    torque_max: float
    R_initial: np.ndarray
    R_final: np.ndarray
    sensor_axis: np.ndarray
    cone_dirs: np.ndarray        # (Z, 3)
    cone_cos: np.ndarray         # (Z,)
    sensor_target: np.ndarray | None = None
    target_basis: np.ndarray | None = None   # (2, 3) rows ⊥ sensor_target
    half_bandwidth: float = PAPER_W
    zone_sensors: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))   # (U, 3) distinct body axes
    zone_sensor_index: np.ndarray = field(default_factory=lambda: np.zeros(0, int))   # (Z,) row per zone
    zone_sign: np.ndarray = field(default_factory=lambda: np.zeros(0))   # (Z,) +1 keep-out, −1 keep-in
    zone_margin: float = 0.0
    zone_ramp: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))   # (Z,) margins ramped at the ends
    zone_sky: Any = None                                     # FittedZones of moving zones, else None
    sky_memo: dict = field(default_factory=dict, compare=False, repr=False)   # (K, t_f, rates) → zone sky arrays

    @property
    def N(self) -> int:
        return self.basis.shape[0]

    @property
    def M(self) -> int:
        return self.basis.shape[1]

    @property
    def n_params(self) -> int:
        return 3 * self.M

    @property
    def moving(self) -> bool:
        """Whether the zone constraints depend on time (and so on t_f)."""
        return self.zone_sky is not None

    def tf_from_peak(self, peak_scaled_torque: float) -> float:
        """t_f = sqrt(J_s T*/T̄): the shortest time in which the profile of peak T* meets T̄."""
        return float(np.sqrt(self.inertia_scale * peak_scaled_torque / self.torque_max))

    def dtf_dpeak(self, peak_scaled_torque: float) -> float:
        """dt_f/dT* = t_f / (2 T*)."""
        return 0.5 * self.tf_from_peak(peak_scaled_torque) / peak_scaled_torque

    def resized(self, N: int | None = None, M: int | None = None) -> SmoothManeuver:
        """Same maneuver with another sample count (same time-bandwidth product N·W, so the same
        continuous Slepian functions) and/or basis size."""
        N = self.N if N is None else N
        M = self.M if M is None else M
        W = self.half_bandwidth * self.N / N
        return replace(self, basis=slepian_basis(N, W, M), half_bandwidth=W)


def build_maneuver(problem: ManeuverProblem, M: int = PAPER_M, N: int = PAPER_N, W: float = PAPER_W,
                   cone_margin: float = 0.0) -> SmoothManeuver:
    """Discretise a :class:`ManeuverProblem` (validated options, see :func:`plan_slepian`): its
    cones and zones from ``problem.zone_sky()``, moving when any zone moves."""
    J = np.asarray(problem.spacecraft.inertia, float)
    scale = float(np.max(np.linalg.eigvalsh(J)))
    sky = problem.zone_sky()
    zones = list(sky.zones)
    sign = np.array([-1.0 if z.keep_in else 1.0 for z in zones])
    dirs = np.asarray(sky.axes(0.0), float).reshape(-1, 3)
    cos = np.cos(np.asarray(sky.half_angles(0.0), float).reshape(-1) + sign * cone_margin)
    r = np.asarray(problem.sensor_axis, float)
    r = r / np.linalg.norm(r)
    sensors = [r]           # the problem's sensor first: the cones share it
    index = []
    for z in zones:
        s = np.asarray(z.sensor_axis, float)
        hit = [u for u, v in enumerate(sensors) if np.allclose(v, s, rtol=0.0, atol=1e-14)]
        if not hit:
            sensors.append(s)
        index.append(hit[0] if hit else len(sensors) - 1)
    target = tbasis = None
    if problem.sensor_target is not None:
        target = np.asarray(problem.sensor_target, float)
        target = target / np.linalg.norm(target)
        smallest = np.eye(3)[np.argmin(np.abs(target))]    # never within 25° of the target
        tbasis = np.stack(rot.orthonormal_basis(target, references=(smallest, smallest)))
    return SmoothManeuver(slepian_basis(N, W, M), J / scale, scale, float(problem.spacecraft.body_torque_max),
                          rot.dcm_NB(problem.q_initial), rot.dcm_NB(problem.q_final), r, dirs, cos, target, tbasis, W,
                          np.array(sensors), np.array(index, int), sign, float(cone_margin),
                          boundary_end_zones(problem, cone_margin), sky if sky.moving else None)


@dataclass
class Evaluation:
    """Rates, torques, attitudes and constraint values for one α, with optional Jacobians.

    Parameter order: p = j·M + k for α_jk (α is (3, M)). Signs: ``cones`` ≤ 0 and
    ``final`` = 0 are feasible. ``cones`` are the zone constraints c_kz (a cone is a static
    keep-out zone), for moving zones evaluated at t_k = τ_k ``tf`` with their exact t_f
    derivative ``cones_dtf``.
    """

    omega: np.ndarray           # (N, 3) normalised-time rates ω*
    torque: np.ndarray          # (N, 3) scaled T* (J/inertia_scale)
    R: np.ndarray               # (N+1, 3, 3)
    final: np.ndarray           # (3,) vee log(R_fᵀ R_{N+1}), or (2,) boresight ⊥ sensor_target
    cones: np.ndarray           # (N+1, Z) σ (a·b − cos(θ + σ margin))
    torque_jac: np.ndarray | None = None   # (N, 3, P)
    final_jac: np.ndarray | None = None    # (3 or 2, P)
    cones_jac: np.ndarray | None = None    # (N+1, Z, P)
    eta: np.ndarray | None = None          # (N+1, 3, P) attitude Jacobians dR_n = (η_n×) R_n
    tf: float | None = None                # t_f of the moving-zone rows (None: static zones)
    cones_dtf: np.ndarray | None = None    # (N+1, Z) ∂c_kz/∂t_f (moving zones, with the Jacobians)

    @property
    def peak_torque(self) -> float:
        return float(np.abs(self.torque).max())


def _tightening(man: SmoothManeuver, K: int):
    """The angular tightening of every zone at the K samples: ``zone_margin``, ramped at the ends
    for the ``zone_ramp`` zones ((K, Z); a scalar when none is ramped)."""
    if not man.zone_ramp.any():
        return man.zone_margin
    w = end_ramp(np.arange(K) / (K - 1), SMOOTH_END_RAMP)
    ramp = -BOUNDARY_TOLERANCE + (man.zone_margin + BOUNDARY_TOLERANCE) * w
    return np.where(man.zone_ramp, ramp[:, None], man.zone_margin)


def _zone_cos(man: SmoothManeuver, K: int) -> np.ndarray:
    """cos(θ_z + σ_z δ_kz) of the static zones: ``cone_cos`` (Z,), or (K, Z) with ramped zones."""
    if not man.zone_ramp.any():
        return man.cone_cos
    theta = np.arccos(man.cone_cos) - man.zone_sign * man.zone_margin
    return np.cos(theta + man.zone_sign * _tightening(man, K))


def _static_zones(man: SmoothManeuver, R: np.ndarray, jac: bool):
    """Constant zones: c = σ (b·a − cos(θ + σ m)) and the (N+1, Z, 3) vectors σ b × a, one
    product per distinct sensor (a single sensor: exactly the cone rows of Celani & Bruni 2021)."""
    if len(man.zone_sensors) == 1:      # the fast path of the cones
        b = R @ man.zone_sensors[0]
        values = b @ man.cone_dirs.T - _zone_cos(man, R.shape[0])
        bw = rot.cross(b[:, None, :], man.cone_dirs[None, :, :]) if jac else None
        if man.zone_sign.size and man.zone_sign.min() < 0:
            values *= man.zone_sign
            if jac:
                bw *= man.zone_sign[:, None]
        return values, bw
    Z = len(man.zone_sign)
    values = np.empty((R.shape[0], Z))
    cos = np.broadcast_to(_zone_cos(man, R.shape[0]), values.shape)
    bw = np.empty((R.shape[0], Z, 3)) if jac else None
    for u, s in enumerate(man.zone_sensors):
        sel = man.zone_sensor_index == u
        if not sel.any():
            continue
        b = R @ s
        values[:, sel] = b @ man.cone_dirs[sel].T - cos[:, sel]
        if jac:
            bw[:, sel] = rot.cross(b[:, None, :], man.cone_dirs[sel][None, :, :])
    if np.any(man.zone_sign < 0):
        values *= man.zone_sign
        if jac:
            bw *= man.zone_sign[:, None]
    return values, bw


def _moving_zones(man: SmoothManeuver, R: np.ndarray, tf: float, jac: bool):
    """Moving zones at t_k = τ_k t_f: c_kz = σ_z (a_z(t_k)·b_kz − cos θ̃_z(t_k)), θ̃ = θ + σ m,
    b_kz = R_k s_z; with ``jac`` also σ b × a (for dc = (σ b × a)·η) and
    ∂c_kz/∂t_f = σ_z τ_k (ȧ_z·b_kz + sin θ̃_z θ̇_z) from the zone sky's exact rates.
    Samples beyond the sky's window (an iterate longer than any plan may be) see the zones as at
    the window's end, with no t_f derivative; :func:`~.sqp.violation` refuses such a t_f."""
    sign = man.zone_sign
    B = np.moveaxis(R @ man.zone_sensors.T, -1, 1)[:, man.zone_sensor_index]     # (N+1, Z, 3)
    a, th = _sky_at(man, R.shape[0], tf, rates=False)
    values = sign * (np.einsum("nzx,nzx->nz", a, B) - np.cos(th))
    if not jac:
        return values, None, None
    bw = sign[:, None] * rot.cross(B, a)
    tau, a_dot, th_dot = _sky_at(man, R.shape[0], tf, rates=True)
    rate = np.einsum("nzx,nzx->nz", a_dot, B) + np.sin(th) * th_dot
    return values, bw, sign * tau[:, None] * rate


def _sky_at(man: SmoothManeuver, K: int, tf: float, rates: bool):
    """(a_z(t_k), θ_z(t_k) + σ_z m) or, with ``rates``, (dt_k/dt_f, ȧ_z, θ̇_z) at the K sample times
    t_k = τ_k t_f, remembered for the last few t_f (an SQP iteration asks for the same t_f several
    times). Beyond the window: the window's end, and dt_k/dt_f = 0 there."""
    key = (K, float(tf), rates, man.zone_margin)
    if key not in man.sky_memo:
        if len(man.sky_memo) > 8:
            man.sky_memo.clear()
        sky = man.zone_sky
        tau = np.arange(K) / (K - 1)
        inside = tau * tf <= sky.window
        t = np.where(inside, tau * tf, sky.window)
        if rates:
            man.sky_memo[key] = (np.where(inside, tau, 0.0), *sky.rates_at(t))
        else:
            axes, half = sky.at(t)
            man.sky_memo[key] = (axes, half + man.zone_sign * _tightening(man, K))
    return man.sky_memo[key]


def zones_at(man: SmoothManeuver, ev: Evaluation, tf: float | None = None, jac: bool = False) -> Evaluation:
    """``ev`` with its zone rows (and, with ``jac``, their Jacobians; needs ``ev.eta``) evaluated
    at the maneuver time ``tf`` (moving zones; default the plan's t_f = sqrt(J_s T*/T̄)).
    Static zones do not depend on t_f."""
    return _fill_zones(man, replace(ev), tf, jac)


def _fill_zones(man: SmoothManeuver, ev: Evaluation, tf: float | None, jac: bool) -> Evaluation:
    """:func:`zones_at` in place."""
    if not man.moving:
        values, bw = _static_zones(man, ev.R, jac)
        dtf = None
    else:
        tf = man.tf_from_peak(ev.peak_torque) if tf is None else float(tf)
        values, bw, dtf = _moving_zones(man, ev.R, tf, jac)
    cones_jac = np.einsum("nxp,ncx->ncp", ev.eta, bw) if jac else None
    ev.cones, ev.cones_jac, ev.tf, ev.cones_dtf = values, cones_jac, tf if man.moving else None, dtf
    return ev


def evaluate(man: SmoothManeuver, alpha: np.ndarray, jac: bool = False, tf: float | None = None) -> Evaluation:
    """Propagate α through the discretisation conventions (module docstring); exact Jacobians.
    Moving zones are evaluated at t_k = τ_k ``tf`` (default: the plan's own t_f, :func:`zones_at`)."""
    V = man.basis
    N, M = V.shape
    dt = 1.0 / N
    A = np.asarray(alpha, float).reshape(3, M)
    w = V @ A.T                                           # (N, 3)
    J = man.inertia
    dw = np.empty_like(w)
    dw[0] = 0.0
    dw[1:] = (w[1:] - w[:-1]) / dt
    Jw = w @ J.T
    torque = dw @ J.T + rot.cross(w, Jw)
    phi = dt * w
    E = _expm_stack(phi)
    R = np.concatenate([man.R_initial[None], man.R_initial @ _cumulative_product(E)])
    if man.sensor_target is None:
        final = _log_so3(man.R_final.T @ R[N])
    else:
        b_end = R[N] @ man.sensor_axis
        final = man.target_basis @ b_end
    ev = Evaluation(w, torque, R, final, np.zeros((N + 1, 0)))
    if not jac:
        return _fill_zones(man, ev, tf, jac=False)
    P = 3 * M
    # torque: dT_ℓ/dα_jk = J e_j D_ℓk + (ω_ℓ× J − (J ω_ℓ)×) e_j V_ℓk
    D = np.vstack([np.zeros((1, M)), np.diff(V, axis=0)]) / dt
    Agyro = rot.hat(w) @ J - rot.hat(Jw)                  # (N, 3, 3)
    tj = J[None, :, :, None] * D[:, None, None, :] + Agyro[..., None] * V[:, None, None, :]
    ev.torque_jac = tj.reshape(N, 3, P)
    # attitudes: dR_n = (η_n×) R_n, η_n = Σ_{m<n} Δτ R_{m+1} J_r(φ_m) e_j V_mk
    G = R[1:] @ _right_jacobian(phi)                      # (N, 3, 3)
    H = (dt * G[..., None] * V[:, None, None, :]).reshape(N, 3, P)
    ev.eta = np.concatenate([np.zeros((1, 3, P)), np.cumsum(H, axis=0)])   # (N+1, 3, P)
    if man.sensor_target is None:
        ev.final_jac = _left_jacobian_inv(final) @ man.R_final.T @ ev.eta[N]
    else:
        bu = rot.cross(b_end[None, :], man.target_basis)                 # (2, 3)
        ev.final_jac = bu @ ev.eta[N]
    return _fill_zones(man, ev, tf, jac=True)


def trace_residual(man: SmoothManeuver, R_end: np.ndarray) -> float:
    """The papers' final-attitude quantity 3 − tr(R_fᵀ R(1)) (≥ 0, zero at the goal)."""
    return float(3.0 - np.trace(man.R_final.T @ R_end))
