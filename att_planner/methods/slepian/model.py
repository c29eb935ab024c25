"""The discretised smooth maneuver and its exact derivatives (see the package docstring)."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.signal.windows import dpss

from att_planner.problem import ManeuverProblem
from att_sim import rotations as rot

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
        axis = rot.to_axis_angle(rot.from_dcm(R))[0]
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
    ``cone_cos`` holds cos(θ_i + margin): the optimiser keeps a small angular margin so that the
    truth integration of the ZOH torque (which lags the model by half a sample) stays outside.
    """

    basis: np.ndarray            # (N, M) unit-energy DPSS
    inertia: np.ndarray          # (3, 3) scaled
    inertia_scale: float
    torque_max: float
    R_initial: np.ndarray
    R_final: np.ndarray
    sensor_axis: np.ndarray
    cone_dirs: np.ndarray        # (C, 3)
    cone_cos: np.ndarray         # (C,)
    sensor_target: np.ndarray | None = None
    target_basis: np.ndarray | None = None   # (2, 3) rows ⊥ sensor_target
    half_bandwidth: float = PAPER_W

    @property
    def N(self) -> int:
        return self.basis.shape[0]

    @property
    def M(self) -> int:
        return self.basis.shape[1]

    @property
    def n_params(self) -> int:
        return 3 * self.M

    def tf_from_peak(self, peak_scaled_torque: float) -> float:
        return float(np.sqrt(self.inertia_scale * peak_scaled_torque / self.torque_max))

    def resized(self, N: int | None = None, M: int | None = None) -> SmoothManeuver:
        """Same maneuver with another sample count (same time-bandwidth product N·W, so the same
        continuous Slepian functions) and/or basis size."""
        N = self.N if N is None else N
        M = self.M if M is None else M
        W = self.half_bandwidth * self.N / N
        return replace(self, basis=slepian_basis(N, W, M), half_bandwidth=W)


def build_maneuver(problem: ManeuverProblem, M: int = PAPER_M, N: int = PAPER_N, W: float = PAPER_W,
                   cone_margin: float = 0.0) -> SmoothManeuver:
    """Discretise a :class:`ManeuverProblem` (validated options, see :func:`plan_slepian`)."""
    J = np.asarray(problem.spacecraft.inertia, float)
    scale = float(np.max(np.linalg.eigvalsh(J)))
    cones = list(problem.cones)
    dirs = np.array([c.direction for c in cones]).reshape(-1, 3)
    cos = np.cos(np.array([c.half_angle for c in cones]) + cone_margin)
    r = np.asarray(problem.sensor_axis, float)
    target = tbasis = None
    if problem.sensor_target is not None:
        target = np.asarray(problem.sensor_target, float)
        target = target / np.linalg.norm(target)
        smallest = np.eye(3)[np.argmin(np.abs(target))]    # never within 25° of the target
        tbasis = np.stack(rot.orthonormal_basis(target, references=(smallest, smallest)))
    return SmoothManeuver(slepian_basis(N, W, M), J / scale, scale, float(problem.spacecraft.body_torque_max),
                          rot.dcm(problem.q_initial), rot.dcm(problem.q_final), r / np.linalg.norm(r),
                          dirs, cos, target, tbasis, W)


@dataclass
class Evaluation:
    """Rates, torques, attitudes and constraint values for one α, with optional Jacobians.

    Parameter order: p = j·M + k for α_jk (α is (3, M)). Signs: ``cones`` ≤ 0 and
    ``final`` = 0 are feasible.
    """

    omega: np.ndarray           # (N, 3) normalised-time rates ω*
    torque: np.ndarray          # (N, 3) scaled T* (J/inertia_scale)
    R: np.ndarray               # (N+1, 3, 3)
    final: np.ndarray           # (3,) vee log(R_fᵀ R_{N+1}), or (2,) boresight ⊥ sensor_target
    cones: np.ndarray           # (N+1, C) w·b − cos(θ + margin)
    torque_jac: np.ndarray | None = None   # (N, 3, P)
    final_jac: np.ndarray | None = None    # (3 or 2, P)
    cones_jac: np.ndarray | None = None    # (N+1, C, P)

    @property
    def peak_torque(self) -> float:
        return float(np.abs(self.torque).max())


def evaluate(man: SmoothManeuver, alpha: np.ndarray, jac: bool = False) -> Evaluation:
    """Propagate α through the discretisation conventions (module docstring); exact Jacobians."""
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
    b = R @ man.sensor_axis                               # (N+1, 3) inertial boresight
    cones = b @ man.cone_dirs.T - man.cone_cos
    if man.sensor_target is None:
        e = _log_so3(man.R_final.T @ R[N])
        final = e
    else:
        final = man.target_basis @ b[N]
    ev = Evaluation(w, torque, R, final, cones)
    if not jac:
        return ev
    P = 3 * M
    # torque: dT_ℓ/dα_jk = J e_j D_ℓk + (ω_ℓ× J − (J ω_ℓ)×) e_j V_ℓk
    D = np.vstack([np.zeros((1, M)), np.diff(V, axis=0)]) / dt
    Agyro = rot.hat(w) @ J - rot.hat(Jw)                  # (N, 3, 3)
    tj = J[None, :, :, None] * D[:, None, None, :] + Agyro[..., None] * V[:, None, None, :]
    ev.torque_jac = tj.reshape(N, 3, P)
    # attitudes: dR_n = (η_n×) R_n, η_n = Σ_{m<n} Δτ R_{m+1} J_r(φ_m) e_j V_mk
    G = R[1:] @ _right_jacobian(phi)                      # (N, 3, 3)
    H = (dt * G[..., None] * V[:, None, None, :]).reshape(N, 3, P)
    eta = np.concatenate([np.zeros((1, 3, P)), np.cumsum(H, axis=0)])   # (N+1, 3, P)
    bw = rot.cross(b[:, None, :], man.cone_dirs[None, :, :])             # (N+1, C, 3)
    ev.cones_jac = np.einsum("nxp,ncx->ncp", eta, bw)
    if man.sensor_target is None:
        ev.final_jac = _left_jacobian_inv(final) @ man.R_final.T @ eta[N]
    else:
        bu = rot.cross(b[N][None, :], man.target_basis)                 # (2, 3)
        ev.final_jac = bu @ eta[N]
    return ev


def trace_residual(man: SmoothManeuver, R_end: np.ndarray) -> float:
    """The papers' final-attitude quantity 3 − tr(R_fᵀ R(1)) (≥ 0, zero at the goal)."""
    return float(3.0 - np.trace(man.R_final.T @ R_end))
