"""The planner's problem type (no ROS): what every planning method is asked.

Every method is a pure function ``plan(problem: ManeuverProblem, **options) -> Plan`` in the style
of ``scipy.optimize``: a problem and options in, one result type out
(:class:`att_msgs_py.types.Plan`: samples, status, message, iterations, wall time, statistics).
The registry of :mod:`att_planner.methods` names them and their options; the planner service
(:mod:`att_planner.service`) validates requests into problems, runs a method, verifies its plan
(:mod:`att_planner.verification`) and answers.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import datetime
from typing import TYPE_CHECKING

import numpy as np

from att_msgs_py.types import Cone, Zone
from att_planner.zones import FittedZones, clenshaw, zones_from_cones
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

if TYPE_CHECKING:          # the annotations only: att_sim.models.ephemeris loads skyfield
    from att_sim.models.ephemeris import Ephemeris

GOAL_DEGREES = (16, 32, 64, 96, 128)   # series degrees a moving goal's fit tries, lowest first
GOAL_FIT_ATTITUDE = 1e-6   # rad: a fit is accepted when it stays this close to the law's attitude ...
GOAL_FIT_RATE = 1e-8       # rad/s: ... and to its rate, between its nodes


class MovingGoal:
    """A goal that moves (a pointing law): ``t ↦ (q, ω)`` from the law in this process, or
    from its Chebyshev series over ``[0, window]`` after pickling: a planner's child process gets
    the series, the verification the law.

    The series (of the sign-continuous attitude and of the rate) is least squares on twice its
    degree's Chebyshev points of the first kind; its degree is the lowest of :data:`GOAL_DEGREES`
    whose series stays within :data:`GOAL_FIT_ATTITUDE` and :data:`GOAL_FIT_RATE` of the law at the
    midpoints between those points (the highest otherwise, its misfit in ``fit_error``). A ground
    site's line of sight turns within a minute near its pass, so a window of many minutes takes a
    high degree; a slew whose terminal condition is met on a series that misses the law by more
    than the arrival tolerance ends beside the target. ``kind``: the pointing mode's kind."""

    def __init__(self, law: Callable[[float], tuple[np.ndarray, np.ndarray]], window: float, kind: str = ""):
        self.law, self.window, self.kind = law, float(window), kind
        for degree in GOAL_DEGREES:
            n = 2 * (degree + 1)
            nodes = np.cos(np.pi * np.arange(2 * n + 1) / (2 * n))[::-1]   # the fit's points and the midpoints
            samples = self._samples(nodes)
            x, check = nodes[1::2], nodes[0::2]
            self.coefficients = np.polynomial.chebyshev.chebfit(x, samples[1::2], degree)    # (degree + 1, 7)
            fitted = np.polynomial.chebyshev.chebval(check, self.coefficients).T
            attitude = np.abs(fitted[:, :4] / np.linalg.norm(fitted[:, :4], axis=1, keepdims=True)
                              - samples[0::2, :4]).max()
            self.fit_error = (float(attitude), float(np.abs(fitted[:, 4:] - samples[0::2, 4:]).max()))
            if self.fit_error[0] <= GOAL_FIT_ATTITUDE and self.fit_error[1] <= GOAL_FIT_RATE:
                break

    def _samples(self, x: np.ndarray) -> np.ndarray:
        """``[q, ω]`` of the law at the points ``x`` of [−1, 1] (increasing), the attitude's sign continuous."""
        samples = []
        for t in 0.5 * (x + 1.0) * self.window:
            q, w = self.law(float(t))
            if samples and np.dot(q, samples[-1][:4]) < 0:
                q = -q
            samples.append(np.concatenate([q, w]))
        return np.array(samples)

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        if self.law is not None:
            return self.law(t)
        value = clenshaw(np.array([[2.0 * t / self.window - 1.0]]), list(self.coefficients))[0]
        return value[:4] / np.linalg.norm(value[:4]), value[4:]

    def series(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The series at the times ``t`` (K,) at once: unit attitudes (K, 4), rates (K, 3) and the rates'
        derivatives (K, 3) (the derivative of the rate's series)."""
        x = 2.0 * np.asarray(t, float) / self.window - 1.0
        value = np.polynomial.chebyshev.chebval(x, self.coefficients).T
        rate_dot = np.polynomial.chebyshev.chebval(x, np.polynomial.chebyshev.chebder(self.coefficients[:, 4:])).T
        return (value[:, :4] / np.linalg.norm(value[:, :4], axis=1, keepdims=True), value[:, 4:],
                rate_dot * 2.0 / self.window)

    def __getstate__(self) -> dict:
        return {**self.__dict__, "law": None}          # the law's sky does not travel: its series does


MIN_WINDOW = 600.0        # s: the shortest default zone window
WINDOW_FACTOR = 4.0       # the default window: this many times the eigenaxis slew time, at least MIN_WINDOW
ZONE_SKY_CACHE = 4        # ZoneSkies a problem keeps (one per window asked for)


def rest_to_rest_time(spacecraft: Spacecraft, axis_B, angle, rate_max: float = math.inf,
                      wheel_momentum_max: float = math.inf) -> np.ndarray:
    """Durations (s) of rest-to-rest eigenaxis slews by ``angle`` (rad, (M,)) about the body unit
    axes ``axis_B`` (M, 3): bang-bang at the largest acceleration the per-axis torque bound T̄
    allows, ``α = T̄ / max_j (|(J e)_j| + φ |(e × J e)_j|)`` (:mod:`att_planner.methods.axis_rotations`),
    coasting at the peak rate ``w = min(sqrt(α φ), ω̄ / max|e_j|, h̄ / max|(G⁺ J e)_i|)`` when the
    per-axis rate bound ``rate_max`` or the wheel momentum bound ``wheel_momentum_max`` is lower:
    ``T = φ / w + w / α`` (accelerate, coast, brake); 0 for a zero angle. The spacecraft needs a
    finite, positive ``body_torque_max``."""
    e = np.atleast_2d(np.asarray(axis_B, float))
    phi = np.atleast_1d(np.asarray(angle, float))
    Je = e @ spacecraft.inertia.T
    alpha = spacecraft.body_torque_max / np.max(np.abs(Je) + phi[:, None] * np.abs(np.cross(e, Je)), axis=1)
    w = np.sqrt(alpha * phi)                             # peak rate of the bang-bang slew
    if np.isfinite(rate_max):
        w = np.minimum(w, rate_max / np.abs(e).max(axis=1))
    if np.isfinite(wheel_momentum_max) and spacecraft.n_wheels:
        w = np.minimum(w, wheel_momentum_max / np.abs(Je @ spacecraft.wheel_axes_pinv.T).max(axis=1))
    positive = phi > 0
    return np.where(positive, phi / np.where(positive, w, 1.0) + w / alpha, 0.0)


@dataclass
class ManeuverProblem:
    """Reorientation of body-fixed sensors among keep-out cones and zones, from rest to rest.

    Attitudes are body-to-inertial quaternions [x, y, z, w]. ``spacecraft.body_torque_max`` is the
    per-axis torque bound T̄ (N m). ``deadline`` is a ``time.monotonic()`` instant after which a
    method must stop and return its best plan so far (``None``: no limit).

    * ``sensor_target``: semi-free final attitude, only the sensor must reach this inertial
      direction (rotation about it free); None: the full final attitude ``q_final`` is imposed.
    * ``targets``: name → attitude, every one to be passed through once, in any order, on the way
      from ``q_initial`` to ``q_final`` (a schedule; Olivares & Staffetti 2018: at a passage the
      attitude is the target's and the body rate about body z is zero). ``target_dwell``: the
      targets observed, held at rest for that many seconds; ``target_windows``: the
      span each observation must lie in (s from the start); a target is never observed while a
      zone covers it.
    * ``rate_max`` (rad/s per body axis) and ``wheel_momentum_max`` (N m s per wheel, the momentum
      the wheels store producing a body-torque plan with zero total momentum): bounds a plan must
      keep, checked by the verification; infinite when not imposed.
    * ``cones``: inertial keep-out cones of ``sensor_axis``; ``zones``: further
      zones, each with its own sensor axis, moving or not (:class:`att_msgs_py.types.Zone`);
      ``epoch``: the UTC instant of t = 0; ``sky``: the sky seen from the spacecraft
      (:class:`att_sim.models.ephemeris.Ephemeris`, needed by sun, moon and earth_limb zones).
      :meth:`zone_sky` joins them: what every method and the verification use.
    * ``goal_motion``: a goal that moves (a pointing law:
      :class:`MovingGoal`, made by :mod:`att_planner.service.moving_goal`): ``t ↦ (q, ω)``, the attitude and
      body rate the plan must reach at its final time ``t`` (``q_final``: its attitude at a first
      estimate of that time, for guesses); None: ``q_final`` at rest.
    * ``wheel_speeds``: the wheels' speeds at the start; the verification follows them along the plan
      (:func:`att_planner.verification.wheel_speeds_along`) against ``wheel_speed_max``.
    * ``boundary_cone``: index of the cone whose boundary the sensor rides for the whole maneuver
      (a forced boundary arc, Melton 2012's BA cases; :func:`att_planner.cones.boundary_arc_issue`);
      None: the sensor may go anywhere outside the cones.
    """

    spacecraft: Spacecraft
    q_initial: np.ndarray
    q_final: np.ndarray
    sensor_axis: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    cones: list[Cone] = field(default_factory=list)
    deadline: float | None = None
    sensor_target: np.ndarray | None = None
    targets: dict = field(default_factory=dict)
    target_dwell: dict = field(default_factory=dict)      # name -> s held at rest on the target (absent: a passage)
    target_windows: dict = field(default_factory=dict)    # name -> (opens, closes) s: its observation within
    rate_max: float = math.inf
    wheel_momentum_max: float = math.inf
    zones: list[Zone] = field(default_factory=list)
    epoch: datetime | None = None
    sky: Ephemeris | None = None
    boundary_cone: int | None = None
    wheel_speeds: np.ndarray | None = None      # rad/s relative to the body at the start (at rest); None: stopped
    goal_motion: MovingGoal | None = None       # t -> (q, ω) of a moving goal
    # caches keyed by the values they depend on, so ``dataclasses.replace`` copies share them
    _zone_skies: dict = field(default_factory=dict, repr=False, compare=False)
    _default_window: tuple = field(default=(), repr=False, compare=False)

    def time_left(self) -> float:
        return np.inf if self.deadline is None else self.deadline - time.monotonic()

    def zone_sky(self, window: float | None = None) -> FittedZones:
        """The cones (first, as inertial keep-out zones of ``sensor_axis``) and the zones over
        ``[0, window]`` s, built once per window and field values (the last :data:`ZONE_SKY_CACHE` kept).

        Default window: :meth:`default_window`. A plan longer than the window cannot be judged
        against the fitted zones (the FittedZones refuses those times); a method asks for a longer
        window then.
        """
        if window is None:
            window = self.default_window()
        # by value (the fields of the cones and zones); the sky by identity (the cached FittedZones holds it)
        key = (float(window), id(self.sky), np.asarray(self.sensor_axis, float).tobytes(),
               tuple((c.direction.tobytes(), c.half_angle, c.name) for c in self.cones),
               tuple((z.name, z.body, z.sensor_axis.tobytes(), z.half_angle, z.keep_in,
                      None if z.direction is None else z.direction.tobytes()) for z in self.zones))
        if key not in self._zone_skies:
            if len(self._zone_skies) >= ZONE_SKY_CACHE:
                self._zone_skies.pop(next(iter(self._zone_skies)))      # the oldest
            zones = zones_from_cones(self.cones, self.sensor_axis) + list(self.zones)
            self._zone_skies[key] = FittedZones(zones, self.sky, float(window))
        return self._zone_skies[key]

    def default_window(self) -> float:
        """The default zone window (s): :data:`WINDOW_FACTOR` × :meth:`slew_time_bound`, at least
        :data:`MIN_WINDOW` (room for detours around the zones); computed once per value of the
        fields the bound reads."""
        bound = (np.asarray(self.q_initial, float).tobytes(), np.asarray(self.q_final, float).tobytes(),
                 self.sensor_target is None, self.rate_max, self.wheel_momentum_max, id(self.spacecraft),
                 self.spacecraft.body_torque_max)
        if self._default_window[:1] != (bound,):
            self._default_window = (bound, max(MIN_WINDOW, WINDOW_FACTOR * self.slew_time_bound()), self.spacecraft)
        return self._default_window[1]

    def slew_time_bound(self) -> float:
        """Duration (s) of the rest-to-rest eigenaxis slew to ``q_final`` (or by π for a semi-free
        goal) with the largest acceleration the per-axis torque bound allows, coasting at the
        problem's rate and momentum bounds: the scale of every method's t_f (0 without a torque bound)."""
        sc = self.spacecraft
        if not (np.isfinite(sc.body_torque_max) and sc.body_torque_max > 0):
            return 0.0
        q_rel = rot.multiply(rot.conjugate(rot.normalize(np.asarray(self.q_initial, float))),
                             rot.normalize(np.asarray(self.q_final, float)))
        e, phi = rot.to_axis_angle(q_rel)
        if self.sensor_target is not None or phi < 1e-12:
            e, phi = np.ones(3) / np.sqrt(3.0), math.pi
        return float(rest_to_rest_time(sc, e, phi, self.rate_max, self.wheel_momentum_max)[0])
