"""Track-to-track slews: from tracking one ground site to tracking the next, in closed form, verified.

An imaging day chains ~190 slews per orbit, each from the state of tracking site k (its pointing
law's attitude and body rate ``(q_0, ω_0)`` at the slew's start ``t_0``) to the state of tracking
site k + 1 at the arrival ``t_0 + T`` (``(q_1, ω_1)``, the law at that time, the site's true motion).
The NLP methods take seconds for one; this construction takes a few milliseconds.

**The path.** The attitude is a curve in the tangent space at the start,
``q(t) = q_0 ⊗ exp(r(t))``, with ``r`` the quintic Hermite polynomial of σ = t/T with

``r(0) = 0``, ``ṙ(0) = ω_0``, ``r̈(0) = 0``, ``r(T) = log(q_0* ⊗ q_1)``, ``ṙ(T) = J_r(r(T))⁻¹ ω_1``,
``r̈(T) = 0``,

``J_r`` the right Jacobian of SO(3) (the body rate of ``q_0 ⊗ exp(r)`` is ``ω = J_r(r) ṙ``;
Solà, Deray & Atchuthan, *A micro Lie theory for state estimation in robotics*, 2018, eq. 143–146):

``J_r(r) = I − (1 − cos θ)/θ² [r×] + (θ − sin θ)/θ³ [r×]²``,
``J_r⁻¹(r) = I + ½ [r×] + (1/θ² − (1 + cos θ)/(2 θ sin θ)) [r×]²``, θ = |r|.

So the slew starts exactly on the tracking state and ends exactly on the next site's attitude and
rate whatever T. Its rate derivative ``ω̇ = J_r r̈ + (d/dt J_r) ṙ`` (the second term a central
difference of ``J_r`` along ``ṙ``, :data:`JACOBIAN_STEP`) gives the body torque of the rigid body,
``τ = J ω̇ + ω × J ω``, fed forward at the knots (linear between them).

**The duration.** T is the shortest, to :data:`DURATION_TOLERANCE`, whose knots keep the per-axis
torque, the per-axis body rate and the wheels' momentum ``G⁺ J ω`` within their bounds less
:data:`BOUND_MARGIN` (room for the feedback): doubling from the rest-to-rest eigenaxis time
(:func:`att_planner.problem.rest_to_rest_time`), then bisection, on :data:`SEARCH_KNOTS` knots; the
plan itself has :data:`PLAN_KNOTS`.

**The verification** (:func:`verify`) is the suite's: the torque integrated through the shared rigid
body of :func:`att_sim.models.dynamics.simulate_profile` from the tracking state (RK4, the knots'
linear torque), the arrival measured against the next site's law itself at the arrival time, held to
the moving-goal tolerances (:data:`att_planner.verification.TOLERANCES`: 0.05°, 0.01°/s), every zone
at every integration step at its TRUE position (:meth:`att_planner.zones.FittedZones.margins` with
``true``), and the torque, rate and momentum limits.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import Interpolation, Plan, Status
from att_planner.problem import rest_to_rest_time
from att_planner.verification import TOLERANCES
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot

METHOD = "track_to_track"
SEARCH_KNOTS = 41            # knots on which the duration search checks the bounds
PLAN_KNOTS = 201             # knots of a plan (linear torque between them)
DURATION_TOLERANCE = 0.01    # relative: the bisection on T stops within this
BOUND_MARGIN = 0.03          # relative room kept below the torque, rate and momentum bounds
JACOBIAN_STEP = 1e-4         # s: the central difference of J_r along the path
MAX_DURATION_S = 600.0       # s: the longest slew searched
VERIFY_STEP_S = 0.05         # s: the verification's largest RK4 step
_SMALL = 1e-6                # rad: below it the Jacobians take their series

# quintic Hermite basis on σ in [0, 1] (coefficients of σ^0..σ^5): p0, T v0, p1, T v1 (end accelerations 0)
_BASIS = np.array([[1.0, 0.0, 0.0, -10.0, 15.0, -6.0],
                   [0.0, 1.0, 0.0, -6.0, 8.0, -3.0],
                   [0.0, 0.0, 0.0, 10.0, -15.0, 6.0],
                   [0.0, 0.0, 0.0, -4.0, 7.0, -3.0]])


def _hat(r: np.ndarray) -> np.ndarray:
    """Skew matrices of rows of vectors, (K, 3, 3)."""
    z = np.zeros(len(r))
    return np.stack([np.stack([z, -r[:, 2], r[:, 1]], -1), np.stack([r[:, 2], z, -r[:, 0]], -1),
                     np.stack([-r[:, 1], r[:, 0], z], -1)], 1)


def right_jacobian(r) -> np.ndarray:
    """``J_r(r)`` of SO(3) for rows of rotation vectors ``r`` (K, 3): (K, 3, 3) (module docstring)."""
    r = np.atleast_2d(np.asarray(r, float))
    th = np.linalg.norm(r, axis=1)
    small = th < _SMALL
    ths = np.where(small, 1.0, th)
    a = np.where(small, 0.5 - th**2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    b = np.where(small, 1.0 / 6.0 - th**2 / 120.0, (ths - np.sin(ths)) / ths**3)
    H = _hat(r)
    return np.eye(3) - a[:, None, None] * H + b[:, None, None] * (H @ H)


def right_jacobian_inverse(r) -> np.ndarray:
    """``J_r(r)⁻¹`` of SO(3), θ = |r| < π, for rows ``r`` (K, 3): (K, 3, 3) (module docstring)."""
    r = np.atleast_2d(np.asarray(r, float))
    th = np.linalg.norm(r, axis=1)
    small = th < _SMALL
    ths = np.where(small, 1.0, th)
    c = np.where(small, 1.0 / 12.0 + th**2 / 720.0, 1.0 / ths**2 - (1.0 + np.cos(ths)) / (2.0 * ths * np.sin(ths)))
    H = _hat(r)
    return np.eye(3) + 0.5 * H + c[:, None, None] * (H @ H)


@dataclass(frozen=True)
class Limits:
    """The bounds a slew keeps: ``inertia_kg_m2`` (3, 3), ``torque_max_Nm`` and ``rate_max_rad_s`` per
    body axis, ``momentum_max_Nms`` per wheel with ``wheel_axes_pinv`` (N, 3) (G⁺)."""

    inertia_kg_m2: np.ndarray
    torque_max_Nm: float
    rate_max_rad_s: float
    momentum_max_Nms: float
    wheel_axes_pinv: np.ndarray

    @classmethod
    def of(cls, spacecraft: dyn.Spacecraft, rate_max_rad_s: float, momentum_max_Nms: float) -> Limits:
        return cls(np.asarray(spacecraft.inertia, float), float(spacecraft.body_torque_max), float(rate_max_rad_s),
                   float(momentum_max_Nms), np.asarray(spacecraft.wheel_axes_pinv, float))

    def ratio(self, omega: np.ndarray, torque: np.ndarray) -> float:
        """The largest ratio of the torque, rate and wheel momentum at the knots to their bounds."""
        ratios = [np.abs(torque).max() / self.torque_max_Nm]
        if math.isfinite(self.rate_max_rad_s):
            ratios.append(np.abs(omega).max() / self.rate_max_rad_s)
        if math.isfinite(self.momentum_max_Nms) and self.wheel_axes_pinv.size:
            h = omega @ (self.wheel_axes_pinv @ self.inertia_kg_m2).T
            ratios.append(np.abs(h).max() / self.momentum_max_Nms)
        return float(max(ratios))


def profile(q0, omega0, q1, omega1, duration: float, inertia, knots: int = PLAN_KNOTS):
    """The path (module docstring) from ``(q0, omega0)`` to ``(q1, omega1)`` in ``duration`` s.

    Returns
    -------
    t, q, omega, torque : ndarray
        Times from the start (s), attitudes [x, y, z, w] (body to inertial), body rates (rad/s) and
        body torques (N m), one row per knot.
    """
    T = float(duration)
    q0 = rot.normalize(np.asarray(q0, float))
    r1 = rot.log_map(rot.multiply(rot.conjugate(q0), rot.normalize(np.asarray(q1, float))))
    v1 = right_jacobian_inverse(r1)[0] @ np.asarray(omega1, float)
    ends = np.stack([np.zeros(3), T * np.asarray(omega0, float), r1, T * v1])      # (4, 3)
    coefficients = _BASIS.T @ ends                                                  # (6, 3): σ^k
    sigma = np.linspace(0.0, 1.0, knots)
    powers = sigma[:, None] ** np.arange(6)
    d1 = np.arange(6)[1:, None] * coefficients[1:]
    d2 = (np.arange(6) * np.arange(-1, 5))[2:, None] * coefficients[2:]
    r = powers @ coefficients
    r_dot = powers[:, :5] @ d1 / T
    r_ddot = powers[:, :4] @ d2 / T**2
    Jr = right_jacobian(r)
    omega = np.einsum("kij,kj->ki", Jr, r_dot)
    step = JACOBIAN_STEP * r_dot
    Jr_dot = (right_jacobian(r + step) - right_jacobian(r - step)) / (2 * JACOBIAN_STEP)
    omega_dot = np.einsum("kij,kj->ki", Jr, r_ddot) + np.einsum("kij,kj->ki", Jr_dot, r_dot)
    J = np.asarray(inertia, float)
    torque = omega_dot @ J.T + rot.cross(omega, omega @ J.T)
    return sigma * T, rot.multiply(np.tile(q0, (knots, 1)), rot.exp_map(r)), omega, torque


@dataclass(frozen=True)
class Slew:
    """A track-to-track slew starting at ``t0_s`` (s past the epoch): its plan (times from the
    start) and its duration ``duration_s``."""

    t0_s: float
    duration_s: float
    plan: Plan

    @property
    def arrival_s(self) -> float:
        return self.t0_s + self.duration_s


Goal = Callable[[float], tuple[np.ndarray, np.ndarray]]      # t (s past the epoch) -> (q_RN, ω_RN_R)


def fastest(start: tuple[np.ndarray, np.ndarray], t0_s: float, goal: Goal, limits: Limits,
            longest_s: float = MAX_DURATION_S) -> Slew | None:
    """The shortest track-to-track slew from ``start`` (attitude, body rate) at ``t0_s`` onto ``goal``
    within the bounds (module docstring); None when none within ``longest_s`` keeps them."""
    q0, omega0 = (np.asarray(a, float) for a in start)
    scale = 1.0 - BOUND_MARGIN

    def fits(T: float) -> bool:
        q1, omega1 = goal(t0_s + T)
        _, _, omega, torque = profile(q0, omega0, q1, omega1, T, limits.inertia_kg_m2, SEARCH_KNOTS)
        return limits.ratio(omega, torque) <= scale

    q1, _ = goal(t0_s)
    e, phi = rot.to_axis_angle(rot.multiply(rot.conjugate(q0), q1))
    high = max(float(rest_to_rest_time_of(limits, e, phi)), 1.0)
    low = 0.0
    while not fits(high):
        low, high = high, 2.0 * high
        if high > longest_s:
            return None
    while high - low > DURATION_TOLERANCE * high:
        middle = 0.5 * (low + high)
        low, high = (low, middle) if fits(middle) else (middle, high)
    return build(start, t0_s, goal, high, limits)


def rest_to_rest_time_of(limits: Limits, axis, angle) -> float:
    """The rest-to-rest eigenaxis time (:func:`att_planner.problem.rest_to_rest_time`) under ``limits``."""
    class _Body:                         # the fields rest_to_rest_time reads
        inertia, body_torque_max = limits.inertia_kg_m2, limits.torque_max_Nm
        n_wheels, wheel_axes_pinv = len(limits.wheel_axes_pinv), limits.wheel_axes_pinv
    return float(rest_to_rest_time(_Body, axis, angle, limits.rate_max_rad_s, limits.momentum_max_Nms)[0])


def build(start, t0_s: float, goal: Goal, duration_s: float, limits: Limits) -> Slew:
    """The slew of ``duration_s`` from ``start`` at ``t0_s`` onto ``goal`` as a plan of :data:`PLAN_KNOTS`."""
    q1, omega1 = goal(t0_s + duration_s)
    t, q, omega, torque = profile(start[0], start[1], q1, omega1, duration_s, limits.inertia_kg_m2)
    plan = Plan(t=t, torque=torque, q=q, omega=omega, interpolation=Interpolation.LINEAR, method=METHOD,
                status=Status.FEASIBLE, message=f"track to track, t_f = {duration_s:.4g} s",
                stats={"tf": float(duration_s)})
    return Slew(float(t0_s), float(duration_s), plan)


@dataclass(frozen=True)
class SlewCheck:
    """A slew's verification: the arrival's attitude (rad) and rate (rad/s) errors to the goal, the
    lowest zone clearance (rad, true sky), the torque, rate and momentum ratios to their limits, and
    why it is refused (None: accepted)."""

    final_attitude_error: float
    final_rate_error: float
    min_zone_margin: float
    torque_ratio: float
    rate_ratio: float
    momentum_ratio: float
    refusal: str | None


def verify(slew: Slew, spacecraft: dyn.Spacecraft, goal: Goal, limits: Limits, zones=None) -> SlewCheck:
    """The slew's torque flown through the shared rigid body from its start state, measured against the
    goal's law at the arrival, the zones (``zones``: a :class:`att_planner.zones.FittedZones` whose
    time zero is the epoch; None: none) and the limits (module docstring)."""
    plan = slew.plan
    x0 = dyn.initial_state(spacecraft, plan.q[0], plan.omega[0])
    traj = dyn.simulate_profile(spacecraft, x0, plan.t, plan.torque, kind="body_torque",
                                interpolation=str(Interpolation.LINEAR), max_step=VERIFY_STEP_S)
    q_goal, omega_goal = goal(slew.arrival_s)
    q_end, omega_end = traj.q_BN[-1], traj.omega_BN_B[-1]
    attitude = float(rot.angle_between(q_end, q_goal))
    rate = float(np.linalg.norm(omega_end - rot.dcm_BN(q_end) @ rot.dcm_NB(q_goal) @ np.asarray(omega_goal, float)))
    margin, zone = math.inf, ""
    if zones is not None and zones.zones:
        margins = zones.margins(slew.t0_s + traj.t, traj.q_BN, true=True).min(axis=0)
        margin, zone = float(margins.min()), zones.names[int(np.argmin(margins))]
    torque_ratio = float(np.abs(plan.torque).max() / limits.torque_max_Nm)
    rate_ratio = float(np.abs(traj.omega_BN_B).max() / limits.rate_max_rad_s) if math.isfinite(
        limits.rate_max_rad_s) else 0.0
    momentum_ratio = 0.0
    if math.isfinite(limits.momentum_max_Nms) and limits.wheel_axes_pinv.size:
        h = traj.omega_BN_B @ (limits.wheel_axes_pinv @ limits.inertia_kg_m2).T
        momentum_ratio = float(np.abs(h).max() / limits.momentum_max_Nms)
    tol = TOLERANCES
    refusal = None
    if not attitude <= tol.arrival_attitude:
        refusal = f"arrival {math.degrees(attitude):.4f} deg from the site's attitude"
    elif not rate <= tol.arrival_rate:
        refusal = f"arrival rate {math.degrees(rate):.4f} deg/s from the site's rate"
    elif not margin >= -tol.cone_penetration:
        refusal = f"enters zone {zone} by {math.degrees(-margin):.3f} deg"
    elif not max(torque_ratio, rate_ratio, momentum_ratio) <= tol.limit_ratio:
        refusal = (f"limits: torque {torque_ratio:.4f}, rate {rate_ratio:.4f}, momentum {momentum_ratio:.4f} "
                   "x their bounds")
    return SlewCheck(attitude, rate, margin, torque_ratio, rate_ratio, momentum_ratio, refusal)
