"""Attitude conventions for the whole suite, written down once.

Convention (used everywhere, messages included):

* A quaternion is a numpy array ``[x, y, z, w]`` (geometry_msgs order, scalar last),
  Hamilton product, unit norm.
* ``q_BN`` is the attitude of the **body frame B with respect to the inertial frame N**
  (Basilisk's naming: ``q_RN`` a reference frame R, ``omega_BN_B`` the rate of B relative to N in
  B axes). Its matrices: ``dcm_NB(q_BN)`` takes body to inertial axes, ``v_N = [NB] v_B``;
  ``dcm_BN(q_BN) = dcm_NB(q_BN)ᵀ`` takes inertial to body axes, ``v_B = [BN] v_N``: the ``[BN]`` of
  Schaub & Junkins, *Analytical Mechanics of Space Systems* (2018) §3.2, and the attitude matrix
  ``C(q)`` of Bruni & Celani and of Wertz (1978).
* Kinematics: ``q̇_BN = ½ q_BN ⊗ [omega_BN_B, 0]``; equivalently ``[NB]˙ = [NB] hat(omega_BN_B)``.
  This equals the Olivares–Staffetti form ``q_dot = 0.5 Q(omega) q`` and the Bruni–Celani form
  ``q_v_dot = 0.5 (q_v × ω + q4 ω)``.
* ``q`` and ``-q`` are the same attitude; errors are computed sign-independently.

All functions accept a single quaternion ``(4,)`` or a stack ``(..., 4)``.
"""
from __future__ import annotations

import math
from operator import mul

import numpy as np

IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


_NEXT_AXIS = np.array([1, 2, 0])
_PREV_AXIS = np.array([2, 0, 1])


def cross(a: np.ndarray, b: np.ndarray, axis: int = -1) -> np.ndarray:
    """``a × b`` along ``axis``, broadcasting: single vectors, rows of runs ``(n, 3)`` and
    component-first batches alike (cheaper than ``np.cross`` on small stacks)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape == b.shape and a.size == 3 and a.shape[axis] == 3:   # one pair: the same products on Python floats
        (ax, ay, az), (bx, by, bz) = a.ravel().tolist(), b.ravel().tolist()
        return np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx]).reshape(a.shape)
    return a.take(_NEXT_AXIS, axis) * b.take(_PREV_AXIS, axis) - a.take(_PREV_AXIS, axis) * b.take(_NEXT_AXIS, axis)


def hat(v: np.ndarray) -> np.ndarray:
    """Skew-symmetric matrix ``v×`` so that ``hat(a) @ b == cross(a, b)``; works on stacks."""
    v = np.asarray(v, dtype=float)
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def normalize(q: np.ndarray) -> np.ndarray:
    """``q`` (or each row) over its norm. A single vector takes the scalar sum of squares, in the
    order numpy's reduction adds them (the same bits, several times faster)."""
    q = np.asarray(q, dtype=float)
    if q.ndim == 1:
        total = 0.0
        for c in q.tolist():
            total += c * c
        return q / math.sqrt(total)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product ``p ⊗ q`` (scalar last). Two single quaternions take the scalar formula
    (the same operations in the same order as the array one, so the same bits, several times faster)."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    if p.shape == (4,) and q.shape == (4,):
        (px, py, pz, pw), (qx, qy, qz, qw) = p.tolist(), q.tolist()
        return np.array([pw * qx + qw * px + (py * qz - pz * qy), pw * qy + qw * py + (pz * qx - px * qz),
                         pw * qz + qw * pz + (px * qy - py * qx), pw * qw - (px * qx + py * qy + pz * qz)])
    pv, pw = p[..., :3], p[..., 3:]
    qv, qw = q[..., :3], q[..., 3:]
    v = pw * qv + qw * pv + cross(pv, qv)
    w = pw * qw - np.sum(pv * qv, axis=-1, keepdims=True)
    return np.concatenate([v, w], axis=-1)


def conjugate(q: np.ndarray) -> np.ndarray:
    q = np.array(q, dtype=float)
    if q.shape == (4,):                 # one quaternion: the same negation on Python floats
        x, y, z, w = q.tolist()
        return np.array([-x, -y, -z, w])
    q[..., :3] *= -1.0
    return q


def dcm_NB(q_BN: np.ndarray) -> np.ndarray:
    """``[NB]``, the body-to-inertial matrix of the attitude ``q_BN`` (``v_N = [NB] v_B``): the
    transpose of Schaub & Junkins' ``[BN]`` (:func:`dcm_BN`)."""
    q = np.asarray(q_BN, dtype=float)
    if q.shape == (4,):                 # one quaternion: the same formula on Python floats
        x, y, z, w = q.tolist()
        return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    out = np.empty(q.shape[:-1] + (3, 3))
    out[..., 0, 0] = 1 - 2 * (y * y + z * z)
    out[..., 0, 1] = 2 * (x * y - z * w)
    out[..., 0, 2] = 2 * (x * z + y * w)
    out[..., 1, 0] = 2 * (x * y + z * w)
    out[..., 1, 1] = 1 - 2 * (x * x + z * z)
    out[..., 1, 2] = 2 * (y * z - x * w)
    out[..., 2, 0] = 2 * (x * z - y * w)
    out[..., 2, 1] = 2 * (y * z + x * w)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


def dcm_BN(q_BN: np.ndarray) -> np.ndarray:
    """``[BN] = [NB]ᵀ``, the inertial-to-body matrix of the attitude ``q_BN`` (``v_B = [BN] v_N``;
    Schaub & Junkins 2018 §3.2): the transposed view of :func:`dcm_NB`."""
    return np.swapaxes(dcm_NB(q_BN), -1, -2)


def to_body(q_BN: np.ndarray, v_N: np.ndarray) -> np.ndarray:
    """``v_B = [BN] v_N``, inertial vectors in body axes: ``q_BN`` (..., 4) (rows of runs, or one),
    ``v_N`` (..., 3) broadcasting against them (one vector for every row, or one per row). The
    matrix is the quadratic form of :func:`dcm_BN` (for a quaternion off unit norm too, as at an
    RK4 stage): ``[BN] = I + T(q qᵀ)`` with ``T`` linear."""
    q, v = np.asarray(q_BN, float), np.asarray(v_N, float)
    lead = q.shape[:-1]
    outer = (q[..., :, None] * q[..., None, :]).reshape(lead + (1, 16))
    quadratic = (outer @ _TO_BODY).reshape(lead + (3, 3))
    return v + (quadratic @ v[..., None])[..., 0]


def _to_body_form() -> np.ndarray:
    """``T`` of :func:`to_body` as a (16, 9) matrix: the entries of ``[BN] − I`` (row-major)
    as combinations of the products ``q_i q_j`` (row ``4 i + j``)."""
    x, y, z, w = range(4)
    form = np.zeros((16, 9))
    terms = {(0, 0): [(-2, y, y), (-2, z, z)], (0, 1): [(2, x, y), (2, z, w)], (0, 2): [(2, x, z), (-2, y, w)],
             (1, 0): [(2, x, y), (-2, z, w)], (1, 1): [(-2, x, x), (-2, z, z)], (1, 2): [(2, y, z), (2, x, w)],
             (2, 0): [(2, x, z), (2, y, w)], (2, 1): [(2, y, z), (-2, x, w)], (2, 2): [(-2, x, x), (-2, y, y)]}
    for (row, col), products in terms.items():
        for factor, i, j in products:
            form[4 * i + j, 3 * row + col] += factor
    return form


_TO_BODY = _to_body_form()


def from_dcm_NB(dcm_NB: np.ndarray) -> np.ndarray:
    """``q_BN`` of a body-to-inertial matrix ``[NB]`` (Shepperd's method, w >= 0)."""
    R = np.asarray(dcm_NB, dtype=float)
    flat = R.reshape(-1, 3, 3)
    out = np.empty((flat.shape[0], 4))
    for n, m in enumerate(flat):
        tr = np.trace(m)
        k = int(np.argmax([m[0, 0], m[1, 1], m[2, 2], tr]))
        if k == 3:
            s = 2.0 * np.sqrt(1.0 + tr)
            q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
        else:
            i, j, l = k, (k + 1) % 3, (k + 2) % 3
            s = 2.0 * np.sqrt(1.0 + m[i, i] - m[j, j] - m[l, l])
            q = np.empty(4)
            q[i] = 0.25 * s
            q[j] = (m[j, i] + m[i, j]) / s
            q[l] = (m[l, i] + m[i, l]) / s
            q[3] = (m[l, j] - m[j, l]) / s
        q = np.asarray(q, float)
        out[n] = q if q[3] >= 0 else -q
    return out.reshape(R.shape[:-2] + (4,))


def from_axis_angle(axis: np.ndarray, angle) -> np.ndarray:
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    half = 0.5 * np.asarray(angle, dtype=float)[..., None]
    return np.concatenate([axis * np.sin(half), np.cos(half)], axis=-1)


def to_axis_angle(q: np.ndarray) -> tuple[np.ndarray, float]:
    """Axis and angle in [0, π] of a single quaternion (shortest rotation)."""
    axis, angle = _axis_angle(q)
    return np.array(axis), angle


def _axis_angle(q) -> tuple[tuple[float, float, float], float]:
    """:func:`to_axis_angle` on Python floats (``q`` normalised as :func:`normalize` does: the same bits)."""
    x, y, z, w = np.asarray(q, float).tolist()
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = (x / n, y / n, z / n, w / n) if n > 0 else (math.nan,) * 4     # numpy's 0/0
    if w < 0:
        x, y, z, w = -x, -y, -z, -w
    s = math.sqrt(x * x + y * y + z * z)
    angle = 2.0 * math.atan2(s, w)
    return ((x / s, y / s, z / s) if s > 1e-15 else (1.0, 0.0, 0.0)), angle


def slerp(q0: np.ndarray, q1: np.ndarray, s) -> np.ndarray:
    """Attitude(s) a fraction ``s`` (scalar or array) of the way from q0 to q1 along the shortest
    rotation: ``q0 ⊗ (q0* ⊗ q1)^s``; shape ``(4,)`` or ``s.shape + (4,)``."""
    axis, angle = to_axis_angle(multiply(conjugate(q0), q1))
    s = np.asarray(s, dtype=float)
    return multiply(q0, from_axis_angle(np.broadcast_to(axis, s.shape + (3,)), s * angle))


def orthonormal_basis(v: np.ndarray, references=((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors ``(e1, e2)`` completing the unit ``v`` to a right-handed frame (e1, e2, v):
    ``e1 = v × a / |v × a|``, ``e2 = v × e1``, with ``a`` the first of ``references`` that is not
    within about 25° of ``v`` (the second otherwise)."""
    v = np.asarray(v, dtype=float)
    v = v / np.linalg.norm(v)
    first, second = (np.asarray(r, dtype=float) for r in references)
    a = first if abs(v @ first) < 0.9 else second
    e1 = np.cross(v, a)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(v, e1)


def exp_map(phi: np.ndarray) -> np.ndarray:
    """Quaternion of the rotation vector ``phi`` (``exp(hat(phi))``), stable near zero."""
    phi = np.asarray(phi, dtype=float)
    if phi.shape == (3,):               # one vector: the same formula on Python floats
        angle = math.sqrt(phi @ phi)
        k = math.sin(0.5 * angle) / angle if angle > 1e-8 else 0.5 - angle**2 / 48.0
        x, y, z = phi.tolist()
        return np.array([x * k, y * k, z * k, math.cos(0.5 * angle)])
    angle = np.linalg.norm(phi, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(half)/angle with its Taylor series near 0
    k = np.where(angle > 1e-8, np.sin(half) / np.where(angle > 1e-8, angle, 1.0), 0.5 - angle**2 / 48.0)
    return np.concatenate([phi * k, np.cos(half)], axis=-1)


def expm_so3(phi: np.ndarray) -> np.ndarray:
    """Rotation matrix ``exp(hat(phi))`` (Rodrigues): ``[NB]`` of the rotation vector ``phi``."""
    return dcm_NB(exp_map(phi))


def angle_between(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Rotation angle (rad, in [0, π]) taking attitude q1 to q2; sign-independent (two single
    quaternions: a float, on Python floats)."""
    q1, q2 = np.asarray(q1, float), np.asarray(q2, float)
    if q1.shape == (4,) and q2.shape == (4,):
        a, b = q1.tolist(), q2.tolist()
        norms = math.sqrt(sum(map(mul, a, a)) * sum(map(mul, b, b)))
        return 2.0 * math.acos(min(abs(sum(map(mul, a, b))) / norms, 1.0)) if norms > 0 else math.nan
    d = np.abs(np.sum(normalize(q1) * normalize(q2), axis=-1))
    return 2.0 * np.arccos(np.clip(d, -1.0, 1.0))


def error_vector(q_BN: np.ndarray, q_RN: np.ndarray) -> np.ndarray:
    """Vector part of the attitude error ``q_BR = q_RN* ⊗ q_BN`` of the body B relative to the
    reference R, sign chosen with w >= 0 (B axes)."""
    q, q_ref = np.asarray(q_BN, float), np.asarray(q_RN, float)
    if q.shape == (4,) and q_ref.shape == (4,):         # one pair: multiply's scalar formula, p = q_ref*
        (rx, ry, rz, pw), (qx, qy, qz, qw) = q_ref.tolist(), q.tolist()
        px, py, pz = -rx, -ry, -rz
        e = [pw * qx + qw * px + (py * qz - pz * qy), pw * qy + qw * py + (pz * qx - px * qz),
             pw * qz + qw * pz + (px * qy - py * qx)]
        return np.array([-c for c in e] if pw * qw - (px * qx + py * qy + pz * qz) < 0 else e)
    e = multiply(conjugate(q_ref), q)
    sign = np.where(e[..., 3:] < 0, -1.0, 1.0)
    return (e * sign)[..., :3]


def propagate_constant_rate(q_BN: np.ndarray, omega_BN_B: np.ndarray, dt: float) -> np.ndarray:
    """Exact attitude after ``dt`` at constant body rate: ``q_BN ⊗ exp(omega_BN_B dt)`` (rows of
    ``q_BN`` and ``omega_BN_B`` with a column of ``dt``: each row's)."""
    return multiply(q_BN, exp_map(np.asarray(omega_BN_B) * dt))


def log_map(q: np.ndarray) -> np.ndarray:
    """Rotation vector (axis × angle, angle in [0, π]) of a quaternion, or of each row: the inverse
    of :func:`exp_map` (rows: :func:`to_axis_angle`'s operations element by element, the same bits)."""
    q = np.asarray(q, float)
    if q.ndim == 1:
        (x, y, z), angle = _axis_angle(q)
        return np.array([x * angle, y * angle, z * angle])
    with np.errstate(invalid="ignore", divide="ignore"):
        x, y, z, w = q.T
        n = np.sqrt(x * x + y * y + z * z + w * w)
        sign = np.where(w / n < 0, -1.0, 1.0)
        x, y, z, w = x / n * sign, y / n * sign, z / n * sign, w / n * sign
        s = np.sqrt(x * x + y * y + z * z)
        angle = 2.0 * np.array([math.atan2(a, b) for a, b in zip(s.tolist(), w.tolist())])   # numpy's differs
        axis = np.where((s > 1e-15)[:, None], np.array([x / s, y / s, z / s]).T, np.array([1.0, 0.0, 0.0]))
    return axis * angle[:, None]


OFF_DIAGONAL = ((0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1))


def small_error_matrix(rng: np.random.Generator, scale_sigma: float, misalignment_sigma: float) -> np.ndarray:
    """``I + S + M``: scale factors on the diagonal, misalignment angles off it, drawn from their 1σ."""
    m = np.eye(3) + np.diag(rng.normal(0.0, scale_sigma, 3))
    for (i, j), angle in zip(OFF_DIAGONAL, rng.normal(0.0, misalignment_sigma, 6)):
        m[i, j] = angle
    return m
