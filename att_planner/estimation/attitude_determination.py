"""Attitude from vector observations without a prior: TRIAD, QUEST and the coarse sun vector.

Observations are unit vectors measured in the body, ``b_i``, whose inertial directions ``r_i`` are
known (the Sun from the ephemeris, the field from IGRF). Wahba's problem: the attitude matrix
``A`` (inertial-to-body) minimising ``Σ w_i |b_i − A r_i|²``. In the suite's convention ``A =
R(q)ᵀ`` with ``q`` body-to-inertial, and ``R(q)ᵀ = (w² − |v|²) I + 2 v vᵀ − 2 w [v×]`` is exactly
Shuster's ``A(q)``: the quaternion these methods find is the suite's ``q`` component for component.

* :func:`triad` — Black (1964): two observations, the first kept exactly.
* :func:`quest` — Shuster & Oh (1981), "Three-axis attitude determination from vector
  observations", J. Guidance Control 4(1): the largest root of Davenport's characteristic equation
  by Newton–Raphson from ``λ₀ = Σ w_i``, the optimal quaternion from its Gibbs vector, and the method
  of sequential rotations (near a 180° rotation both parts of ``(x, γ)`` vanish: of the references
  as given and turned by π about each axis, the one with the largest ``|γ|`` is solved); with
  weights ``1/σ_i²`` its attitude-error covariance (body axes) is ``(Σ w_i (I − b_i b_iᵀ))⁻¹``
  (Markley & Crassidis 2014 §5.5).
* :func:`sun_vector` — least squares on the lit coarse sun sensors' cosine law.
"""
from __future__ import annotations

import numpy as np

from att_sim.models import rotations as rot

# the references as given, and turned by π about x, y, z (the method of sequential rotations)
REFERENCE_ROTATIONS = (rot.IDENTITY, np.array([1.0, 0.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0, 0.0]),
                       np.array([0.0, 0.0, 1.0, 0.0]))


def _unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    n = float(np.linalg.norm(v))
    if not np.isfinite(n) or n == 0.0:
        raise ValueError("an observation is zero or not finite")
    return v / n


def triad(b1_B, b2_B, r1_N, r2_N) -> np.ndarray:
    """The attitude ``q_BN`` from two observations (``b_B`` in body axes of the inertial ``r_N``); the
    first pair is matched exactly. ValueError when either pair is parallel (no attitude)."""
    b1_B, b2_B, r1_N, r2_N = (_unit(v) for v in (b1_B, b2_B, r1_N, r2_N))
    frames = []
    for u, v in ((b1_B, b2_B), (r1_N, r2_N)):
        w = np.cross(u, v)
        n = float(np.linalg.norm(w))
        if n < 1e-8:
            raise ValueError("TRIAD needs two observations that are not parallel")
        w /= n
        frames.append(np.column_stack([u, w, np.cross(u, w)]))
    body, inertial = frames
    return rot.normalize(rot.from_dcm_NB(inertial @ body.T))


def _quest_once(b: np.ndarray, r: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, float]:
    """Shuster's QUEST for these references: the quaternion and |γ| (unnormalised)."""
    B = (w[:, None, None] * b[:, :, None] * r[:, None, :]).sum(axis=0)
    S = B + B.T
    z = (w[:, None] * np.cross(b, r)).sum(axis=0)
    sigma = float(np.trace(B))
    kappa = float(S[1, 1] * S[2, 2] - S[1, 2] * S[2, 1] + S[0, 0] * S[2, 2] - S[0, 2] * S[2, 0]
                  + S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0])          # tr adj(S): the principal 2x2 minors
    delta = float(np.linalg.det(S))
    a, bb = sigma**2 - kappa, sigma**2 + z @ z
    c, d = delta + z @ S @ z, z @ S @ S @ z
    lam = float(w.sum())
    for _ in range(50):                 # λ⁴ − (a + b)λ² − cλ + (ab + cσ − d) = 0, Newton from Σ w
        f = lam**4 - (a + bb) * lam**2 - c * lam + (a * bb + c * sigma - d)
        df = 4 * lam**3 - 2 * (a + bb) * lam - c
        step = f / df if df != 0 else 0.0
        lam -= step
        if abs(step) <= 1e-15 * max(1.0, abs(lam)):
            break
    alpha = lam**2 - sigma**2 + kappa
    beta = lam - sigma
    gamma = (lam + sigma) * alpha - delta
    x = (alpha * np.eye(3) + beta * S + S @ S) @ z
    q = np.append(x, gamma)
    norm = float(np.linalg.norm(q))
    if norm == 0.0:                     # this reference rotation's solution is 180 deg away: |γ| 0, never chosen
        return q, 0.0
    return q / norm, abs(gamma)


def quest(observed_B, reference_N, weights) -> tuple[np.ndarray, np.ndarray]:
    """The optimal attitude ``q_BN`` for unit observations ``observed_B`` (n, 3, body axes) of the
    inertial ``reference_N`` (n, 3) with ``weights`` (n,) (use 1/σ_i²), and its attitude-error
    covariance in body axes (rad², valid for weights 1/σ_i²). ValueError for fewer than two
    non-parallel vectors."""
    b = np.array([_unit(v) for v in np.atleast_2d(observed_B)])
    r = np.array([_unit(v) for v in np.atleast_2d(reference_N)])
    w = np.asarray(weights, float).reshape(-1)
    if len(b) != len(r) or len(b) != len(w) or len(b) < 2 or np.any(~np.isfinite(w)) or np.any(w <= 0):
        raise ValueError("QUEST needs at least two observations with matching references and positive weights")
    information = (w[:, None, None] * (np.eye(3) - b[:, :, None] * b[:, None, :])).sum(axis=0)
    if np.linalg.cond(information) > 1e12:
        raise ValueError("QUEST needs two observations that are not parallel")
    # references r' = R_k r (R_k symmetric) give A' = A R_k, so R(q) = R_k R(q'): q = q_k ⊗ q'
    candidates = [(q_k, *_quest_once(b, r @ rot.dcm_NB(q_k), w)) for q_k in REFERENCE_ROTATIONS]
    q_k, q_rotated, _ = max(candidates, key=lambda c: c[2])
    return rot.normalize(rot.multiply(q_k, q_rotated)), np.linalg.inv(information)


def sun_vector(values, normals_B, threshold: float) -> np.ndarray | None:
    """Sun direction in body axes (``sun_B``) from coarse sun sensor outputs (cosine law ``I_i = n_iᵀ s``) by
    least squares over the detectors above ``threshold``; None when fewer than three lit detectors
    span the space (eclipse, or the Sun seen by too few)."""
    values = np.asarray(values, float)
    lit = values > threshold
    n = np.asarray(normals_B, float)[lit]
    if lit.sum() < 3 or np.linalg.matrix_rank(n, tol=1e-3) < 3:
        return None
    s, *_ = np.linalg.lstsq(n, values[lit], rcond=None)
    norm = float(np.linalg.norm(s))
    return s / norm if norm > 0 else None
