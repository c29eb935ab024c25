"""Field checks shared by every receiver of the suite (planner, controller, simulator, tools).

Each check takes the raw value, the field's name as the sender knows it and the error code of the
surface, and returns the value in its checked form or raises :class:`RequestError` with a sentence
naming the field and the reason. Nothing here knows about ROS messages: the nodes call these on
what :mod:`att_msgs_py.convert` read.
"""
from __future__ import annotations

import math
import unicodedata

import numpy as np

from att_msgs_py.errors import ErrorCode, RequestError

UNIT_TOLERANCE = 1e-3          # |‖q‖ − 1| (and unit vectors) accepted and normalised below this
MAX_NAME_LENGTH = 128          # names, ids and frames
MAX_TEXT_LENGTH = 1000         # free text (plan messages)
MAX_PLAN_SAMPLES = 20_000      # knots of a plan (about 1.8 MB on the wire)
MAX_PLAN_BYTES = 4 * 1024 * 1024   # serialized ManeuverPlan
MAX_PLAN_DURATION = 86_400.0   # s


def text(value, name: str, code: ErrorCode = ErrorCode.INVALID_TEXT, max_length: int = MAX_NAME_LENGTH) -> str:
    """A string without control or format characters (NUL, newline, escape, bidi overrides, ...)
    and at most ``max_length``
    characters. (A NUL cannot reach a node: rclpy's C strings end at the first NUL, so senders
    check with this too, see :mod:`att_msgs_py.convert`.)"""
    if not isinstance(value, str):
        raise RequestError(code, f"{name} must be a string, got {type(value).__name__}")
    if len(value) > max_length:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"{name} has {len(value)} characters; at most {max_length}")
    bad = next((ch for ch in value if unicodedata.category(ch) in ("Cc", "Cf", "Cs", "Cn")), None)
    if bad is not None:
        raise RequestError(ErrorCode.INVALID_TEXT,
                           f"{name} contains the control, format or unassigned character U+{ord(bad):04X} at "
                           f"position {value.index(bad)}")
    return value


def finite_array(value, name: str, code: ErrorCode, shape: tuple | None = None) -> np.ndarray:
    """A float array of ``shape`` (``-1`` for any length) with only finite entries."""
    a = np.asarray(value, dtype=float)
    if shape is not None and (a.ndim != len(shape) or any(s not in (-1, n) for s, n in zip(shape, a.shape))):
        want = "x".join("K" if s == -1 else str(s) for s in shape)
        raise RequestError(code, f"{name} has shape {'x'.join(map(str, a.shape)) or 'scalar'}; expected {want}")
    if not np.all(np.isfinite(a)):
        raise RequestError(code, f"{name} has NaN or Inf entries")
    return a


def number(value, name: str, code: ErrorCode, low: float = -math.inf, high: float = math.inf,
           *, low_open: bool = False) -> float:
    """A finite float in [low, high] (``(low, high]`` with ``low_open``)."""
    v = float(value)
    if not math.isfinite(v) or v > high or v < low or (low_open and v == low):
        interval = f"{'(' if low_open else '['}{low:g}, {high:g}]"
        raise RequestError(code, f"{name} = {v!r} is outside {interval}")
    return v


def _unit(v, size: int, name: str, code: ErrorCode, what: str) -> np.ndarray:
    """A ``size``-vector within :data:`UNIT_TOLERANCE` of unit norm, normalised."""
    v = np.asarray(v, float)
    if v.shape != (size,) or not np.all(np.isfinite(v)):
        raise RequestError(code, f"{name} has NaN or Inf components")
    with np.errstate(over="ignore"):
        n = np.linalg.norm(v)
    if n == 0.0:
        raise RequestError(code, f"{name} is the zero {what}")
    if abs(n - 1.0) > UNIT_TOLERANCE:
        raise RequestError(code, f"{name} has norm {n:.6g}; a unit {what} is required (tolerance {UNIT_TOLERANCE})")
    return v / n


def unit_quaternion(q, name: str, code: ErrorCode = ErrorCode.INVALID_ATTITUDE) -> np.ndarray:
    """A quaternion within :data:`UNIT_TOLERANCE` of unit norm, normalised."""
    return _unit(q, 4, name, code, "quaternion")


def unit_vector(v, name: str, code: ErrorCode) -> np.ndarray:
    """A 3-vector within :data:`UNIT_TOLERANCE` of unit norm, normalised."""
    return _unit(v, 3, name, code, "vector")


def unit_quaternions(q, name: str, code: ErrorCode) -> np.ndarray:
    """(K, 4) quaternions, each within :data:`UNIT_TOLERANCE` of unit norm, normalised."""
    q = finite_array(q, name, code, (-1, 4))
    with np.errstate(over="ignore"):
        n = np.linalg.norm(q, axis=1)
    bad = np.flatnonzero(np.abs(n - 1.0) > UNIT_TOLERANCE)
    if bad.size:
        raise RequestError(code, f"{name}[{bad[0]}] has norm {n[bad[0]]:.6g}; unit quaternions are required "
                                 f"(tolerance {UNIT_TOLERANCE})")
    return q / n[:, None]
