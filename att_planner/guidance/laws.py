"""Pointing laws: the reference attitude of each pointing mode as a function of time (no ROS).

Every law is the **two-vector alignment** (:func:`two_vector_attitude`): a primary body axis ``p``
exactly on a primary direction ``P(t)``, a secondary body axis ``s`` as close as possible to a
secondary direction ``S(t)`` (the standard construction of Wertz 1978 §12.2 and of Basilisk's
pointing guidance: the triads ``(p, p×s/|p×s|, p×(p×s)/…)`` and the same of ``(P, S)`` are matched).
The directions (inertial axes, unit, seen from the spacecraft):

* ``nadir``: ``P = −r̂`` (the primary axis, default body +z, on the Earth's centre), ``S = v⊥``
  (the velocity without its radial part: the secondary axis, default body +x, along-track: LVLH),
  then a ``yaw`` about the primary axis;
* ``sun``: ``P`` = the Sun from the spacecraft;
* ``ground``: ``P`` = the line of sight to a point of latitude, longitude (geodetic, WGS-84) and
  altitude, carried by the Earth's rotation (GCRS→ITRS through skyfield's ITRS frame, as the
  geomagnetic field; without an epoch the inertial frame turns at the Earth's rate from t = 0);
* ``inertial_target``: ``P`` a fixed inertial direction; ``inertial``: a fixed attitude.

Secondary directions: ``velocity`` (v⊥), ``ground_velocity`` (the spacecraft's velocity over the
turning Earth, ``v − ω_E k × r`` with ``k`` the Earth's axis, without its radial part: the ground
track's direction, on which a detector's along-track axis is kept), ``orbit_normal`` (r × v),
``sun``, ``nadir``, ``north`` (the inertial +z) or ``inertial`` (a given direction). Where the
primary and secondary directions become parallel the law has no attitude; :func:`two_vector_attitude`
raises, and the law keeps its last attitude (:class:`TwoVectorLaw` notes it) so the controller never
sees a jump.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from att_sim.models import rotations as rot
from att_sim.models.geomagnetic import EARTH_ROTATION_RATE

WGS84_A = 6378137.0                       # m, equatorial radius
WGS84_F = 1.0 / 298.257223563             # flattening
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)      # first eccentricity squared
PARALLEL = 1e-6                           # |P × S| (unit vectors) below this: no attitude


def two_vector_attitude(primary_B, secondary_B, primary_N, secondary_N) -> np.ndarray:
    """The attitude ``q_RN`` (body-to-inertial) putting the body axis ``primary_B`` on the inertial
    direction ``primary_N`` and ``secondary_B`` as close as possible to ``secondary_N`` (all
    unit-normalised here); ValueError when either pair is parallel (within :data:`PARALLEL`): then no
    rotation about the primary is defined."""
    frames = []
    for a, b, what in ((primary_B, secondary_B, "body axes"), (primary_N, secondary_N, "directions")):
        a = np.asarray(a, float) / np.linalg.norm(a)
        b = np.asarray(b, float) / np.linalg.norm(b)
        c = rot.cross(a, b)
        n = float(np.linalg.norm(c))
        if not n > PARALLEL:
            raise ValueError(f"the primary and secondary {what} are parallel: no attitude about the primary")
        c /= n
        frames.append(np.column_stack([a, c, rot.cross(a, c)]))
    body, inertial = frames
    return rot.normalize(rot.from_dcm_NB(inertial @ body.T))


def earth_turning(t: float) -> np.ndarray:
    """Without an epoch: the Earth-fixed frame turning about the inertial z axis at the Earth's rate
    from t = 0 (``R_3(ω_E t)``, inertial to Earth-fixed)."""
    c, s = math.cos(EARTH_ROTATION_RATE * t), math.sin(EARTH_ROTATION_RATE * t)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def geodetic_to_itrs(latitude: float, longitude: float, altitude: float) -> np.ndarray:
    """ITRS position (m) of a geodetic latitude, longitude (rad) and altitude (m) on WGS-84."""
    s, c = math.sin(latitude), math.cos(latitude)
    n = WGS84_A / math.sqrt(1.0 - WGS84_E2 * s * s)
    return np.array([(n + altitude) * c * math.cos(longitude), (n + altitude) * c * math.sin(longitude),
                     (n * (1.0 - WGS84_E2) + altitude) * s])


@dataclass
class PointingGeometry:
    """The geometry the pointing laws look at: ``state_N(t) -> (r_N, v_N)`` (the spacecraft's inertial
    position and velocity, m and m/s), ``sun_N(t)`` (unit, from the spacecraft, inertial axes; None
    without an epoch) and ``dcm_EN(t)`` (the GCRS→ITRS rotation matrix: inertial N to Earth-fixed E
    axes, ``r_E = [EN] r_N``)."""

    state_N: Callable
    sun_N: Callable | None
    dcm_EN: Callable

    @classmethod
    def of(cls, environment) -> PointingGeometry:
        """The pointing geometry of an :class:`att_sim.models.world.Environment` (the onboard models of
        the scenario); the orbit's states are remembered for the last few times asked (a reference differentiates
        its law at three times, each asking for the orbit more than once)."""
        field_model = environment.field
        dcm_EN = field_model.itrs_rotation if field_model.epoch is not None else earth_turning
        sun_N = None if environment.sky is None else environment.sky.sun_direction
        return cls(_remembered(environment.orbit.state), sun_N, dcm_EN)


@dataclass
class TwoVectorLaw:
    """A pointing law: the body axis ``primary_B`` on the inertial direction ``primary_N(t)``,
    ``secondary_B`` as close as possible to ``secondary_N(t)``, then ``yaw`` (rad) about the primary
    axis; :meth:`attitude` is the reference attitude ``q_RN(t)``."""

    name: str
    primary_B: np.ndarray
    secondary_B: np.ndarray
    primary_N: Callable
    secondary_N: Callable
    yaw: float = 0.0
    last_q_RN: np.ndarray | None = field(default=None, repr=False)
    degenerate: bool = False                   # the last attitude asked for was held, not computed

    def attitude(self, t: float) -> np.ndarray:
        try:
            q_RN = two_vector_attitude(self.primary_B, self.secondary_B, self.primary_N(t), self.secondary_N(t))
        except ValueError:
            if self.last_q_RN is None:
                raise
            self.degenerate = True
            return self.last_q_RN
        if self.yaw:
            q_RN = rot.multiply(q_RN, rot.from_axis_angle(self.primary_B, self.yaw))
        self.degenerate, self.last_q_RN = False, q_RN
        return q_RN


@dataclass
class FixedAttitude:
    """Inertial hold of the reference attitude ``q_RN``."""

    q_RN: np.ndarray
    name: str = "inertial"
    degenerate: bool = False

    def attitude(self, t: float) -> np.ndarray:
        return self.q_RN


def _remembered(state: Callable, size: int = 8) -> Callable:
    """``state`` remembering its last ``size`` results by time."""
    memory: dict[float, tuple] = {}

    def remembered(t):
        got = memory.get(t)
        if got is None:
            if len(memory) >= size:
                memory.pop(next(iter(memory)))
            got = memory[t] = tuple(np.asarray(x, float) for x in state(t))
        return got
    return remembered


def _unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    return v / math.sqrt(float(v @ v))


def directions(geometry: PointingGeometry) -> dict[str, Callable]:
    """The named directions of :data:`SECONDARY` as functions of time (unit, inertial)."""
    def nadir(t):
        return -_unit(geometry.state_N(t)[0])

    def velocity(t):
        r, v = geometry.state_N(t)
        r_hat = _unit(r)
        return _unit(v - (v @ r_hat) * r_hat)

    def ground_velocity(t):
        r, v = geometry.state_N(t)
        r_hat = _unit(r)
        g = v - EARTH_ROTATION_RATE * rot.cross(np.asarray(geometry.dcm_EN(t))[2], r)
        return _unit(g - (g @ r_hat) * r_hat)

    def orbit_normal(t):
        r, v = geometry.state_N(t)
        return _unit(rot.cross(r, v))

    out = {"nadir": nadir, "velocity": velocity, "ground_velocity": ground_velocity, "orbit_normal": orbit_normal,
           "north": lambda t: np.array([0.0, 0.0, 1.0])}
    if geometry.sun_N is not None:
        out["sun"] = lambda t: _unit(geometry.sun_N(t))
    return out


def ground_line_of_sight(geometry: PointingGeometry, latitude: float, longitude: float, altitude: float) -> Callable:
    """The unit line of sight from the spacecraft to a ground point, as a function of time."""
    r_itrs = geodetic_to_itrs(latitude, longitude, altitude)

    def sight(t):
        return _unit(np.asarray(geometry.dcm_EN(t)).T @ r_itrs - geometry.state_N(t)[0])
    return sight


@dataclass
class BlendedLaw:
    """``law`` entered from rest at ``start`` (s) through a time warp (the smooth planner's plans end
    at rest): over ``duration`` s the reference is ``law(start + w(τ))`` with
    ``w(τ) = τ − τ(1 − τ/T)²``, so it starts on the law's attitude at ``start`` with zero rate, runs
    up to 4/3 of the law's rate, and joins the law exactly (``w(T) = T``, ``w'(T) = 1``) at
    ``start + T``; the law itself after."""

    law: object
    start: float
    duration: float

    @property
    def name(self) -> str:
        return self.law.name

    @property
    def degenerate(self) -> bool:
        return self.law.degenerate

    def attitude(self, t: float) -> np.ndarray:
        tau = t - self.start
        if tau >= self.duration:
            return self.law.attitude(t)
        tau = max(tau, 0.0)
        return self.law.attitude(self.start + tau - tau * (1.0 - tau / self.duration) ** 2)
