"""An integration of torque profiles that uses nothing of the suite, for the independent checks
of the committed benchmark JSONs: its own RK4 of the rigid body (J ω̇ = T − ω × Jω,
q̇ = ½ q ⊗ [ω, 0]; Euler's equations, Wie, *Space Vehicle Dynamics and Control*, 2008, §5.2) on
Python floats, quaternions (x, y, z, w) body-to-inertial; the torque samples held (ZOH) or
interpolated linearly (at each RK4 stage's time)."""
from __future__ import annotations

import numpy as np


def dcm_NB(q_BN):
    """``[NB]``, the body-to-inertial matrices of unit quaternions q_BN (K, 4) = (x, y, z, w)."""
    x, y, z, w = np.moveaxis(np.asarray(q_BN, float), -1, 0)
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
                     np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
                     np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)], -2)


def integrate(J, t, torque, q0, substeps: int = 4, dense: bool = False, interpolation: str = "zoh"):
    """RK4 from rest at ``q0``, the torque of knot k held to knot k + 1 (switched exactly at the
    knots; ``interpolation='linear'``: interpolated to knot k + 1), ``substeps`` steps per interval;
    the states (x, y, z, w, ωx, ωy, ωz) at the knots ``t``, or with ``dense`` ``(times, states)`` after
    every step."""
    J = [list(map(float, row)) for row in J]
    Ji = np.linalg.inv(np.array(J)).tolist()

    def f(x, u):
        qx, qy, qz, qw, wx, wy, wz = x
        h = [J[i][0] * wx + J[i][1] * wy + J[i][2] * wz for i in range(3)]
        r = (u[0] - (wy * h[2] - wz * h[1]), u[1] - (wz * h[0] - wx * h[2]), u[2] - (wx * h[1] - wy * h[0]))
        return (0.5 * (qw * wx + qy * wz - qz * wy), 0.5 * (qw * wy + qz * wx - qx * wz),
                0.5 * (qw * wz + qx * wy - qy * wx), -0.5 * (qx * wx + qy * wy + qz * wz),
                *(Ji[i][0] * r[0] + Ji[i][1] * r[1] + Ji[i][2] * r[2] for i in range(3)))

    def axpy(x, a, k):
        return [xi + a * ki for xi, ki in zip(x, k)]

    x = [float(v) for v in q0] + [0.0, 0.0, 0.0]
    times, states = [float(t[0])], [list(x)]
    for k in range(len(t) - 1):
        h = (t[k + 1] - t[k]) / substeps
        a = [float(v) for v in torque[k]]
        b = [float(v) for v in torque[k + 1]] if interpolation == "linear" else a
        for j in range(substeps):
            u0, um, u1 = ([ai + (bi - ai) * (j + f) / substeps for ai, bi in zip(a, b)] for f in (0.0, 0.5, 1.0))
            k1 = f(x, u0)
            k2 = f(axpy(x, 0.5 * h, k1), um)
            k3 = f(axpy(x, 0.5 * h, k2), um)
            k4 = f(axpy(x, h, k3), u1)
            x = [xi + h / 6.0 * (a + 2 * b + 2 * c + d) for xi, a, b, c, d in zip(x, k1, k2, k3, k4)]
            n = sum(v * v for v in x[:4]) ** 0.5
            x[:4] = [v / n for v in x[:4]]
            if dense or j == substeps - 1:
                times.append(float(t[k]) + (j + 1) * h)
                states.append(list(x))
    return (np.array(times), np.array(states)) if dense else np.array(states)
