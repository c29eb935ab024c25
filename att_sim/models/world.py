"""The environment the simulator integrates: orbit, geomagnetic field, Sun and shadow, disturbance torques.

:class:`Environment` composes the models of the real sky for one spacecraft:

* orbit: any :class:`att_sim.models.orbit.Orbit` (circular, Kepler + J2, TLE/SGP4), GCRS, t past the epoch;
* field: :class:`att_sim.models.geomagnetic.GeomagneticField` (``dipole`` or ``igrf14``), in body axes
  ``B_b = C(q) B_N(t, r(t))``; for IGRF-14 the inertial field is tabulated along the orbit in
  10-minute tracks (:meth:`~att_sim.models.geomagnetic.GeomagneticField.track`, < 1e-3 nT) built as t
  reaches them;
* sky: :class:`att_sim.models.ephemeris.Ephemeris` for the Sun's position and the conical shadow;
* torques (:mod:`att_sim.models.disturbances`), each switched by :class:`Flags`: gravity gradient, solar
  radiation pressure on the facets (zero in umbra, scaled by the visible fraction of the Sun),
  aerodynamic drag on the facets with the exponential density of :mod:`att_sim.models.atmosphere` at the
  spherical altitude ``|r| − R_E`` and the air co-rotating with the Earth
  (:func:`~att_sim.models.disturbances.relative_velocity`, ``v − ω_E ẑ × r`` with ``ẑ`` GCRS's pole: the
  Earth's pole within 0.4°), and the residual magnetic dipole ``m_res × B_b``.

:meth:`Environment.stage` is the :data:`att_sim.models.dynamics.StageEnvironment` the simulator passes to
:func:`att_sim.models.dynamics.step`: it is evaluated at every RK4 stage's (t, x). What depends on t only
(position, velocity, inertial field, Sun, shadow, density) is computed once per distinct time and
cached — the two middle stages share a time and the last stage's time is the next step's first — so
a step costs two time evaluations and four attitude evaluations.

A scenario without the real sky's keys (:func:`Environment.from_scenario`) has the circular world
(:meth:`Environment.circular`): the circular orbit, the tilted dipole and optionally the gravity gradient, nothing else.

:func:`stages` evaluates the environments of many runs at one stage on rows (one state per run); the
time-only part is computed once when the runs' environments share it (:meth:`Environment.share_time_part`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from datetime import datetime
from typing import NamedTuple

import numpy as np

from att_sim.models import atmosphere, disturbances
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft
from att_sim.models.environment import EARTH_RADIUS, OrbitParams
from att_sim.models.ephemeris import Ephemeris, shadow_function
from att_sim.models.geomagnetic import GeomagneticField
from att_sim.models.orbit import CircularOrbit, Orbit

TRACK_SPAN = 600.0        # s of orbit per tabulated IGRF-14 field track
CACHE_TIMES = 4           # distinct times whose time-only part is kept


@dataclass(frozen=True)
class Flags:
    """Which disturbance torques act (the residual dipole acts when it is non-zero)."""

    gravity_gradient: bool = False
    solar_pressure: bool = False
    drag: bool = False


class Sample(NamedTuple):
    """The environment at one time and attitude."""

    field_B: np.ndarray       # (3,) T, body axes
    torque_B: np.ndarray      # (3,) N m, body axes: the sum of the active disturbance torques
    position: np.ndarray      # (3,) m, inertial (GCRS with an epoch)
    shadow: float             # visible fraction of the solar disc (1 without a sky)


class Bodies(NamedTuple):
    """What the sensors see at one time (inertial axes): the spacecraft's position, the field, and
    unit directions from the spacecraft (Sun and Moon None without a sky)."""

    position: np.ndarray      # m
    field_N: np.ndarray       # T
    nadir: np.ndarray         # unit, −r̂
    earth_radius: float       # rad, the Earth's angular radius asin(R_E/|r|)
    sun: np.ndarray | None    # unit
    moon: np.ndarray | None   # unit
    shadow: float             # visible fraction of the solar disc (1 without a sky)


class _Now(NamedTuple):
    """What depends on time only."""

    r: np.ndarray
    v_rel: np.ndarray | None      # m/s, velocity relative to the co-rotating air (drag only)
    density: float                # kg/m³ (drag only, else 0)
    field_N: np.ndarray
    sun_N: np.ndarray | None      # unit, from the spacecraft (solar pressure only)
    sun_distance: float
    shadow: float


class Environment:
    """Orbit, field, sky and disturbances of one spacecraft (see module docstring)."""

    def __init__(self, epoch: datetime | None, orbit: Orbit, field: GeomagneticField, sky: Ephemeris | None,
                 spacecraft: Spacecraft, facets=(), residual_dipole=None, flags: Flags = Flags(),
                 drag_coefficient: float = 2.2):
        self.epoch, self.orbit, self.field, self.sky, self.spacecraft = epoch, orbit, field, sky, spacecraft
        self.facets, self.flags, self.drag_coefficient = list(facets), flags, float(drag_coefficient)
        m = np.zeros(3) if residual_dipole is None else np.asarray(residual_dipole, float).reshape(3)
        self.residual_dipole = m if np.any(m) else None
        if flags.solar_pressure and sky is None:
            raise ValueError("solar_pressure needs a sky (an epoch): the Sun's position and the shadow")
        if (flags.solar_pressure or flags.drag) and not self.facets:
            raise ValueError("solar_pressure and drag need facets (the surfaces they act on)")
        self._tracks: dict[int, object] = {}
        self._cache: dict[float, _Now] = {}

    @classmethod
    def circular(cls, spacecraft: Spacecraft, orbit: OrbitParams, gravity_gradient: bool = False) -> Environment:
        """The circular world of Bruni & Celani: circular orbit, tilted dipole, optional gravity gradient, no epoch."""
        return cls(None, CircularOrbit(orbit), GeomagneticField("dipole"), None, spacecraft,
                   flags=Flags(gravity_gradient=gravity_gradient))

    @classmethod
    def from_scenario(cls, scenario, gravity_gradient: bool | None = None) -> Environment:
        """The environment of a :class:`att_sim.models.scenario.Scenario`; ``gravity_gradient`` (the
        simulator's parameter), when given, overrides the scenario's ``environment.gravity_gradient``."""
        e = scenario.environment
        flags = Flags(gravity_gradient=e.get("gravity_gradient", False) if gravity_gradient is None
                      else bool(gravity_gradient),
                      solar_pressure=e.get("solar_pressure", False), drag=e.get("drag", False))
        sky = None if scenario.epoch is None else Ephemeris(scenario.epoch, scenario.orbit_model)
        return cls(scenario.epoch, scenario.orbit_model, GeomagneticField(scenario.field_model, scenario.epoch),
                   sky, scenario.spacecraft, e.get("facets", ()), e.get("residual_dipole"), flags,
                   e.get("drag_coefficient", 2.2))

    def with_orbit(self, orbit: Orbit) -> Environment:
        """The same environment on another orbit (caches fresh)."""
        sky = None if self.sky is None else Ephemeris(self.sky.epoch, orbit)
        return Environment(self.epoch, orbit, self.field, sky, self.spacecraft, self.facets, self.residual_dipole,
                           self.flags, self.drag_coefficient)

    def with_phase(self, t: float, phase: float) -> Environment:
        """A circular orbit's environment with argument of latitude ``phase`` (rad) at time ``t``."""
        if not isinstance(self.orbit, CircularOrbit):
            raise ValueError("orbit_phase can only be set on a circular orbit")
        params = self.orbit.params
        return self.with_orbit(CircularOrbit(replace(params, arg0=phase - params.mean_motion * t)))

    # -- time-only part ------------------------------------------------------------------------
    def _field_inertial(self, t: float, r: np.ndarray) -> np.ndarray:
        if self.field.model == "dipole":
            return self.field.field_inertial(t, r)
        k = math.floor(t / TRACK_SPAN)
        track = self._tracks.get(k)
        if track is None:
            if len(self._tracks) > 2:
                self._tracks.pop(next(iter(self._tracks)))
            track = self._tracks[k] = self.field.track(self.orbit.position, k * TRACK_SPAN, (k + 1) * TRACK_SPAN)
        return track(t)

    def _now(self, t: float) -> _Now:
        got = self._cache.get(t)
        if got is not None:
            return got
        r, v = self.orbit.state(t)
        r, v = np.asarray(r, float), np.asarray(v, float)
        sun_n, distance, shadow = None, 0.0, 1.0
        if self.sky is not None:
            sun = self.sky.sun(t)
            s = sun - r
            distance = float(np.linalg.norm(s))
            sun_n = s / distance
            shadow = float(shadow_function(r, sun))
        v_rel, density = None, 0.0
        if self.flags.drag:
            v_rel = disturbances.relative_velocity(r, v)
            density = float(atmosphere.density(float(np.linalg.norm(r)) - EARTH_RADIUS))
        got = _Now(r, v_rel, density, self._field_inertial(t, r), sun_n, distance, shadow)
        if len(self._cache) >= CACHE_TIMES:
            self._cache.pop(next(iter(self._cache)))
        self._cache[t] = got
        return got

    def bodies(self, t: float) -> Bodies:
        """Position, field and the directions of the Earth, Sun and Moon at time ``t``."""
        now = self._now(t)
        rn = float(np.linalg.norm(now.r))
        sun = moon = None
        if self.sky is not None:
            sun = now.sun_N
            moon = np.asarray(self.sky.moon_direction(t), float)
        return Bodies(now.r.copy(), now.field_N.copy(), -now.r / rn, math.asin(min(1.0, EARTH_RADIUS / rn)), sun,
                      moon, now.shadow)

    # -- per attitude --------------------------------------------------------------------------
    def torques(self, t: float, q_BN: np.ndarray) -> dict[str, np.ndarray]:
        """Each active disturbance torque (N m, body axes) at time ``t`` and attitude ``q_BN``."""
        now = self._now(t)
        return self._torques(now, q_BN, rot.dcm_BN(q_BN) @ now.field_N)

    def _torques(self, now: _Now, q_BN: np.ndarray, field_b: np.ndarray) -> dict[str, np.ndarray]:
        out, f = {}, self.flags
        if f.gravity_gradient:
            out["gravity_gradient"] = disturbances.gravity_gradient_torque(now.r, q_BN, self.spacecraft.inertia)
        if f.solar_pressure:
            out["solar_pressure"] = disturbances.srp_torque(self.facets, q_BN, now.sun_N, now.sun_distance, now.shadow)
        if f.drag:
            out["drag"] = disturbances.drag_torque(self.facets, q_BN, now.v_rel, now.density, self.drag_coefficient)
        if self.residual_dipole is not None:
            out["residual_dipole"] = disturbances.residual_dipole_torque(self.residual_dipole, field_b)
        return out

    def stage(self, t: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """``(B_b, τ_env)`` at one RK4 stage (:data:`att_sim.models.dynamics.StageEnvironment`) of one
        state (7 + N,) or of rows of states, all in this environment; ``τ_env`` is None when no
        disturbance is active."""
        x = np.asarray(x, float)
        field_b, tau = stages([self] * (len(x) if x.ndim == 2 else 1), t, x if x.ndim == 2 else x[None])
        return (field_b, tau) if x.ndim == 2 else (field_b[0], None if tau is None else tau[0])

    def share_time_part(self, other: Environment) -> None:
        """Keep the time-only part (:class:`_Now`, field tracks) in one cache with ``other``'s, when
        both have the same orbit object, epoch, field model, sky and drag (the runs of a campaign:
        each run's environment would compute the same values); otherwise nothing changes."""
        if other is not self and self._time_key() == other._time_key():
            self._cache, self._tracks = other._cache, other._tracks

    def _time_key(self) -> tuple:
        return (id(self.orbit), self.epoch, self.field.model, self.field.epoch, self.field.dipole, self.sky is None,
                self.flags.drag)

    def field_inertial(self, t: float) -> np.ndarray:
        """The geomagnetic field at the spacecraft at time ``t`` (T, inertial axes)."""
        return self._now(t).field_N

    @property
    def disturbed(self) -> bool:
        """Whether any disturbance torque acts (else :meth:`disturbance` is always None)."""
        f = self.flags
        return f.gravity_gradient or f.solar_pressure or f.drag or self.residual_dipole is not None

    def disturbance(self, t: float, q_BN: np.ndarray, field_b: np.ndarray) -> np.ndarray | None:
        """The sum of the active disturbance torques (N m, body axes) at time ``t``, attitude ``q_BN``
        and body field ``field_b`` (None when none is active)."""
        torques = self._torques(self._now(t), q_BN, field_b)
        return sum(torques.values()) if torques else None

    def sample(self, t: float, q_BN: np.ndarray) -> Sample:
        """Field, total disturbance torque, position and shadow at time ``t`` and attitude ``q_BN``."""
        field_B, tau = stages([self], t, np.asarray(q_BN, float)[None])
        return self.sample_of(t, field_B[0], None if tau is None else tau[0])

    def sample_of(self, t: float, field_b: np.ndarray, torque: np.ndarray | None) -> Sample:
        """:meth:`sample` of the attitude whose :meth:`stage` values at ``t`` are ``field_b``, ``torque``."""
        now = self._now(t)
        return Sample(field_b, np.zeros(3) if torque is None else torque, now.r.copy(), now.shadow)


def stages(environments: list[Environment], t: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """``(B_b, τ_env)`` of each run at time ``t``: the field in body axes (n, 3) and the sum of the
    disturbance torques (n, 3; None when no run is disturbed) of the run of each row of ``x`` (rows
    whose first four entries are the attitude) in its environment."""
    first = environments[0]
    if all(e._cache is first._cache for e in environments):
        field_N = first.field_inertial(t)
    else:
        field_N = np.array([e.field_inertial(t) for e in environments])
    field_b = rot.to_body(x[:, :4], field_N)
    if not any(e.disturbed for e in environments):
        return field_b, None
    torques = [e.disturbance(t, x[i, :4], field_b[i]) for i, e in enumerate(environments)]
    return field_b, np.array([np.zeros(3) if tau is None else tau for tau in torques])
