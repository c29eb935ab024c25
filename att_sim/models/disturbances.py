"""Disturbance torques on a rigid spacecraft (body axes, N m): solar radiation pressure and
aerodynamic drag on flat facets, residual magnetic dipole, gravity gradient at any position.

Models of Wertz (ed.), *Spacecraft Attitude Determination and Control* (1978), ch. 17 (§17.1 gravity
gradient, §17.2 solar radiation, §17.3 aerodynamic, §17.4 magnetic), the flat-plate forms also in
Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed. (2013), §8.6. A facet is a flat
plate of area ``A``, outward unit normal ``n̂`` and centre of pressure ``c`` (from the centre of mass),
body axes; the torque of a force ``F`` on it is ``c × F``. Facets do not shadow each other.

* Solar radiation, facet lit when ``cos θ = n̂·ŝ > 0`` (``ŝ`` unit vector to the Sun)::

      F = −P A cos θ [2 (δ/3 + ρ cos θ) n̂ + (1 − ρ) ŝ],    P = 4.56e-6 N/m² (1 AU / d)² × shadow,

  ``ρ`` specular, ``δ`` diffuse reflectivity, absorbed ``1 − ρ − δ``; ``shadow`` the visible
  fraction of the solar disc (1 sunlit, 0 umbra).
* Drag (free-molecular, no re-emission), facet facing the flow when ``n̂·v̂ > 0``::

      F = −½ ρ_air C_d A (n̂·v̂) |v|² v̂,     v = v_rel = v − ω_E × r (atmosphere co-rotating),

* residual dipole ``τ = m × B``; gravity gradient ``τ = (3μ/|r|⁵) r_b × (J r_b)``, ``r_b = C(q) r``.

Frames: ``q`` is body-to-inertial (:mod:`att_sim.models.rotations`); inertial vectors go to the body by
``C(q) = dcm_BN(q)``. Every function broadcasts over stacks of ``q`` and the vectors.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from att_sim.models import rotations as rot
from att_sim.models.environment import EARTH_MU

SOLAR_PRESSURE_1AU = 4.56e-6          # N/m², solar flux 1367 W/m² over c (Wertz §17.2)
ASTRONOMICAL_UNIT = 1.495978707e11    # m (IAU 2012)
EARTH_ANGULAR_VELOCITY = 7.292115e-5  # rad/s, ω_E about the GCRS z axis (Vallado 2013)
DRAG_COEFFICIENT = 2.2                # C_d of a flat plate in free-molecular flow (Vallado §8.6)
UNIT_TOLERANCE = 1e-3


def _vector(value, name: str) -> tuple[float, float, float]:
    try:
        v = np.asarray(value, float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a list of 3 finite numbers, got {value!r}") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be a list of 3 finite numbers, got {value!r}")
    return tuple(v.tolist())


def _number(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
        raise ValueError(f"{name} must be a number, got {value!r}")
    return float(value)


def _checked(name: str, names: Sequence[str], area, normal, center, specular, diffuse) -> tuple:
    """Validated ``(area, unit normal, center, specular, diffuse)``; ``names`` label the fields."""
    area = _number(area, f"{name}.{names[0]}")
    if not (math.isfinite(area) and area > 0.0):
        raise ValueError(f"{name}.{names[0]} must be a finite area > 0 m², got {area}")
    normal = _vector(normal, f"{name}.{names[1]}")
    norm = math.sqrt(sum(x * x for x in normal))
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise ValueError(f"{name}.{names[1]} is not a unit vector (norm {norm:.6g}; accepted within "
                         f"{UNIT_TOLERANCE:g} of 1)")
    normal = tuple(x / norm for x in normal)
    center = _vector(center, f"{name}.{names[2]}")
    specular, diffuse = _number(specular, f"{name}.{names[3]}"), _number(diffuse, f"{name}.{names[4]}")
    for key, value in ((names[3], specular), (names[4], diffuse)):
        if not 0.0 <= value <= 1.0:
            raise ValueError(f"{name}.{key} must be a reflectivity in [0, 1], got {value}")
    if specular + diffuse > 1.0:
        raise ValueError(f"{name}.{names[3]} + {names[4]} must be at most 1 (the rest is absorbed), "
                         f"got {specular} + {diffuse}")
    return area, normal, center, specular, diffuse


@dataclass(frozen=True)
class Facet:
    """Flat plate: area (m²), outward unit normal and centre of pressure from the centre of mass
    (body axes, m), specular and diffuse reflectivity; ``absorption = 1 − specular − diffuse``."""

    area: float
    normal_B: tuple[float, float, float]
    center_B: tuple[float, float, float]
    specular: float
    diffuse: float

    def __post_init__(self):
        values = _checked("facet", ("area", "normal_B", "center_B", "specular", "diffuse"), self.area,
                          self.normal_B, self.center_B, self.specular, self.diffuse)
        for key, value in zip(("area", "normal_B", "center_B", "specular", "diffuse"), values):
            object.__setattr__(self, key, value)

    @property
    def absorption(self) -> float:
        return 1.0 - self.specular - self.diffuse


def _body(q_BN, v_N) -> tuple:
    """``v_B = [BN] v_N`` (:func:`att_sim.models.rotations.to_body`) as its three components: Python
    floats for one vector (the per-stage path: the facet sums below then run on floats, the same
    IEEE operations as on numpy scalars at a fraction of their cost), arrays for stacks."""
    b = rot.to_body(q_BN, v_N)
    if b.ndim == 1:
        x, y, z = b.tolist()
        return x, y, z
    return b[..., 0], b[..., 1], b[..., 2]


def _vector_out(tx, ty, tz, like) -> np.ndarray:
    if isinstance(like, float):
        return np.array([tx, ty, tz])
    return np.stack(np.broadcast_arrays(tx, ty, tz, like)[:3], -1)


def _plain(value):
    """A 0-d input as a float (the per-stage path), anything else as an array."""
    a = np.asarray(value, float)
    return float(a) if a.ndim == 0 else a


def _all(condition) -> bool:
    """``np.all`` without its cost on a plain bool (the per-stage path)."""
    return condition if isinstance(condition, bool) else bool(np.all(condition))


def srp_torque(facets, q_BN, sun_direction_N, sun_distance_m, shadow) -> np.ndarray:
    """Solar-radiation-pressure torque (N m, body): flat facets, ``sun_direction_N`` from the
    spacecraft to the Sun (normalised here), ``sun_distance_m`` (m), ``shadow`` in [0, 1]."""
    d, nu = _plain(sun_distance_m), _plain(shadow)
    if not _all(d > 0.0):
        raise ValueError(f"sun_distance_m must be > 0 m, got {sun_distance_m}")
    if not _all((nu >= 0.0) & (nu <= 1.0)):
        raise ValueError(f"shadow must be a visible fraction of the solar disc in [0, 1], got {shadow}")
    sx, sy, sz = _body(q_BN, sun_direction_N)
    norm = (sx * sx + sy * sy + sz * sz) ** 0.5
    if not _all((norm > 0.0) & (norm < math.inf)):
        raise ValueError("sun_direction_N must be a nonzero vector")
    sx, sy, sz = sx / norm, sy / norm, sz / norm
    p = SOLAR_PRESSURE_1AU * (ASTRONOMICAL_UNIT / d) ** 2 * nu
    tx = ty = tz = 0.0
    for f in facets:
        (nx, ny, nz), (cx, cy, cz) = f.normal_B, f.center_B
        cos = nx * sx + ny * sy + nz * sz
        cos = cos * (cos > 0.0)                                   # unlit: 0
        k = -p * f.area * cos
        kn, ks = k * 2.0 * (f.diffuse / 3.0 + f.specular * cos), k * (1.0 - f.specular)
        fx, fy, fz = kn * nx + ks * sx, kn * ny + ks * sy, kn * nz + ks * sz
        tx, ty, tz = tx + cy * fz - cz * fy, ty + cz * fx - cx * fz, tz + cx * fy - cy * fx
    return _vector_out(tx, ty, tz, sx * p)


def drag_torque(facets, q_BN, v_rel_N, density, cd: float = DRAG_COEFFICIENT) -> np.ndarray:
    """Aerodynamic torque (N m, body): flat facets facing the flow, velocity ``v_rel_N`` (m/s,
    inertial axes) relative to the atmosphere, air ``density`` (kg/m³)."""
    rho_air = _plain(density)
    if not _all(rho_air >= 0.0):
        raise ValueError(f"density must be at least 0 kg/m³, got {density}")
    if not (math.isfinite(cd) and cd > 0.0):
        raise ValueError(f"cd must be a finite drag coefficient > 0, got {cd}")
    vx, vy, vz = _body(q_BN, v_rel_N)
    if not _all(abs(vx) + abs(vy) + abs(vz) < math.inf):          # NaN fails too
        raise ValueError("v_rel_N must be finite")
    k_air = -0.5 * cd * rho_air                     # F = −½ρC_d A (n̂·v̂)|v|² v̂ = −½ρC_d A (n̂·v) v
    tx = ty = tz = 0.0
    for f in facets:
        (nx, ny, nz), (cx, cy, cz) = f.normal_B, f.center_B
        nv = nx * vx + ny * vy + nz * vz
        k = k_air * f.area * nv * (nv > 0.0)                      # leeward: 0
        fx, fy, fz = k * vx, k * vy, k * vz
        tx, ty, tz = tx + cy * fz - cz * fy, ty + cz * fx - cx * fz, tz + cx * fy - cy * fx
    return _vector_out(tx, ty, tz, vx * rho_air)


def relative_velocity(r_N, v_N) -> np.ndarray:
    """``v − ω_E × r``: velocity relative to the co-rotating atmosphere (ω_E along GCRS z)."""
    r, v = np.asarray(r_N, float), np.asarray(v_N, float)
    w = EARTH_ANGULAR_VELOCITY
    if r.shape == v.shape == (3,):
        (x, y, _), (a, b, c) = r.tolist(), v.tolist()
        return np.array([a + w * y, b - w * x, c])
    return v - np.stack(np.broadcast_arrays(-w * r[..., 1], w * r[..., 0], 0.0 * r[..., 2]), -1)


def residual_dipole_torque(m_B, B_B) -> np.ndarray:
    """``m × B`` (N m): residual dipole ``m_B`` (A m²) in the field ``B_B`` (T), body axes."""
    return rot.cross(np.asarray(m_B, float), np.asarray(B_B, float))


def gravity_gradient_torque(r_N, q_BN, inertia) -> np.ndarray:
    """``(3μ/|r|⁵) r_b × (J r_b)``, ``r_b = C(q_BN) r_N`` (N m, body), at any position ``r_N`` (m)."""
    x, y, z = _body(q_BN, r_N)
    (j00, j01, j02), (j10, j11, j12), (j20, j21, j22) = np.asarray(inertia, float).tolist()
    jx, jy, jz = j00 * x + j01 * y + j02 * z, j10 * x + j11 * y + j12 * z, j20 * x + j21 * y + j22 * z
    k = 3.0 * EARTH_MU / (x * x + y * y + z * z) ** 2.5
    return _vector_out(k * (y * jz - z * jy), k * (z * jx - x * jz), k * (x * jy - y * jx), x)
