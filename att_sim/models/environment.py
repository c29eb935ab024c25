"""Orbit and geomagnetic environment: circular orbit, tilted-dipole field, gravity gradient.

Model of Bruni & Celani (the magnetorquer PD-gain study), in the inertial (ECI) frame:

* circular orbit of radius ``R = R_E + altitude``, mean motion ``n = sqrt(μ / R³)``; the position in
  the orbital plane ``R [cos(n t + ψ), sin(n t + ψ), 0]`` is rotated by the inclination ``i``
  (about x) and the right ascension of the ascending node ``Ω`` (about z):
  ``r = R_z(Ω) R_x(i) R [cos u, sin u, 0]``, ``u = n t + ψ`` (argument of latitude);
* tilted dipole (Wertz, eq. H-17 form)::

      B_i = (μ_m / R³) [3 (m̂ᵀ r̂) r̂ − m̂],
      m̂   = [sin θ_m cos(ω_e t + α_0), sin θ_m sin(ω_e t + α_0), cos θ_m],

  ``μ_m = 7.746e15 Wb·m``, ``θ_m = 170°``, ``ω_e = 360.99°/day``, ``α_0 = 0``;
* gravity-gradient torque ``τ = (3 μ / R³) r̂_b × (J r̂_b)`` (optional helper).

All functions broadcast: ``t`` and ``arg0`` (ψ) may be arrays, so many cases are evaluated at once.
Vectors come back with a trailing axis of 3. Body-frame helpers use the suite's convention
(:mod:`att_sim.models.rotations`): the inertial-to-body matrix ``C(q)`` of the paper is ``dcm_BN(q)``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_sim.models import rotations as rot

EARTH_RADIUS = 6378.137e3            # m (WGS-84 equatorial)
EARTH_MU = 3.986004418e14            # m³/s²
DIPOLE_STRENGTH = 7.746e15           # Wb·m, μ_m
DIPOLE_COELEVATION = math.radians(170.0)   # θ_m
EARTH_RATE = math.radians(360.99) / 86400.0  # ω_e, rad/s
DIPOLE_RIGHT_ASCENSION0 = 0.0        # α_0


@dataclass(frozen=True)
class OrbitParams:
    """Circular orbit. ``arg0`` is ψ, the argument of latitude at t = 0 (rad)."""

    altitude: float = 450e3                      # m
    inclination: float = math.radians(87.0)      # rad
    raan: float = 0.0                            # rad
    arg0: float = 0.0                            # rad (ψ)

    @property
    def radius(self) -> float:
        return EARTH_RADIUS + self.altitude

    @property
    def mean_motion(self) -> float:
        return math.sqrt(EARTH_MU / self.radius**3)

    @property
    def period(self) -> float:
        return 2.0 * math.pi / self.mean_motion

    def plane_matrix(self) -> np.ndarray:
        """Columns: inertial directions of the in-plane axes ``R_z(Ω) R_x(i) [e1, e2]`` (3, 2)."""
        ci, si = math.cos(self.inclination), math.sin(self.inclination)
        co, so = math.cos(self.raan), math.sin(self.raan)
        return np.array([[co, -so * ci], [so, co * ci], [0.0, si]])


@dataclass(frozen=True)
class DipoleModel:
    """Tilted-dipole geomagnetic field constants (defaults: Bruni & Celani's values)."""

    strength: float = DIPOLE_STRENGTH
    coelevation: float = DIPOLE_COELEVATION
    earth_rate: float = EARTH_RATE
    right_ascension0: float = DIPOLE_RIGHT_ASCENSION0

    def axis(self, t) -> np.ndarray:
        """Unit dipole axis m̂(t) in inertial axes, shape ``t.shape + (3,)``."""
        t = np.asarray(t, float)
        a = self.earth_rate * t + self.right_ascension0
        s = math.sin(self.coelevation)
        return np.stack([s * np.cos(a), s * np.sin(a), np.full_like(a, math.cos(self.coelevation))], -1)

    def axis_at(self, t: float) -> tuple[float, float, float]:
        """m̂ at one scalar time as plain floats (the batch simulator's per-stage call)."""
        a = self.earth_rate * t + self.right_ascension0
        s = math.sin(self.coelevation)
        return (s * math.cos(a), s * math.sin(a), math.cos(self.coelevation))


DEFAULT_DIPOLE = DipoleModel()


def _arg0(orbit: OrbitParams, arg0):
    return orbit.arg0 if arg0 is None else np.asarray(arg0, float)


def direction(orbit: OrbitParams, cos_u, sin_u, plane: np.ndarray | None = None) -> tuple:
    """Unit position components ``(r̂x, r̂y, r̂z)`` from cos/sin of the argument of latitude
    (``plane``: :meth:`OrbitParams.plane_matrix`, passed in by callers that reuse it)."""
    p = orbit.plane_matrix().tolist() if plane is None else plane
    return (p[0][0] * cos_u + p[0][1] * sin_u, p[1][0] * cos_u + p[1][1] * sin_u, p[2][1] * sin_u)


def dipole_field_components(orbit: OrbitParams, r_hat: tuple, m_hat, dipole: DipoleModel = DEFAULT_DIPOLE) -> tuple:
    """``B_i = (μ_m/R³)[3 (m̂ᵀr̂) r̂ − m̂]`` as three component arrays (T).

    ``r_hat`` is a tuple of component arrays, ``m_hat`` a 3-sequence (scalars or arrays). This is the
    one field routine: :func:`field_inertial` and the batch simulator of
    :mod:`att_planner.tuning` both call it.
    """
    k = dipole.strength / orbit.radius**3
    rx, ry, rz = r_hat
    mx, my, mz = m_hat
    proj3 = 3.0 * (mx * rx + my * ry + mz * rz)
    return (k * (proj3 * rx - mx), k * (proj3 * ry - my), k * (proj3 * rz - mz))


def argument_of_latitude(orbit: OrbitParams, t, arg0=None):
    return orbit.mean_motion * np.asarray(t, float) + _arg0(orbit, arg0)


def position(orbit: OrbitParams, t, arg0=None) -> np.ndarray:
    """Inertial position (m), shape ``broadcast(t, arg0).shape + (3,)``."""
    u = argument_of_latitude(orbit, t, arg0)
    return orbit.radius * np.stack(direction(orbit, np.cos(u), np.sin(u)), -1)


def field_inertial(orbit: OrbitParams, t, arg0=None, dipole: DipoleModel = DEFAULT_DIPOLE) -> np.ndarray:
    """Geomagnetic field in inertial axes (T) at time(s) ``t`` (s), shape ``(..., 3)``."""
    t = np.asarray(t, float)
    u = argument_of_latitude(orbit, t, arg0)
    r_hat = direction(orbit, np.cos(u), np.sin(u))
    m_hat = np.moveaxis(dipole.axis(t), -1, 0)
    return np.stack(np.broadcast_arrays(*dipole_field_components(orbit, r_hat, m_hat, dipole)), -1)


def field_body(orbit: OrbitParams, t, q_BN, arg0=None, dipole: DipoleModel = DEFAULT_DIPOLE) -> np.ndarray:
    """``B_b = C(q_BN) B_i(t)`` (T)."""
    return rot.to_body(q_BN, field_inertial(orbit, t, arg0, dipole))


def gravity_gradient_torque(orbit: OrbitParams, t, q_BN, inertia, arg0=None) -> np.ndarray:
    """Gravity-gradient torque in body axes (N m): ``(3μ/R³) r̂_b × (J r̂_b)``."""
    r = position(orbit, t, arg0)
    r_b = rot.to_body(q_BN, r / orbit.radius)
    j_r = np.einsum("ij,...j->...i", np.asarray(inertia, float), r_b)
    return 3.0 * EARTH_MU / orbit.radius**3 * np.cross(r_b, j_r)
