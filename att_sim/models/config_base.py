"""The base of the configuration schemas (pydantic v2): the model every mapping of a file derives
from, the checked field types (finite numbers, unit vectors, quaternions, names), the field helpers
writing a default, range, unit and meaning once, and the cone shared by a scenario's zones and a star
tracker's exclusions.

A key of an older name is refused with its new name (each model's ``renamed`` table, reported by
:mod:`att_sim.models.config_files`). Numbers are finite but the limits documented as accepting
``.inf`` (no limit); axes, normals and directions are unit vectors (within :data:`UNIT_TOLERANCE`);
quaternions are [x, y, z, w] of unit norm.
"""
from __future__ import annotations

import math
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator

from att_msgs_py.types import ZONE_BODIES

UNIT_TOLERANCE = 1e-3          # |‖v‖ − 1| accepted for a unit vector or quaternion of a file
MAX_NAME = 128


class Schema(BaseModel):
    """A mapping of a configuration file: unknown keys refused, values immutable once read."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, populate_by_name=True,
                              ser_json_inf_nan="strings")
    renamed: ClassVar[dict[str, str]] = {}     # old key -> its new name (refused, answered with it)


def _finite(x: float) -> float:
    if not math.isfinite(x):
        raise ValueError(f"a finite number, got {x!r}")
    return x


def distinct_names(items: list, what: str) -> list:
    """``items`` when their ``name`` fields differ (a validator's ValueError naming the first repeated
    one otherwise)."""
    names = [item.name for item in items]
    repeat = next((n for i, n in enumerate(names) if n in names[:i]), None)
    if repeat is not None:
        raise ValueError(f"distinct {what} names, got '{repeat}' twice")
    return items


def near_unit(tolerance: float = UNIT_TOLERANCE):
    """A validator of a vector whose norm is within ``tolerance`` of 1."""
    def check(v: list[float]) -> list[float]:
        norm = float(np.linalg.norm(v))
        if abs(norm - 1.0) > tolerance:
            raise ValueError(f"a unit vector (norm within {tolerance:g} of 1), got norm {norm:.9g}")
        return v
    return check


def _unit_triples(v: list[float]) -> list[float]:
    rows = np.asarray(v, float).reshape(-1, 3)
    norms = np.linalg.norm(rows, axis=1)
    bad = np.flatnonzero(np.abs(norms - 1.0) > UNIT_TOLERANCE)
    if bad.size:
        raise ValueError(f"3 numbers per unit vector; vector {int(bad[0])} has norm {norms[bad[0]]:.6g}")
    return v


def _triples(v: list[float]) -> list[float]:
    if len(v) % 3:
        raise ValueError(f"3 numbers per vector, got {len(v)} numbers")
    return v


def _printable(name: str) -> str:
    if not name.isprintable():
        raise ValueError("a printable name (no control characters)")
    return name


Finite = Annotated[float, AfterValidator(_finite)]
Vector3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
UnitVector3 = Annotated[Vector3, AfterValidator(near_unit())]
UnitVectors = Annotated[list[Finite], Field(max_length=3 * 64), AfterValidator(_triples),
                        AfterValidator(_unit_triples)]
Quaternion = Annotated[list[Finite], Field(min_length=4, max_length=4), AfterValidator(near_unit())]
Name = Annotated[str, Field(min_length=1, max_length=MAX_NAME), AfterValidator(_printable)]


def number(default: Any = ..., *, unit: str, meaning: str, ge: float | None = None, gt: float | None = None,
           le: float | None = None, lt: float | None = None) -> Any:
    """A float field with its default, range, unit and meaning (the JSON Schema's description)."""
    return Field(default, ge=ge, gt=gt, le=le, lt=lt, description=f"{meaning} ({unit})" if unit else meaning)


def limit(meaning: str, unit: str) -> Any:
    """A positive limit; ``.inf`` (the default) for no limit."""
    return Field(math.inf, gt=0.0, description=f"{meaning} ({unit}); .inf: no limit")


class Cone(Schema):
    """A cone about a body's direction: a star tracker's exclusion or a scenario's zone. Its half-angle
    is in (0, 180) deg, or for ``earth_limb`` the margin beyond the Earth limb in [0, 90) deg; a
    ``direction`` is given for body ``inertial`` and only for it."""

    body: Literal[ZONE_BODIES] = Field(description="the body the cone is about")
    half_angle_deg: float = Field(description="cone half-angle in (0, 180) deg; earth_limb: margin in [0, 90) deg")
    direction: UnitVector3 | None = Field(None, description="unit inertial direction (body inertial only)")

    @model_validator(mode="after")
    def _consistent(self):
        limb, angle = self.body == "earth_limb", self.half_angle_deg
        if not ((0.0 <= angle < 90.0) if limb else (0.0 < angle < 180.0)):
            what = "the margin beyond the Earth limb in [0, 90) deg" if limb else "a cone half-angle in (0, 180) deg"
            raise ValueError(f"half_angle_deg {what}, got {angle:g}")
        if (self.body == "inertial") != (self.direction is not None):
            raise ValueError("direction (a unit inertial vector) for body inertial, and only for it")
        return self
