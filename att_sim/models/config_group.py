"""Checked reading of one mapping of a scenario file (a sensor, an actuator, a dispersion).

:class:`Group` reads the keys of a YAML mapping one by one — numbers in ranges, vectors, unit
vectors, quaternions, flags, names — and raises ``ValueError`` with a sentence naming the field
(``sensors.gyro.arw_deg_per_sqrt_h must be a number >= 0, got 'fast'``); :meth:`Group.done`
refuses the keys nobody read (a typo must not silently mean a default). The scenario loader
attaches the file's name to the sentence.
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from att_sim.models.config_schema import declared

UNIT_TOLERANCE = 1e-3          # |‖v‖ − 1| accepted for a unit vector or quaternion (then normalised)


def _clip(value, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


class Group:
    """The mapping ``values`` at ``label`` (e.g. ``sensors.gyro``), read key by key."""

    def __init__(self, values, label: str):
        if not isinstance(values, Mapping):
            raise ValueError(f"{label} must be a mapping, got {type(values).__name__}")
        self.values, self.label, self.read = values, label, set()

    def __contains__(self, key: str) -> bool:
        return key in self.values

    def field(self, key: str) -> str:
        return f"{self.label}.{key}"

    def raw(self, key: str, default=None):
        self.read.add(key)
        return self.values.get(key, default)

    def number(self, key: str, default: float | None = None, low: float = -math.inf, high: float = math.inf,
               low_open: bool = False, high_open: bool = False) -> float:
        """A finite number (or ``.inf`` when ``high`` is inf) in [low, high] (ends open as asked);
        required when ``default`` is None."""
        v = self.raw(key, default)
        if v is None:
            raise ValueError(f"{self.field(key)} is missing")
        span = f"{'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ValueError(f"{self.field(key)} must be a number in {span}, got {_clip(v)}")
        x = float(v)
        inside = (x > low if low_open else x >= low) and (x < high if high_open else x <= high)
        if math.isnan(x) or (math.isinf(x) and not (x > 0 and high == math.inf)) or not inside:
            raise ValueError(f"{self.field(key)} must be a number in {span}, got {_clip(v)}")
        return x

    def declared(self, model, key: str, field: str | None = None) -> float:
        """The number ``key`` with the default and range the pydantic ``model`` declares for its field
        ``field`` (default: ``key``): :func:`att_sim.models.config_schema.declared`."""
        default, low, high, low_open, high_open = declared(model, field or key)
        return self.number(key, default, low, high, low_open=low_open, high_open=high_open)

    def numbers(self, key: str, default=None, size: int | None = None, multiple: int | None = None) -> np.ndarray:
        """A list of finite numbers (``size`` of them, or a multiple of ``multiple``)."""
        v = self.raw(key, default)
        if v is None:
            raise ValueError(f"{self.field(key)} is missing")
        ok = isinstance(v, list) and all(not isinstance(x, bool) and isinstance(x, (int, float)) for x in v)
        a = np.asarray(v, float) if ok else np.zeros(0)
        if not ok or not np.all(np.isfinite(a)) or (size is not None and a.size != size) \
                or (multiple is not None and (a.size == 0 or a.size % multiple)):
            want = f"{size} finite numbers" if size is not None else f"finite numbers, {multiple} per item"
            raise ValueError(f"{self.field(key)} must be a list of {want}, got {_clip(v)}")
        return a

    def unit_vectors(self, key: str, default=None) -> np.ndarray:
        """A flat list of 3 numbers per unit vector, as an (N, 3) array of unit rows."""
        rows = self.numbers(key, default, multiple=3).reshape(-1, 3)
        norms = np.linalg.norm(rows, axis=1)
        bad = np.flatnonzero(np.abs(norms - 1.0) > UNIT_TOLERANCE)
        if bad.size:
            raise ValueError(f"{self.field(key)}: vector {int(bad[0])} has norm {norms[bad[0]]:.6g}, not a unit "
                             f"vector (within {UNIT_TOLERANCE:g})")
        return rows / norms[:, None]

    def quaternion(self, key: str, default=None) -> np.ndarray:
        """A unit quaternion [x, y, z, w] (norm within the tolerance, then normalised)."""
        q = self.numbers(key, default, size=4)
        norm = float(np.linalg.norm(q))
        if abs(norm - 1.0) > UNIT_TOLERANCE:
            raise ValueError(f"{self.field(key)} must be a unit quaternion [x, y, z, w], got norm {norm:.6g}")
        return q / norm

    def flag(self, key: str, default: bool = False) -> bool:
        v = self.raw(key, default)
        if not isinstance(v, bool):
            raise ValueError(f"{self.field(key)} must be true or false, got {_clip(v)}")
        return v

    def name(self, key: str, default: str | None = None) -> str:
        v = self.raw(key, default)
        if not (isinstance(v, str) and v and len(v) <= 128 and v.isprintable()):
            raise ValueError(f"{self.field(key)} must be a non-empty printable name of at most 128 characters, "
                             f"got {_clip(v)}")
        return v

    def choice(self, key: str, choices: tuple, default: str | None = None) -> str:
        v = self.raw(key, default)
        if v not in choices:
            raise ValueError(f"{self.field(key)} must be one of {', '.join(choices)}, got {_clip(v)}")
        return v

    def group(self, key: str) -> Group:
        return Group(self.raw(key, {}), self.field(key))

    def items(self, key: str) -> list[Group]:
        """A list of mappings, each as a :class:`Group` labelled ``key[i]``."""
        v = self.raw(key, [])
        if not isinstance(v, list):
            raise ValueError(f"{self.field(key)} must be a list of mappings, got {type(v).__name__}")
        return [Group(item, f"{self.field(key)}[{i}]") for i, item in enumerate(v)]

    def done(self) -> None:
        """Refuse the keys that were not read (a typo must not silently mean a default)."""
        unknown = sorted(str(k) for k in self.values if k not in self.read)
        if unknown:
            known = ", ".join(sorted(self.read))
            raise ValueError(f"{self.label} has unknown key(s) {', '.join(unknown)[:120]} (known: {known})")
