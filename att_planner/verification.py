"""The one verification of a plan: predict its trajectory with the prediction model and measure it
against its problem, with one named set of tolerances (:data:`TOLERANCES`).

The prediction model (:func:`prediction_model`) is the problem's nominal spacecraft flown through
the shared rigid-body and wheel equations of :mod:`att_sim.models.dynamics`: no dispersions, no
disturbances, no sensor or actuator errors (those belong to the truth simulation, which the flight
side never sees). Every plan the planner returns carries these figures, and the methods and the
benchmarks judge plans by them; nothing is taken from a planner's own transcription. The
prediction is :func:`att_sim.models.dynamics.simulate_profile` (RK4 with inputs switched exactly at
the knots for zero-order hold, :data:`VERIFY_STEPS` steps over the plan at least), from the
problem's initial attitude at rest with the wheels stopped. Checked: the final attitude (semi-free: the boresight
on its target; a moving goal: its attitude at the final time, from the goal's law itself — a ground
site's line of sight at that time, :mod:`att_planner.guidance.ground_arrival`) and rate (a moving
goal: relative to its rate, turned into body axes), a moving goal's within the tighter arrival
tolerances, every passage of a schedule (attitude, rate about body z), every zone
(the cones, then the zones: :meth:`ManeuverProblem.zone_sky`) at every dense sample at its TRUE
position at that sample's time (straight from the sky, not the planners' fit, at any time), and the
control, wheel-speed (relative to the body), body-rate and wheel-momentum limits.

Zones are judged by their *clearance* above the floor a sample may reach (:func:`clearances`): the
margin, plus :data:`~att_planner.cones.BOUNDARY_TOLERANCE` where the boresight is within
:data:`~att_planner.cones.END_RADIUS` of the path's own start or final boresight (an end may lie on
a boundary, within the tolerance); for a forced boundary arc's cone
:data:`~att_planner.cones.ARC_TOLERANCE` − |margin| (the boresight stays on the boundary). The
reported ``cone_margins`` are these clearances; a plan passes when every one is ≥ 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import ControlKind, Interpolation, Plan, Verification
from att_planner.cones import ARC_TOLERANCE, BOUNDARY_TOLERANCE, END_RADIUS
from att_planner.problem import ManeuverProblem
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot

VERIFY_STEPS = 2000         # RK4 steps over the plan (at least one per control interval)


def prediction_model(problem: ManeuverProblem) -> dyn.Spacecraft:
    """The spacecraft a plan is predicted with: the problem's nominal one (module docstring)."""
    return problem.spacecraft


@dataclass(frozen=True)
class Tolerances:
    """Acceptance of a plan's predicted trajectory."""

    attitude: float = math.radians(0.5)    # rad: final (semi-free: boresight) and passage attitude error
    rate: float = 1e-3                     # rad/s: final ‖ω‖, |ω_z| at each passage, ‖ω‖ through an observation
    arrival_attitude: float = math.radians(0.05)   # rad: final attitude error to a moving goal (tracking takes over)
    arrival_rate: float = math.radians(0.01)       # rad/s: final rate error to a moving goal
    cone_penetration: float = 0.0          # rad a dense sample may lie below its clearance floor (clearances)
    limit_ratio: float = 1.0 + 1e-6        # control, wheel speed, body rate, wheel momentum / their limits


TOLERANCES = Tolerances()


def predict(problem: ManeuverProblem, plan: Plan, steps: int = VERIFY_STEPS) -> dyn.Trajectory:
    """The trajectory the prediction model flies under the plan's controls from the problem's start at
    rest: a wheel-torque plan from the problem's wheel speeds, a body-torque plan with the wheels
    stopped (the rigid body it was planned for; :func:`wheel_speeds_along` gives the wheels that
    produce its torque)."""
    sc = prediction_model(problem)
    wheels = plan.control_kind == ControlKind.WHEEL_TORQUE and problem.wheel_speeds is not None
    x0 = dyn.initial_state(sc, problem.q_initial, wheel_speed=problem.wheel_speeds if wheels else None)
    return dyn.simulate_profile(sc, x0, plan.t, plan.torque, kind=str(plan.control_kind),
                                interpolation=str(plan.interpolation),
                                max_step=max(plan.duration, 1e-9) / steps)


def clearances(problem: ManeuverProblem, t: np.ndarray, q: np.ndarray, true: bool = True) -> np.ndarray:
    """Clearance (rad, ≥ 0: acceptable) of every zone at attitudes ``q`` (K, 4) of a path at times
    ``t`` (K,), (K, Z): the margin at the zone's true position (``true=False``: the planners' fit), +
    BOUNDARY_TOLERANCE within END_RADIUS of the path's first or last boresight of the zone's sensor;
    ARC_TOLERANCE − |margin| for the forced boundary arc's cone."""
    zone_sky = problem.zone_sky()
    m = zone_sky.margins(t, q, true=true)
    if not m.size:
        return m
    R = rot.dcm_NB(np.asarray(q, float).reshape(-1, 4))
    near = np.zeros(m.shape, bool)
    for s in np.unique(zone_sky.sensor_axes, axis=0):              # once per sensor
        b = R @ (s / np.linalg.norm(s))
        close = np.maximum(b @ b[0], b @ b[-1]) >= math.cos(END_RADIUS)
        near[:, np.all(zone_sky.sensor_axes == s, axis=1)] = close[:, None]
    out = m + BOUNDARY_TOLERANCE * near
    if problem.boundary_cone is not None:
        out[:, problem.boundary_cone] = ARC_TOLERANCE - np.abs(m[:, problem.boundary_cone])
    return out


def measure(problem: ManeuverProblem, plan: Plan, traj: dyn.Trajectory) -> Verification:
    """The verification figures of ``plan`` from its predicted trajectory ``traj``."""
    sc = prediction_model(problem)
    wheels = plan.control_kind == ControlKind.WHEEL_TORQUE
    controls = np.asarray(plan.torque, float).reshape(len(plan.t), -1)
    applied = controls[:-1] if plan.interpolation == Interpolation.ZOH and len(controls) > 1 else controls
    limit = sc.wheel_torque_max if wheels else sc.body_torque_max
    zone_sky = problem.zone_sky()
    m = clearances(problem, traj.t, traj.q_BN)
    final_rate = float(np.linalg.norm(traj.omega_BN_B[-1]))
    if problem.goal_motion is not None:            # the moving goal where and as fast as it is at t_f
        q_goal, omega_goal = problem.goal_motion(float(traj.t[-1]))
        final_error = float(rot.angle_between(traj.q_BN[-1], q_goal))
        omega_goal_B = rot.dcm_BN(traj.q_BN[-1]) @ rot.dcm_NB(q_goal) @ np.asarray(omega_goal, float)
        final_rate = float(np.linalg.norm(traj.omega_BN_B[-1] - omega_goal_B))
    elif problem.sensor_target is None:
        final_error = float(rot.angle_between(traj.q_BN[-1], problem.q_final))
    else:
        reached = rot.dcm_NB(traj.q_BN[-1]) @ np.asarray(problem.sensor_axis, float)
        target = np.asarray(problem.sensor_target, float)
        final_error = float(np.arccos(np.clip(reached @ target / np.linalg.norm(target), -1.0, 1.0)))
    passage_errors, passage_rates = [], []
    for passage in plan.passages:      # an observation: the worst sample of its dwell, at rest
        k = int(np.argmin(np.abs(traj.t - passage.time)))
        held = np.flatnonzero((traj.t >= traj.t[k]) & (traj.t <= passage.time + passage.dwell)) \
            if passage.dwell > 0 else np.array([k])
        passage_errors.append(float(max(rot.angle_between(traj.q_BN[i], passage.attitude) for i in held)))
        rates = np.linalg.norm(traj.omega_BN_B[held], axis=1) if passage.dwell > 0 else np.abs(traj.omega_BN_B[held, 2])
        passage_rates.append(float(rates.max()))
    return Verification(
        final_attitude_error=final_error,
        final_rate=final_rate,
        min_cone_margin=float(m.min()) if m.size else math.inf,
        cone_margins=[float(v) for v in m.min(axis=0)] if m.size else [],
        torque_ratio=_ratio(peak_magnitude(applied), limit),
        wheel_speed_ratio=_ratio(peak_magnitude(wheel_speeds_along(problem, plan, traj)), sc.wheel_speed_max),
        rate_max=float(np.linalg.norm(traj.omega_BN_B, axis=1).max()),
        dense_samples=len(traj.t),
        duration=plan.duration,
        body_rate_ratio=_ratio(peak_magnitude(traj.omega_BN_B), problem.rate_max),
        wheel_momentum_ratio=_ratio(peak_magnitude(_wheel_momentum(sc, traj, wheels)), problem.wheel_momentum_max),
        passage_attitude_errors=passage_errors,
        passage_rates_z=passage_rates,
        zone_names=list(zone_sky.names),
        zone_keep_in=[bool(k) for k in zone_sky.keep_in],
        boundary_arc="" if problem.boundary_cone is None else zone_sky.names[problem.boundary_cone],
        goal="" if problem.goal_motion is None else problem.goal_motion.kind or "moving",
    )


def verify(problem: ManeuverProblem, plan: Plan, steps: int = VERIFY_STEPS) -> Verification:
    """Predict the plan's trajectory with the prediction model and measure it against its problem."""
    return measure(problem, plan, predict(problem, plan, steps))


def rejection(ver: Verification, tol: Tolerances = TOLERANCES) -> str | None:
    """Why a verified plan is not acceptable, or None (a figure that is NaN is never acceptable). The
    arrival on a moving goal (``ver.goal``) is held to the arrival tolerances: tracking takes over there."""
    attitude, rate = (tol.arrival_attitude, tol.arrival_rate) if ver.goal else (tol.attitude, tol.rate)
    if not ver.final_attitude_error <= attitude:
        return (f"final attitude error {math.degrees(ver.final_attitude_error):.3f} deg > "
                f"{math.degrees(attitude):.3f} deg" + (f" (arrival on the moving {ver.goal} goal)" if ver.goal else ""))
    if not ver.final_rate <= rate:
        return (f"final rate {ver.final_rate:.3g} rad/s > {rate:.3g} rad/s"
                + (f" (relative to the moving {ver.goal} goal)" if ver.goal else ""))
    if not ver.min_cone_margin >= -tol.cone_penetration:
        return _zone_violation(ver)
    for name in ("torque_ratio", "wheel_speed_ratio", "body_rate_ratio", "wheel_momentum_ratio"):
        if not getattr(ver, name) <= tol.limit_ratio:
            return f"{name.replace('_ratio', '').replace('_', ' ')} {getattr(ver, name):.6f} x the limit"
    for k, (err, rate) in enumerate(zip(ver.passage_attitude_errors, ver.passage_rates_z)):
        if not (err <= tol.attitude and rate <= tol.rate):
            return (f"passage {k} missed: attitude error {math.degrees(err):.3f} deg, "
                    f"|w_z| {rate:.3g} rad/s")
    return None


def _zone_violation(ver: Verification) -> str:
    """Which zone the plan violates and by how much (the deepest one)."""
    depth = math.degrees(-ver.min_cone_margin)
    if not ver.zone_names or len(ver.zone_names) != len(ver.cone_margins):
        return f"enters a keep-out cone by {depth:.3f} deg"
    k = int(np.argmin(np.nan_to_num(ver.cone_margins, nan=-np.inf)))
    if ver.boundary_arc and ver.zone_names[k] == ver.boundary_arc:
        return (f"leaves the boundary of cone {ver.boundary_arc} by {math.degrees(ARC_TOLERANCE) + depth:.5f} deg "
                f"(more than the boundary arc's {ARC_TOLERANCE:g} rad)")
    if k < len(ver.zone_keep_in) and ver.zone_keep_in[k]:
        return f"leaves keep-in zone {ver.zone_names[k]} by {depth:.3f} deg"
    return f"enters keep-out zone {ver.zone_names[k]} by {depth:.3f} deg"


def peak_magnitude(values: np.ndarray) -> float:
    """Largest ``|value|`` of an array, 0 when it is empty."""
    return float(np.abs(values).max()) if np.size(values) else 0.0


def _ratio(peak: float, limit: float) -> float:
    return float(peak / limit) if math.isfinite(limit) and limit > 0 else 0.0


def _wheel_momentum(sc: dyn.Spacecraft, traj: dyn.Trajectory, wheels: bool) -> np.ndarray:
    """Per-wheel momentum (N m s) along the trajectory: ``I_w Ω`` for a wheel-torque plan, else the
    momentum ``G⁺ J ω`` the wheels would hold producing the body torque with zero total momentum."""
    if wheels:
        return sc.wheel_inertia * traj.wheel_speed
    return traj.omega_BN_B @ (sc.wheel_axes_pinv @ sc.inertia).T


def wheel_speeds_along(problem: ManeuverProblem, plan: Plan, traj: dyn.Trajectory) -> np.ndarray:
    """The wheels' speeds relative to the body along the trajectory, ``Ω − Gᵀω`` (K, N): the speed the
    wheel limit of the dynamics applies to (:func:`att_sim.models.dynamics.relative_wheel_speed`). A wheel-torque plan
    predicts its wheels; a body-torque plan's are :func:`body_plan_wheel_speeds` (the two parts summed)."""
    sc = prediction_model(problem)
    if plan.control_kind == ControlKind.WHEEL_TORQUE:
        return traj.wheel_speed - traj.omega_BN_B @ sc.wheel_axes
    stored, slew = body_plan_wheel_speeds(problem, traj.q_BN, traj.omega_BN_B)
    return stored + slew


def body_plan_wheel_speeds(problem: ManeuverProblem, q: np.ndarray, omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The relative speeds (K, N) of the wheels that fly a body-torque plan through attitudes ``q``
    and rates ``omega``, in two parts: (stored, slew).

    The wheels exchange momentum with the body, and the total ``H_N = R (J ω + G I_w Ω)`` is
    conserved: from the start at rest with speeds ``Ω₀`` (the problem's ``wheel_speeds``, else
    stopped) the wheels hold ``I_w Ω = I_w Ω₀ + G⁺ (Rᵀ H_N − J ω − G I_w Ω₀)`` (the change shared by
    the pseudo-inverse, as the controller distributes a torque; a null-space spin stays). *stored*:
    ``Ω₀ + G⁺ (Rᵀ H_N − G I_w Ω₀) / I_w``, what the stored momentum becomes as the body turns;
    *slew*: ``−G⁺ J ω / I_w − Gᵀ ω``, the slew's own share (∝ ω)."""
    sc = prediction_model(problem)
    zeros = np.zeros((len(q), sc.n_wheels))
    if not (sc.n_wheels and sc.wheel_inertia > 0):
        return zeros, zeros.copy()
    speeds0 = np.zeros(sc.n_wheels) if problem.wheel_speeds is None else np.asarray(problem.wheel_speeds, float)
    h0_B = sc.wheel_axes @ (sc.wheel_inertia * speeds0)
    H_N = rot.dcm_NB(q[0]) @ h0_B
    h_B = np.einsum("kji,j->ki", rot.dcm_NB(q), H_N)                          # R_kᵀ H_N
    stored = speeds0 + (h_B - h0_B) @ sc.wheel_axes_pinv.T / sc.wheel_inertia
    slew = -omega @ (sc.wheel_axes_pinv @ sc.inertia).T / sc.wheel_inertia - omega @ sc.wheel_axes
    return stored, slew
