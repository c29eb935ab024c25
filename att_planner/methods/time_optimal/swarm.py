"""Melton's (2012) two-stage proposal, its first stage: a particle swarm over a Chebyshev torque
parametrisation, a fast global search whose best plan seeds the collocation.

Each particle is ``(c, t_f)``: per body axis the torque ``u_j(τ) = tanh(Σ_k c_jk T_k(2τ − 1))``
(Chebyshev polynomials ``T_k`` up to :data:`DEGREE`; tanh keeps ``|u_j| < 1`` and lets large
coefficients saturate into bang-bang arcs), held over :data:`STEPS` equal steps of the normalised
time (``τ = sqrt(J0/T̄)``, :mod:`.model`) and integrated from rest with RK4, every particle at once.
Cost (Melton's penalty form)::

    t_f + W_END (e_f + |ω̃(t_f)|) + W_ZONE Σ_k Σ_z v_kz Δt

``e_f`` the final attitude error (semi-free: the boresight's angle to its target), ``v_kz`` the
violation of zone z at step k (``−margin`` where negative; on a forced boundary arc ``|margin|``).
The swarm is the constricted PSO of Clerc & Kennedy (2002): inertia :data:`INERTIA`, both pulls
:data:`PULL`, global best topology, velocities clamped to a fifth of the box.
"""
from __future__ import annotations

import time

import numpy as np

from att_msgs_py.types import Plan
from att_planner.methods.time_optimal.model import Scaling
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot

DEGREE = 4            # Chebyshev polynomials T_0 … T_DEGREE per axis
STEPS = 48            # ZOH torque steps (RK4, one per step)
COEFFICIENT = 4.0     # box of each coefficient: [−COEFFICIENT, COEFFICIENT]
INERTIA, PULL = 0.7298, 1.49618      # Clerc & Kennedy's constriction
W_END, W_ZONE = 10.0, 10.0


def _dynamics(x: np.ndarray, u: np.ndarray, Jn: np.ndarray, Jn_inv: np.ndarray) -> np.ndarray:
    """Normalised rigid body ``ẋ`` for states (P, 7) and torques (P, 3) (:func:`.model.rigid_body_dynamics`)."""
    q, w = x[:, :4], x[:, 4:]
    qx, qy, qz, qw = q.T
    wx, wy, wz = w.T
    q_dot = 0.5 * np.stack([qw * wx + qy * wz - qz * wy, qw * wy + qz * wx - qx * wz,
                            qw * wz + qx * wy - qy * wx, -(qx * wx + qy * wy + qz * wz)], axis=1)
    w_dot = (u - np.cross(w, w @ Jn.T)) @ Jn_inv.T
    return np.concatenate([q_dot, w_dot], axis=1)


def _torques(coefficients: np.ndarray) -> np.ndarray:
    """``(P, STEPS, 3)`` torques of particles' coefficients ``(P, 3, DEGREE + 1)`` at the step midpoints."""
    mid = (np.arange(STEPS) + 0.5) / STEPS
    basis = np.polynomial.chebyshev.chebvander(2 * mid - 1, DEGREE)          # (STEPS, DEGREE + 1)
    return np.tanh(np.einsum("pjk,sk->psj", coefficients, basis))


def rollout(problem: ManeuverProblem, s: Scaling, coefficients: np.ndarray, tf: np.ndarray) -> np.ndarray:
    """States ``(P, STEPS + 1, 7)`` of particles (normalised units) from rest at ``q_initial``."""
    u = _torques(coefficients)
    Jn_inv = np.linalg.inv(s.Jn)
    P = len(tf)
    x = np.tile(np.concatenate([rot.normalize(np.asarray(problem.q_initial, float)), np.zeros(3)]), (P, 1))
    h = (tf / STEPS)[:, None]
    out = [x]
    for k in range(STEPS):
        uk = u[:, k]
        k1 = _dynamics(x, uk, s.Jn, Jn_inv)
        k2 = _dynamics(x + 0.5 * h * k1, uk, s.Jn, Jn_inv)
        k3 = _dynamics(x + 0.5 * h * k2, uk, s.Jn, Jn_inv)
        k4 = _dynamics(x + h * k3, uk, s.Jn, Jn_inv)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        x[:, :4] /= np.linalg.norm(x[:, :4], axis=1, keepdims=True)
        out.append(x)
    return np.stack(out, axis=1)


def cost(problem: ManeuverProblem, s: Scaling, coefficients: np.ndarray, tf: np.ndarray) -> np.ndarray:
    """The penalised cost (module docstring) of every particle, (P,)."""
    x = rollout(problem, s, coefficients, tf)
    P = len(tf)
    q_end = x[:, -1, :4]
    if problem.sensor_target is None:
        error = rot.angle_between(q_end, rot.normalize(np.asarray(problem.q_final, float)))
    else:
        r = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
        target = np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
        error = np.arccos(np.clip(rot.dcm_NB(q_end) @ r @ target, -1.0, 1.0))
    end = error + np.linalg.norm(x[:, -1, 4:], axis=1)
    zones = problem.zone_sky()
    violation = np.zeros(P)
    if zones.zones:
        t = np.minimum(tf[:, None] * np.linspace(0.0, 1.0, STEPS + 1) * s.tu, zones.window)
        m = zones.margins(t.ravel(), x[:, :, :4].reshape(-1, 4)).reshape(P, STEPS + 1, -1)
        v = np.maximum(-m, 0.0)
        if problem.boundary_cone is not None:
            v[:, :, problem.boundary_cone] = np.abs(m[:, :, problem.boundary_cone])
        violation = v.sum(axis=(1, 2)) * tf / STEPS
    return tf + W_END * end + W_ZONE * violation


def swarm_plan(problem: ManeuverProblem, s: Scaling, tf_guess: float, particles: int = 40, iterations: int = 60,
               seed: int = 0) -> Plan:
    """The swarm's best particle as a plan (SI units, ZOH), ``nit`` its iterations; ``tf_guess``
    (TU) centres the box of t_f, ``[0.4, 1.6] tf_guess``. Stops early at ``problem.deadline``."""
    start = time.monotonic()
    rng = np.random.default_rng(seed)
    n = 3 * (DEGREE + 1)
    low = np.concatenate([np.full(n, -COEFFICIENT), [0.4 * tf_guess]])
    high = np.concatenate([np.full(n, COEFFICIENT), [1.6 * tf_guess]])
    clamp = 0.2 * (high - low)

    def evaluate(z):
        return cost(problem, s, z[:, :n].reshape(-1, 3, DEGREE + 1), z[:, n])

    z = rng.uniform(low, high, (particles, n + 1))
    v = rng.uniform(-clamp, clamp, z.shape)
    f = evaluate(z)
    best_z, best_f = z.copy(), f.copy()
    g = int(np.argmin(best_f))
    history = [float(best_f[g])]
    for _ in range(iterations):
        if problem.time_left() <= 0:
            break
        r1, r2 = rng.random(z.shape), rng.random(z.shape)
        v = np.clip(INERTIA * v + PULL * r1 * (best_z - z) + PULL * r2 * (best_z[g] - z), -clamp, clamp)
        z = np.clip(z + v, low, high)
        f = evaluate(z)
        better = f < best_f
        best_z[better], best_f[better] = z[better], f[better]
        g = int(np.argmin(best_f))
        history.append(float(best_f[g]))
    coefficients, tf = best_z[g, :n].reshape(1, 3, DEGREE + 1), best_z[g, n:]
    x = rollout(problem, s, coefficients, tf)[0]
    torque = np.vstack([_torques(coefficients)[0], np.zeros((1, 3))]) * s.torque_max
    return Plan(t=np.linspace(0.0, tf[0], STEPS + 1) * s.tu, torque=torque, q=rot.normalize(x[:, :4]),
                omega=x[:, 4:] / s.tu, method="swarm", nit=len(history) - 1, nfev=particles * len(history),
                wall_time=time.monotonic() - start,
                stats={"cost": float(best_f[g]), "tf": float(tf[0] * s.tu), "history": history})
