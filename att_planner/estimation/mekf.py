"""Multiplicative extended Kalman filter for attitude and gyro bias (no ROS, pure functions).

Lefferts, Markley & Shuster (1982), "Kalman filtering for spacecraft attitude estimation", J.
Guidance 5(5); Markley & Crassidis, *Fundamentals of Spacecraft Attitude Determination and
Control* (2014) §6.2. In the suite's convention (``q_BN``: the attitude of the body B relative to the
inertial frame N, ``q̇ = ½ q ⊗ [ω, 0]`` with ``ω = ω_BN_B``):

* global state: the reference quaternion ``q̂`` and the gyro bias ``b̂`` (body axes); the filter's state is the
  error ``δx = [δϑ, Δb]`` with ``q = q̂ ⊗ δq(δϑ)`` (a small rotation in **body** axes) and
  ``Δb = b − b̂``, covariance ``P`` (6×6);
* gyro model ``ω_m = ω + b + η_v``, ``ḃ = η_u`` (``σ_v`` angle random walk, ``σ_u`` rate random walk);
* propagation over ``Δt`` with ``ω̂ = ω_m − b̂`` held: ``q̂ ← q̂ ⊗ exp(ω̂ Δt)``, ``P ← Φ P Φᵀ + Q`` with
  ``Φ = [[Φ₁₁, Φ₁₂], [0, I]]``, ``Φ₁₁ = exp(−[ω̂×]Δt)`` and
  ``Φ₁₂ = −(I Δt − [ω̂×](1 − cos θ)/|ω̂|² + [ω̂×]²(θ − sin θ)/|ω̂|³)`` (θ = |ω̂|Δt), and
  ``Q = [[(σ_v²Δt + σ_u²Δt³/3) I, −σ_u²Δt²/2 I], [−σ_u²Δt²/2 I, σ_u²Δt I]]`` (§6.2.4);
* update with a residual ``y = h(x) − ĥ`` and sensitivity ``H`` (3×6): ``K = P Hᵀ S⁻¹``,
  ``S = H P Hᵀ + R``, Joseph-form covariance, then the **reset**: ``q̂ ← q̂ ⊗ δq(δϑ̂)`` (normalised),
  ``b̂ ← b̂ + Δb̂``, ``δx ← 0``;
* innovation gating: a measurement whose ``d² = yᵀ S⁻¹ y`` exceeds the chi-square quantile of its
  dimension is rejected (the filter is left unchanged);
* the gyro's scale factors and misalignments ``p`` (``ω_m = (I + E(p)) ω + ...``, nine small
  constants known only by their datasheet spread ``P_pp``) are *considered*, not estimated (Schmidt's
  consider filter; Tapley, Schutz & Born 2004 §6.9): ``E(p) ω̂ = G(ω̂) p`` drives the attitude error
  like the bias, ``Ψ = [Φ₁₂ G; 0]``, and the filter carries the cross-covariance ``C = cov(δx, p)``:
  ``P ← Φ P Φᵀ + Φ C Ψᵀ + Ψ Cᵀ Φᵀ + Ψ P_pp Ψᵀ + Q``, ``C ← Φ C + Ψ P_pp``; an update leaves ``p``
  alone: ``C ← (I − K H) C``. Without it a filter blind for a 60° slew is overconfident by the
  error ``E θ`` it cannot see (tens of arcseconds for a 50 ppm, 20″ gyro).

Residuals: an attitude measurement ``q_m`` (body) gives ``y = 2 vec(q̂* ⊗ q_m)`` (sign with w ≥ 0),
``H = [I 0]``; a unit vector measured in body axes ``b_m`` of the inertial ``r`` gives ``y = b_m −
R(q̂)ᵀ r`` and ``H = [[b̂×] 0]`` (from ``b = R(δq)ᵀ b̂ ≈ b̂ + b̂ × δϑ``).

Every function works on a stack of filters (a leading run axis: the runs of a Monte Carlo batch);
a single filter is a stack of one. The products and solves of each filter are the same whatever
the stack holds, so a filter reaches the same numbers in a batch as alone.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from att_sim.models import rotations as rot

I3 = np.eye(3)



@dataclass(frozen=True)
class FilterState:
    """One filter at time ``t``: reference attitude, gyro bias estimate and error covariance."""

    t: float
    q_BN: np.ndarray              # (4,) attitude of the body B relative to the inertial frame N
    bias_B: np.ndarray            # (3,) rad/s, body axes
    P: np.ndarray                 # (6, 6): [δϑ (rad, body), Δb (rad/s)]
    C: np.ndarray = field(default_factory=lambda: np.zeros((6, 9)))   # cov(δx, p): the considered gyro errors


@dataclass(frozen=True)
class Update:
    """What one measurement did: the state after it, whether it was accepted, its gate statistic."""

    state: FilterState
    accepted: bool
    d2: float


class Correction(NamedTuple):
    """A Kalman update to make on ``x``: residual ``y``, sensitivity ``H``, noise ``R``, gate on ``d²``."""

    x: FilterState
    y: np.ndarray
    H: np.ndarray
    R: np.ndarray
    gate: float = math.inf


def transition(omega_BN_B: np.ndarray, dt) -> np.ndarray:
    """``Φ`` (R×6×6) of R filters at their estimated rates ``omega_BN_B`` (R×3) over ``dt`` (R). With
    ``W = [ω̂×]`` and ``W² = ω̂ω̂ᵀ − |ω̂|² I``: ``Φ₁₁ = I − a W + b W²``, ``Φ₁₂ = −dt I + b W − c W²``,
    ``a = sin θ/|ω̂|``, ``b = (1 − cos θ)/|ω̂|²``, ``c = (θ − sin θ)/|ω̂|³`` (their series to O(θ³) below
    θ = 1e-6): the coefficients on Python floats filter by filter, the entries on arrays of filters."""
    w = np.asarray(omega_BN_B, float).reshape(-1, 3)
    dts = [float(d) for d in dt]
    coefficients = []
    for (w0, w1, w2), h in zip(w.tolist(), dts):
        n2 = w0 * w0 + w1 * w1 + w2 * w2
        norm = math.sqrt(n2)
        theta = norm * h
        if theta > 1e-6:
            sin = math.sin(theta)
            coefficients.append((sin / norm, (1.0 - math.cos(theta)) / n2, (theta - sin) / (n2 * norm), n2))
        else:
            coefficients.append((h, h * h / 2.0, h**3 / 6.0, n2))
    a, b, c, n2 = (v[:, None, None] for v in np.array(coefficients).T)
    W = rot.hat(w)
    W2 = w[:, :, None] * w[:, None, :] - n2 * I3        # ω̂ω̂ᵀ − |ω̂|² I (off the diagonal: minus 0.0)
    diagonal = np.zeros_like(W)
    diagonal[:, _DIAGONAL, _DIAGONAL] = -np.array(dts)[:, None]
    out = np.zeros((len(dts), 6, 6))
    out[:, :3, :3] = I3 - a * W + b * W2
    out[:, :3, 3:] = diagonal + b * W - c * W2
    out[:, 3:, 3:] = I3
    return out


_DIAGONAL = [0, 1, 2]


@functools.lru_cache(maxsize=64)
def process_noise(arw: float, rrw: float, dt: float) -> np.ndarray:
    """Discrete ``Q`` (6×6) of the gyro noise over ``dt`` (module docstring); read-only, cached
    (the gyro's interval is nearly always the same)."""
    Q = np.zeros((6, 6))
    i = np.arange(3)
    Q[i, i] = arw**2 * dt + rrw**2 * dt**3 / 3.0
    Q[i, i + 3] = Q[i + 3, i] = -rrw**2 * dt**2 / 2.0
    Q[i + 3, i + 3] = rrw**2 * dt
    Q.flags.writeable = False
    return Q


OFF_DIAGONAL = ((0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1))   # as att_sim.models.rotations.small_error_matrix


def scale_misalignment_sensitivity(omega_BN_B: np.ndarray) -> np.ndarray:
    """``G(ω)`` (3×9) with ``E(p) ω = G(ω) p``, ``p = [s_x, s_y, s_z, m_01, m_02, m_10, m_12, m_20, m_21]``
    (of each row of ``omega_BN_B`` (R×3): R×3×9)."""
    omega = np.asarray(omega_BN_B, float)
    G = np.zeros(omega.shape[:-1] + (27,))
    G[..., _SENSITIVITY_AT] = omega[..., _SENSITIVITY_OF]
    return G.reshape(omega.shape[:-1] + (3, 9))


_SENSITIVITY_AT = [0, 10, 20] + [9 * i + 3 + k for k, (i, _) in enumerate(OFF_DIAGONAL)]   # flat indices in G
_SENSITIVITY_OF = [0, 1, 2] + [j for _, j in OFF_DIAGONAL]                                # the rate's axis


def propagate(states, omega_BN_B_measured: np.ndarray, dt, arw: float, rrw: float,
              consider: np.ndarray | None = None, extra_attitude_noise=None) -> list[FilterState]:
    """The R filters ``states`` of one tuning, each advanced by its ``dt`` (R) with its measured mean rate
    ``omega_BN_B_measured`` (R×3) over the interval; ``consider``: the variances (9,) of the gyro's
    scale factors and misalignments (None: none); ``extra_attitude_noise`` (R, rad² per axis; None:
    none) is added to the attitude block (a saturated gyro). The matrices of all the filters are
    multiplied as one stack, the attitudes too (``q ⊗ exp(ω̂ Δt)``, elementwise)."""
    dt = [float(d) for d in dt]
    omega = np.asarray(omega_BN_B_measured, float).reshape(-1, 3) - np.array([x.bias_B for x in states])
    phi = transition(omega, dt)
    phi_T = phi.transpose(0, 2, 1)
    P = phi @ np.array([x.P for x in states]) @ phi_T + np.array([process_noise(arw, rrw, d) for d in dt])
    C = np.array([x.C for x in states])
    if consider is not None:
        psi = np.zeros((len(states), 6, 9))
        psi[:, :3] = phi[:, :3, 3:] @ scale_misalignment_sensitivity(omega)
        phi_C, psi_consider = phi @ C, psi * consider
        psi_T = psi.transpose(0, 2, 1)
        cross = phi_C @ psi_T
        P += cross + cross.transpose(0, 2, 1) + psi_consider @ psi_T
        C = phi_C + psi_consider
    for i, extra in enumerate(extra_attitude_noise if extra_attitude_noise is not None else ()):
        if extra:
            P[i, :3, :3] += extra * I3
    P = 0.5 * (P + P.transpose(0, 2, 1))
    q = rot.normalize(rot.propagate_constant_rate(np.array([x.q_BN for x in states]), omega, np.array(dt)[:, None]))
    return [FilterState(x.t + d, q[i], x.bias_B, P[i], C[i]) for i, (x, d) in enumerate(zip(states, dt))]


def attitude_residual(q_BN_estimate: np.ndarray, q_BN_measured: np.ndarray) -> np.ndarray:
    """``y = 2 vec(q̂* ⊗ q_m)`` (w ≥ 0): the measured small rotation from the estimate, body axes."""
    return 2.0 * rot.error_vector(q_BN_measured, q_BN_estimate)


def attitude_sensitivity() -> np.ndarray:
    return np.hstack([I3, np.zeros((3, 3))])


def vector_residual(q_BN_estimate: np.ndarray, measured_B: np.ndarray, reference_N: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Residual and sensitivity (3×6) of a body-axis measurement of the inertial vector ``reference_N``."""
    predicted_B = rot.dcm_BN(q_BN_estimate) @ np.asarray(reference_N, float)
    return np.asarray(measured_B, float) - predicted_B, np.hstack([rot.hat(predicted_B), np.zeros((3, 3))])


def update(corrections) -> list[Update]:
    """The Kalman update of each :class:`Correction` (residual, sensitivity, noise), then the reset;
    a measurement is rejected (its filter unchanged) when ``yᵀ S⁻¹ y`` exceeds its gate. The
    matrices of the corrections of one measurement size are stacks; a stack holding a singular
    innovation covariance is made correction by correction (that one rejected, ``d² = ∞``)."""
    corrections = list(corrections)
    shapes = {(c.y.shape, c.H.shape) for c in corrections}
    if len(shapes) > 1:                      # one stack per measurement size
        out: list[Update | None] = [None] * len(corrections)
        for shape in shapes:
            at = [i for i, c in enumerate(corrections) if (c.y.shape, c.H.shape) == shape]
            for i, u in zip(at, update([corrections[i] for i in at])):
                out[i] = u
        return out
    if not corrections:
        return []
    P, H, R = (np.array([c.x.P for c in corrections]), np.array([c.H for c in corrections]),
               np.array([c.R for c in corrections]))
    y = np.array([c.y for c in corrections], float)
    S = H @ P @ H.transpose(0, 2, 1) + R
    try:
        S_inv_y = np.linalg.solve(S, y[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:
        if len(corrections) == 1:
            return [Update(corrections[0].x, False, math.inf)]
        return [update([c])[0] for c in corrections]
    d2 = [float(a @ b) for a, b in zip(y, S_inv_y)]
    out = [Update(c.x, False, d) for c, d in zip(corrections, d2)]
    passed = [k for k, (c, d) in enumerate(zip(corrections, d2)) if d <= c.gate]
    if passed:
        P, H, R, y, S = P[passed], H[passed], R[passed], y[passed], S[passed]
        K = np.linalg.solve(S, H @ P).transpose(0, 2, 1)
        dx = (K @ y[:, :, None])[:, :, 0]
        A = np.eye(P.shape[1]) - K @ H
        P = A @ P @ A.transpose(0, 2, 1) + K @ R @ K.transpose(0, 2, 1)       # Joseph form
        P = 0.5 * (P + P.transpose(0, 2, 1))
        C = A @ np.array([corrections[k].x.C for k in passed])
        for j, k in enumerate(passed):
            x = corrections[k].x
            q = rot.normalize(rot.multiply(x.q_BN, rot.exp_map(dx[j, :3])))
            out[k] = Update(FilterState(x.t, q, x.bias_B + dx[j, 3:], P[j], C[j]), True, d2[k])
    return out


def healthy(P: np.ndarray) -> list[bool]:
    """Whether each covariance of the stack ``P`` (R×6×6) is usable: finite and positive definite (one
    Cholesky factorisation of the stack when every one is, else one by one)."""
    P = np.asarray(P, float)
    if np.all(np.isfinite(P)):
        try:
            np.linalg.cholesky(P)
            return [True] * len(P)
        except np.linalg.LinAlgError:
            pass
    if len(P) == 1:
        return [False]
    return [healthy(p[None])[0] for p in P]


def largest_attitude_variance(P: np.ndarray) -> list[float]:
    """The largest eigenvalue of the attitude block of each covariance of the stack ``P`` (R×6×6)."""
    return np.linalg.eigvalsh(np.asarray(P, float)[:, :3, :3]).max(axis=-1).tolist()
