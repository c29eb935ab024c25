"""Strip imaging: a ground segment scanned at a set ground speed, the detector's across-track axis across it.

A push-broom instrument images a **strip** by sweeping its line of sight along a ground segment at
the ground speed its line rate needs, its detector line (the across-track axis) kept across the
strip. The segment (docs: ``strips.md``):

* its **path** is the great ellipse of WGS-84 through its start and end: the section of the
  ellipsoid by the plane through the Earth's centre and both points (the start, an azimuth and a
  length: the plane through the start and its local direction of that azimuth). With ``u(θ) = cos θ u₀
  + sin θ w`` (``u₀`` the start's geocentric direction, ``w`` the unit direction of the plane
  orthogonal to it), the surface point is ``f(θ) = ρ(u) u``, ``ρ = (uᵀ M u)^(-1/2)``,
  ``M = diag(1/a², 1/a², 1/b²)``, and the path at altitude ``h`` is ``p(θ) = f(θ) + h n̂(θ)``,
  ``n̂ = M f / |M f|`` the ellipsoid's normal (so ``p(0)`` is the start's geodetic position exactly);
* its **arc length** ``s(θ) = ∫₀^θ |p'(x)| dx`` (Gauss-Legendre, :data:`QUADRATURE_POINTS` points:
  exact to rounding on strips up to :data:`~.MAX_STRIP_LENGTH_M`), inverted by Newton's method;
* the **aim point** at time ``t`` of a scan started at ``t_s`` is ``p(θ(s))``, ``s = v (t − t_s)``:
  it moves along the path at the scan ground speed ``v`` in the Earth-fixed frame, ``ṗ_E = v T_E``,
  ``T_E = p'/|p'|`` the path's unit tangent, ``Ṫ_E = v (dT_E/dθ)/|p'|`` (a central difference in θ).

In the inertial frame (``[EN]`` the Earth rotation model of :class:`~.laws.PointingGeometry`,
``k_N`` the Earth's axis, ``ω_E`` its rate) the aim point and the strip's ground direction are

    s_N = [EN]ᵀ p_E,      ṡ_N = [EN]ᵀ ṗ_E + ω_E k_N × s_N,
    S_N = [EN]ᵀ T_E,      Ṡ_N = [EN]ᵀ Ṫ_E + ω_E k_N × S_N,

and the reference attitude is the two-vector alignment of the instrument's boresight on the line of
sight ``P = (s_N − r_N)/|s_N − r_N|`` and its along-track axis as near as possible to ``S_N``
(:func:`att_planner.guidance.ground_arrival.two_vector_motion`, the rate in closed form from ``Ṗ``
and ``Ṡ``): the detector's along-track axis lies in the plane of the line of sight and the strip's
ground direction, so the image of the ground moves across the detector line along the strip, the
Earth's rotation included (the scan is defined on the turning Earth). This is the yaw steering of
agile push-broom imagers (Lemaître et al., *Selecting and scheduling observations of agile
satellites*, Aerospace Science and Technology 6(5), 2002: the strip's direction is free, the
attitude follows it). The rate's derivative is a central difference of the closed-form rate over
:data:`RATE_STEP`.

Two uses: :func:`strip_reference` is the reference a tracking law follows along the strip (attitude
``q_RN``, rate ``omega_RN_R`` and acceleration ``omega_dot_RN_R``), :class:`StripLaw` the pointing law
the controller hands over to; :func:`strip_start_goal` is the goal a slew must end on (the strip's
first point at the strip's rate, whatever the arrival time: the scan starts where the slew ends).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from att_planner.guidance import Reference
from att_planner.guidance.ground_arrival import earth_axis_N, itrs_to_geodetic, two_vector_motion
from att_planner.guidance.laws import WGS84_A, WGS84_F, PointingGeometry, geodetic_to_itrs
from att_sim.models import rotations as rot
from att_sim.models.geomagnetic import EARTH_ROTATION_RATE

WGS84_B = WGS84_A * (1.0 - WGS84_F)          # m, polar radius
QUADRATURE_POINTS = 16                       # Gauss-Legendre points of the arc length
NEWTON_ITERATIONS = 6                        # Newton steps of θ(s) at most (quadratic: 1e-12 m in 3 on 2000 km)
NEWTON_TOLERANCE = 1e-15                     # relative step of θ where Newton's method stops
TANGENT_STEP = 1e-5                          # rad of θ: the central difference of the tangent
RATE_STEP = 0.05                             # s: the central difference of the rate
MAX_STRIP_LENGTH_M = 2_000_000.0             # m: a strip is imaged within one pass
MIN_STRIP_LENGTH_M = 1.0                     # m: shorter is a point, not a strip
MAX_SCAN_SPEED_M_S = 20_000.0                # m/s: over twice a LEO ground track's speed
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(QUADRATURE_POINTS)
_M = np.array([1.0 / WGS84_A**2, 1.0 / WGS84_A**2, 1.0 / WGS84_B**2])


@dataclass(frozen=True)
class Strip:
    """A ground segment on WGS-84 (module docstring): ``u0``, ``w`` the plane's orthonormal
    directions (ITRS), ``altitude_m`` above the ellipsoid, ``length_m`` along the path at that
    altitude, ``scan_speed_m_s`` the ground speed of its scan. Build it with :meth:`between` or
    :meth:`from_azimuth` (ValueError for a strip shorter than :data:`MIN_STRIP_LENGTH_M`, longer than
    :data:`MAX_STRIP_LENGTH_M`, or without a defined plane)."""

    u0: np.ndarray
    w: np.ndarray
    altitude_m: float
    length_m: float
    scan_speed_m_s: float
    theta_end: float = field(default=math.nan)

    @classmethod
    def between(cls, latitude0: float, longitude0: float, latitude1: float, longitude1: float, altitude_m: float,
                scan_speed_m_s: float) -> Strip:
        """The strip from one geodetic point to another (rad), both at ``altitude_m``."""
        u0 = _unit(geodetic_to_itrs(latitude0, longitude0, 0.0))
        u1 = _unit(geodetic_to_itrs(latitude1, longitude1, 0.0))
        normal = rot.cross(u0, u1)
        sine = float(np.linalg.norm(normal))
        if sine < MIN_STRIP_LENGTH_M / WGS84_A and float(u0 @ u1) > 0.0:
            raise ValueError("the end is the start: no strip between them")
        if float(u0 @ u1) < 0.0:
            raise ValueError(f"the end is {math.degrees(math.atan2(sine, float(u0 @ u1))):.1f} deg of arc from the "
                             f"start; a strip is at most {MAX_STRIP_LENGTH_M:g} m long")
        w = _unit(u1 - u0 * float(u0 @ u1))
        strip = cls(u0, w, float(altitude_m), 0.0, float(scan_speed_m_s))
        return strip._with_length(strip.arc_length(math.atan2(sine, float(u0 @ u1))))

    @classmethod
    def from_azimuth(cls, latitude0: float, longitude0: float, azimuth: float, length_m: float, altitude_m: float,
                     scan_speed_m_s: float) -> Strip:
        """The strip of ``length_m`` from a geodetic point (rad) in the direction ``azimuth`` (rad, from
        the local north towards the east)."""
        u0 = _unit(geodetic_to_itrs(latitude0, longitude0, 0.0))
        north = np.array([-math.sin(latitude0) * math.cos(longitude0), -math.sin(latitude0) * math.sin(longitude0),
                          math.cos(latitude0)])
        east = np.array([-math.sin(longitude0), math.cos(longitude0), 0.0])
        t = math.cos(azimuth) * north + math.sin(azimuth) * east
        w = _unit(t - u0 * float(u0 @ t))
        strip = cls(u0, w, float(altitude_m), 0.0, float(scan_speed_m_s))
        return strip._with_length(float(length_m))

    def _with_length(self, length_m: float) -> Strip:
        if not MIN_STRIP_LENGTH_M <= length_m <= MAX_STRIP_LENGTH_M:
            raise ValueError(f"the strip is {length_m:.6g} m long, outside [{MIN_STRIP_LENGTH_M:g}, "
                             f"{MAX_STRIP_LENGTH_M:g}] m")
        if not (math.isfinite(self.scan_speed_m_s) and self.scan_speed_m_s > 0.0):
            raise ValueError(f"the scan speed {self.scan_speed_m_s!r} m/s is not positive")
        return Strip(self.u0, self.w, self.altitude_m, float(length_m), self.scan_speed_m_s, self.theta_of(length_m))

    @property
    def duration_s(self) -> float:
        """The scan's duration (s): length over speed."""
        return self.length_m / self.scan_speed_m_s

    def point(self, theta: float) -> tuple[np.ndarray, np.ndarray]:
        """The path's point ``p(θ)`` (ITRS, m) and its derivative ``p'(θ)`` (m/rad)."""
        c, s = math.cos(theta), math.sin(theta)
        u, u_d = c * self.u0 + s * self.w, -s * self.u0 + c * self.w
        rho = 1.0 / math.sqrt(float(u @ (_M * u)))
        rho_d = -rho**3 * float(u @ (_M * u_d))
        f, f_d = rho * u, rho_d * u + rho * u_d
        m, m_d = _M * f, _M * f_d
        m_norm = math.sqrt(float(m @ m))
        n = m / m_norm
        n_d = (m_d - n * float(n @ m_d)) / m_norm
        return f + self.altitude_m * n, f_d + self.altitude_m * n_d

    def arc_length(self, theta: float) -> float:
        """``s(θ)`` (m): Gauss-Legendre over [0, θ]."""
        x = 0.5 * theta * (_NODES + 1.0)
        return 0.5 * theta * float(sum(wk * np.linalg.norm(self.point(xk)[1]) for xk, wk in zip(x, _WEIGHTS)))

    def theta_of(self, s: float) -> float:
        """``θ(s)``: Newton's method on :meth:`arc_length` (``s`` may be negative or past the end: the
        great ellipse continues)."""
        if s == 0.0:
            return 0.0
        theta = s / float(np.linalg.norm(self.point(0.0)[1]))
        for _ in range(NEWTON_ITERATIONS):
            step = (self.arc_length(theta) - s) / float(np.linalg.norm(self.point(theta)[1]))
            theta -= step
            if abs(step) <= NEWTON_TOLERANCE * max(abs(theta), 1e-300):
                break
        return theta

    def tangent(self, theta: float) -> tuple[np.ndarray, np.ndarray]:
        """The unit tangent ``T_E`` at θ (ITRS) and ``dT_E/ds`` (1/m, the path's curvature vector)."""
        def unit_tangent(x):
            return _unit(self.point(x)[1])
        d = (unit_tangent(theta + TANGENT_STEP) - unit_tangent(theta - TANGENT_STEP)) / (2.0 * TANGENT_STEP)
        return unit_tangent(theta), d / float(np.linalg.norm(self.point(theta)[1]))

    def geodetic(self, s: float) -> tuple[float, float]:
        """The geodetic latitude and longitude (rad) of the path's point at arc length ``s``."""
        lat, lon, _ = itrs_to_geodetic(self.point(self.theta_of(s))[0])
        return lat, lon


def _unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    return v / math.sqrt(float(v @ v))


def aim_motion(geometry: PointingGeometry, strip: Strip, primary_B, secondary_B, t: float, s: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """The attitude and body rate at ``t`` with the aim point at arc length ``s`` moving at the scan speed.

    Parameters
    ----------
    geometry : PointingGeometry
        The onboard geometry: orbit state and Earth rotation model.
    strip : Strip
        The strip.
    primary_B, secondary_B : array_like, shape (3,)
        The instrument's boresight and its detector's along-track axis (body axes).
    t : float
        Time (s past the scenario's epoch).
    s : float
        Arc length of the aim point from the strip's start (m).

    Returns
    -------
    q_RN, omega_RN_R : ndarray
        The reference attitude ([x, y, z, w]) and its body rate (rad/s, its own axes).
    """
    theta = strip.theta_of(s)
    p_E, _ = strip.point(theta)
    T_E, dT_ds = strip.tangent(theta)
    v = strip.scan_speed_m_s
    dcm_NE = np.asarray(geometry.dcm_EN(t)).T
    spin = EARTH_ROTATION_RATE * earth_axis_N(geometry, t)
    s_N = dcm_NE @ p_E
    s_dot_N = v * (dcm_NE @ T_E) + rot.cross(spin, s_N)
    S = dcm_NE @ T_E
    S_dot = v * (dcm_NE @ dT_ds) + rot.cross(spin, S)
    r_N, v_N = geometry.state_N(t)
    d, d_dot = s_N - r_N, s_dot_N - v_N
    rho = math.sqrt(float(d @ d))
    P = d / rho
    P_dot = (d_dot - P * float(P @ d_dot)) / rho
    return two_vector_motion(primary_B, secondary_B, P, P_dot, S, S_dot)


def strip_reference(geometry: PointingGeometry, strip: Strip, primary_B, secondary_B, t_start: float,
                    t: float) -> Reference:
    """The reference along a strip scanned from ``t_start`` (s): ``q_RN``, ``omega_RN_R`` in closed
    form and ``omega_dot_RN_R`` by a central difference of the rate over :data:`RATE_STEP` (the rate's
    components in R: ``d/dt`` of them is the rate's derivative, ``ω × ω = 0``)."""
    v = strip.scan_speed_m_s

    def at(time: float):
        return aim_motion(geometry, strip, primary_B, secondary_B, time, v * (time - t_start))

    q_RN, omega = at(t)
    _, before = at(t - RATE_STEP)
    _, after = at(t + RATE_STEP)
    return Reference(q_RN, omega, (after - before) / (2.0 * RATE_STEP))


def strip_start_goal(geometry: PointingGeometry, strip: Strip, primary_B, secondary_B
                     ) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
    """``t ↦ (q_RN, ω_RN_R)``: the strip's first point at the strip's rate, a scan starting at ``t``
    (the moving goal of a slew onto the strip: :class:`att_planner.problem.MovingGoal`)."""
    return lambda t: aim_motion(geometry, strip, primary_B, secondary_B, t, 0.0)


def tracking_demand(spacecraft, geometry: PointingGeometry, strip: Strip, primary_B, secondary_B, t_start: float,
                    samples: int = 11) -> tuple[float, float]:
    """The largest body rate (rad/s, per axis) and body torque (N m, per axis,
    ``τ = J ω̇ + ω × J ω`` on the reference) the scan asks, sampled over its duration."""
    rate, torque = 0.0, 0.0
    J = spacecraft.inertia
    for t in np.linspace(t_start, t_start + strip.duration_s, samples):
        ref = strip_reference(geometry, strip, primary_B, secondary_B, t_start, float(t))
        w = ref.omega_RN_R
        rate = max(rate, float(np.abs(w).max()))
        torque = max(torque, float(np.abs(J @ ref.omega_dot_RN_R + rot.cross(w, J @ w)).max()))
    return rate, torque


@dataclass
class StripLaw:
    """The pointing law of a strip scanned from ``t_start`` (s): the controller's reference along it
    (:func:`strip_reference`; its attitude is what the controller differentiates). Past the strip's
    end (``t_start + strip.duration_s``) the aim point continues on the great ellipse."""

    geometry: PointingGeometry
    strip: Strip
    primary_B: np.ndarray
    secondary_B: np.ndarray
    t_start: float
    name: str = "strip"
    degenerate: bool = False

    @property
    def t_end(self) -> float:
        """When the aim point reaches the strip's end (s)."""
        return self.t_start + self.strip.duration_s

    def attitude(self, t: float) -> np.ndarray:
        return aim_motion(self.geometry, self.strip, self.primary_B, self.secondary_B, t,
                          self.strip.scan_speed_m_s * (t - self.t_start))[0]

    def reference(self, t: float) -> Reference:
        return strip_reference(self.geometry, self.strip, self.primary_B, self.secondary_B, self.t_start, t)

    def primary_N(self, t: float) -> np.ndarray:
        """The unit line of sight to the aim point at ``t`` (inertial): where the law puts the boresight."""
        return rot.dcm_NB(self.attitude(t)) @ np.asarray(self.primary_B, float)
