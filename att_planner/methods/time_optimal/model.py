"""The time-optimal slew as a collocation NLP (see :mod:`.planner` for the problem statement):
normalisation, the CasADi rigid-body model, path constraints and the Hermite–Simpson transcription."""
from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from att_planner.methods import symbolic
from att_planner.methods.axis_rotations import time_unit
from att_planner.methods.time_optimal import collocation as col
from att_planner.problem import ManeuverProblem
from att_sim import rotations as rot

# Relative tightening of the rate and wheel-momentum bounds at the collocation points, so that
# the truth trajectory between them stays within the bound itself.
BOUND_MARGIN = 2e-3


@dataclass
class Scaling:
    tu: float            # s per time unit
    J0: float            # kg m²
    Jn: np.ndarray       # J / J0
    torque_max: float    # N m


def scaling(problem: ManeuverProblem) -> Scaling:
    J = problem.spacecraft.inertia
    J0 = float(np.linalg.eigvalsh(J).max())
    return Scaling(time_unit(problem), J0, J / J0, float(problem.spacecraft.body_torque_max))


def rigid_body_dynamics(Jn: np.ndarray) -> ca.Function:
    """Normalised ``ẋ = f(x, u)`` with ``x = [q (xyzw), ω̃]`` (:mod:`.planner` docstring)."""
    x, u = ca.SX.sym("x", 7), ca.SX.sym("u", 3)
    q, w = x[:4], x[4:]
    Jn_dm = ca.DM(Jn)
    q_dot = 0.5 * symbolic.quat_mul(q, ca.vertcat(w, 0)) + 0.5 * (1 - ca.dot(q, q)) * q
    w_dot = ca.solve(Jn_dm, u - ca.cross(w, ca.mtimes(Jn_dm, w)))
    return ca.Function("rigid_body", [x, u], [ca.vertcat(q_dot, w_dot)])


def path_function(problem: ManeuverProblem, s: Scaling, cone_margin: float, n_state: int = 7):
    """Path constraints ``g ≤ 0`` (zones, wheel momentum) or None when there are none; ``x`` has
    ``n_state`` rows, the attitude and rate first.

    Every zone of ``problem.zone_sky()`` (:mod:`att_planner.zones`: the cones, then the zones, each
    with its own sensor axis ``s_z``, ``b_z = R(q) s_z``) is tightened by ``cone_margin``: keep-out
    ``a_z · b_z ≤ cos(θ_z + δ)``, keep-in ``a_z · b_z ≥ cos(θ_z − δ)``. When a zone moves, the
    function is ``(x, u, t) -> g`` with ``t`` the normalised time from the start: ``a_z(t τ_u)``
    and ``θ_z(t τ_u)`` are the ZoneSky's Chebyshev series of that CasADi expression, so the
    collocation couples them exactly to ``t_f``. Without motion it is ``(x, u) -> g`` with the
    zones constant (no time dependence is built)."""
    x, u, t = ca.SX.sym("x", n_state), ca.SX.sym("u", 3), ca.SX.sym("t")
    zones = problem.zone_sky()
    g = zones.casadi_constraints(t * s.tu if zones.moving else 0.0, symbolic.dcm(x[:4]), cone_margin)
    if math.isfinite(problem.wheel_momentum_max) and problem.spacecraft.n_wheels:   # no wheels: no momentum
        h_per_rate = s.J0 / s.tu / (problem.wheel_momentum_max * (1 - BOUND_MARGIN))
        h_w = ca.mtimes(ca.DM(problem.spacecraft.wheel_axes_pinv @ s.Jn * h_per_rate), x[4:7])
        g += [h_w - 1, -h_w - 1]
    if not g:
        return None
    if zones.moving:
        return ca.Function("path", [x, u, t], [ca.vertcat(*g)])
    return ca.Function("path", [x, u], [ca.vertcat(*g)])


def transcription(problem: ManeuverProblem, s: Scaling, mesh: np.ndarray, control: str, cone_margin: float,
                  tf_bounds: tuple[float, float]) -> col.Transcription:
    """The minimum-time NLP on ``mesh`` (``control``: 'constant' for ZOH torques, 'linear')."""
    rate_bound = problem.rate_max * s.tu * (1 - BOUND_MARGIN)
    phase = col.Phase(rigid_body_dynamics(s.Jn), mesh, control=control,
                      state_bounds=([-1.1] * 4 + [-rate_bound] * 3, [1.1] * 4 + [rate_bound] * 3),
                      control_bounds=(-1.0, 1.0), duration_bounds=tf_bounds,
                      path=path_function(problem, s, cone_margin), path_bounds=(-np.inf, 0.0), name="slew")
    tr = col.Transcription([phase], duration_copies=True)
    v = tr.variables(0)
    q0 = rot.normalize(np.asarray(problem.q_initial, float))
    tr.bound_state(0, 0, np.concatenate([q0, np.zeros(3)]))
    tr.bound_state(0, -1, [-1.1] * 4 + [0.0] * 3, [1.1] * 4 + [0.0] * 3)
    q_end = v.x_end[:4]
    if problem.sensor_target is None:
        qf = rot.normalize(np.asarray(problem.q_final, float))
        tr.add_constraint(symbolic.error_vector(q_end, ca.DM(qf)), 0.0, 0.0)
    else:
        target = np.asarray(problem.sensor_target, float) / np.linalg.norm(problem.sensor_target)
        r = np.asarray(problem.sensor_axis, float) / np.linalg.norm(problem.sensor_axis)
        b = ca.mtimes(symbolic.dcm(q_end), ca.DM(r))
        tr.add_constraint(ca.mtimes(ca.DM(np.stack(rot.orthonormal_basis(target))), b), 0.0, 0.0)
        tr.add_constraint(ca.dot(ca.DM(target), b), 0.0, np.inf)
    tr.minimize(v.duration)
    return tr


def plan_arrays(sol: col.PhaseSolution, s: Scaling):
    """SI arrays ``(t, torque, q, omega)`` of a normalised solution."""
    t = sol.t * s.tu
    torque = np.clip(sol.control_samples() * s.torque_max, -s.torque_max, s.torque_max)
    q = rot.normalize(sol.x[:, :4])
    omega = sol.x[:, 4:] / s.tu
    return t, torque, q, omega
