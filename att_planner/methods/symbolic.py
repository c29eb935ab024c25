"""Quaternion algebra for CasADi expressions (SX or MX), the symbolic twins of
:mod:`att_sim.models.rotations` used by the collocation and multiple-shooting transcriptions.
Quaternions ``[x, y, z, w]``, Hamilton product, body-to-inertial (the suite's convention)."""
from __future__ import annotations

import casadi as ca


def quat_mul(p, q):
    """Hamilton product ``p ⊗ q`` (scalar last)."""
    pv, pw, qv, qw = p[:3], p[3], q[:3], q[3]
    return ca.vertcat(pw * qv + qw * pv + ca.cross(pv, qv), pw * qw - ca.dot(pv, qv))


def error_vector(q_BN, q_RN):
    """Vector part of ``q_BR = q_RN* ⊗ q_BN``: zero iff q_BN = ±q_RN (unit quaternions); the argument
    order of :func:`att_sim.models.rotations.error_vector`, without its sign choice."""
    return q_RN[3] * q_BN[:3] - q_BN[3] * q_RN[:3] - ca.cross(q_RN[:3], q_BN[:3])


def dcm_NB(q_BN):
    """``[NB]``, the body-to-inertial matrix of the attitude ``q_BN`` (:func:`att_sim.models.rotations.dcm_NB`)."""
    x, y, z, w = q_BN[0], q_BN[1], q_BN[2], q_BN[3]
    return ca.vertcat(
        ca.horzcat(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        ca.horzcat(2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        ca.horzcat(2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))
