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

Frames: ``q`` is body-to-inertial (:mod:`att_sim.rotations`); inertial vectors go to the body by
``C(q) = dcm(q).T``. Every function broadcasts over stacks of ``q`` and the vectors.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from att_sim.environment import EARTH_MU, to_body

SOLAR_PRESSURE_1AU = 4.56e-6          # N/m², solar flux 1367 W/m² over c (Wertz §17.2)
ASTRONOMICAL_UNIT = 1.495978707e11    # m (IAU 2012)
EARTH_ANGULAR_VELOCITY = 7.292115e-5  # rad/s, ω_E about the GCRS z axis (Vallado 2013)
DRAG_COEFFICIENT = 2.2                # C_d of a flat plate in free-molecular flow (Vallado §8.6)
UNIT_TOLERANCE = 1e-3
FACET_KEYS = ("area", "normal", "center", "specular", "diffuse")


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


def facets_from_params(params, field: str = "environment.facets") -> list[Facet]:
    """Facets from the scenario's list of ``{area, normal, center, specular, diffuse}`` mappings
    (every key required); a ``ValueError`` names the facet, e.g. ``environment.facets[2].normal``."""
    if isinstance(params, str | bytes | Mapping) or not isinstance(params, Sequence):
        raise ValueError(f"{field} must be a list of facets {{{', '.join(FACET_KEYS)}}}, got {params!r}")
    out = []
    for i, item in enumerate(params):
        name = f"{field}[{i}]"
        if not isinstance(item, Mapping):
            raise ValueError(f"{name} must be a mapping with keys {', '.join(FACET_KEYS)}, got {item!r}")
        missing = [k for k in FACET_KEYS if k not in item]
        unknown = sorted(str(k) for k in item if k not in FACET_KEYS)
        if missing or unknown:
            raise ValueError(f"{name} must have exactly the keys {', '.join(FACET_KEYS)} "
                             f"(missing: {missing or 'none'}, unknown: {unknown or 'none'})")
        out.append(Facet(*_checked(name, FACET_KEYS, *(item[k] for k in FACET_KEYS))))
    return out


@lru_cache(maxsize=32)
def _arrays(facets: tuple[Facet, ...]):
    """``(A (F,), n̂ (F, 3), c (F, 3), ρ (F,), δ (F,))`` of a facet set."""
    return (np.array([f.area for f in facets]), np.array([f.normal_B for f in facets]).reshape(-1, 3),
            np.array([f.center_B for f in facets]).reshape(-1, 3), np.array([f.specular for f in facets]),
            np.array([f.diffuse for f in facets]))


def _unit(v, name: str) -> tuple[np.ndarray, np.ndarray]:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    if not np.all(np.isfinite(norm)):
        raise ValueError(f"{name} must be finite")
    return v / np.where(norm > 0.0, norm, 1.0), norm[..., 0]


def srp_torque(facets, q, sun_direction_N, sun_distance_m, shadow) -> np.ndarray:
    """Solar-radiation-pressure torque (N m, body): flat facets, ``sun_direction_N`` from the
    spacecraft to the Sun (normalised here), ``sun_distance_m`` (m), ``shadow`` in [0, 1]."""
    d, nu = np.asarray(sun_distance_m, float), np.asarray(shadow, float)
    if not np.all(d > 0.0):
        raise ValueError(f"sun_distance_m must be > 0 m, got {sun_distance_m}")
    if not np.all((nu >= 0.0) & (nu <= 1.0)):
        raise ValueError(f"shadow must be a visible fraction of the solar disc in [0, 1], got {shadow}")
    a, n, c, rho, delta = _arrays(tuple(facets))
    s, s_norm = _unit(to_body(q, sun_direction_N), "sun_direction_N")
    if not np.all(s_norm > 0.0):
        raise ValueError("sun_direction_N must be a nonzero vector")
    p = SOLAR_PRESSURE_1AU * (ASTRONOMICAL_UNIT / d) ** 2 * nu
    cos = np.maximum(np.einsum("...i,fi->...f", s, n), 0.0)             # unlit facets: 0
    scale = -np.asarray(p)[..., None] * a * cos                            # (..., F)
    force = scale[..., None] * (2.0 * (delta / 3.0 + rho * cos)[..., None] * n
                                + (1.0 - rho)[:, None] * s[..., None, :])
    return np.sum(np.cross(c, force), axis=-2)


def drag_torque(facets, q, v_rel_N, density, cd: float = DRAG_COEFFICIENT) -> np.ndarray:
    """Aerodynamic torque (N m, body): flat facets facing the flow, velocity ``v_rel_N`` (m/s,
    inertial axes) relative to the atmosphere, air ``density`` (kg/m³)."""
    rho_air = np.asarray(density, float)
    if not np.all(rho_air >= 0.0):
        raise ValueError(f"density must be at least 0 kg/m³, got {density}")
    if not (math.isfinite(cd) and cd > 0.0):
        raise ValueError(f"cd must be a finite drag coefficient > 0, got {cd}")
    a, n, c, _, _ = _arrays(tuple(facets))
    v_hat, speed = _unit(to_body(q, v_rel_N), "v_rel_N")
    cos = np.maximum(np.einsum("...i,fi->...f", v_hat, n), 0.0)
    scale = -0.5 * cd * (rho_air * speed**2)[..., None] * a * cos          # (..., F)
    return np.sum(np.cross(c, scale[..., None] * v_hat[..., None, :]), axis=-2)


def relative_velocity(r_N, v_N) -> np.ndarray:
    """``v − ω_E × r``: velocity relative to the co-rotating atmosphere (ω_E along GCRS z)."""
    r, v = np.asarray(r_N, float), np.asarray(v_N, float)
    w = EARTH_ANGULAR_VELOCITY
    return v - np.stack(np.broadcast_arrays(-w * r[..., 1], w * r[..., 0], 0.0 * r[..., 2]), -1)


def residual_dipole_torque(m_B, B_B) -> np.ndarray:
    """``m × B`` (N m): residual dipole ``m_B`` (A m²) in the field ``B_B`` (T), body axes."""
    return np.cross(np.asarray(m_B, float), np.asarray(B_B, float))


def gravity_gradient_torque(r_N, q, inertia) -> np.ndarray:
    """``(3μ/|r|⁵) r_b × (J r_b)``, ``r_b = C(q) r_N`` (N m, body), at any position ``r_N`` (m)."""
    r_b = to_body(q, r_N)
    j_r = np.einsum("ij,...j->...i", np.asarray(inertia, float), r_b)
    return 3.0 * EARTH_MU / np.sum(r_b * r_b, -1, keepdims=True) ** 2.5 * np.cross(r_b, j_r)
