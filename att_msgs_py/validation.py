"""Field checks shared by every receiver of the suite (planner, controller, simulator, tools).

Each check takes the raw value, the field's name as the sender knows it and the error code of the
surface, and returns the value in its checked form or raises :class:`RequestError` with a sentence
naming the field and the reason. Nothing here knows about ROS messages: the nodes call these on
what :mod:`att_msgs_py.convert` read.
"""
from __future__ import annotations

import math
import unicodedata
from datetime import UTC, datetime, timedelta
from operator import mul

import numpy as np

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.limits import MAX_NAME_LENGTH
from att_msgs_py.limits import MAX_PLAN_BYTES as MAX_PLAN_BYTES  # the caps, declared in one place
from att_msgs_py.limits import MAX_PLAN_SAMPLES as MAX_PLAN_SAMPLES
from att_msgs_py.limits import MAX_TEXT_LENGTH as MAX_TEXT_LENGTH
from att_msgs_py.types import ZONE_BODIES, Zone

UNIT_TOLERANCE = 1e-3          # |‖q‖ − 1| (and unit vectors) accepted and normalised below this
MAX_PLAN_DURATION = 86_400.0   # s
UNIX_EPOCH = datetime(1970, 1, 1, tzinfo=UTC)
WIRE_EPOCH_MIN = UNIX_EPOCH + timedelta(seconds=-2**31)       # builtin_interfaces/Time has int32 seconds:
WIRE_EPOCH_MAX = UNIX_EPOCH + timedelta(seconds=2**31 - 1)    # 1901-12-13T20:45:52Z .. 2038-01-19T03:14:07Z


def text(value, name: str, code: ErrorCode = ErrorCode.INVALID_TEXT, max_length: int = MAX_NAME_LENGTH) -> str:
    """A string without control or format characters (NUL, newline, escape, bidi overrides, ...)
    and at most ``max_length``
    characters. (A NUL cannot reach a node: rclpy's C strings end at the first NUL, so senders
    check with this too, see :mod:`att_msgs_py.convert`.)"""
    if not isinstance(value, str):
        raise RequestError(code, f"{name} must be a string, got {type(value).__name__}")
    if len(value) > max_length:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"{name} has {len(value)} characters; at most {max_length}")
    if value.isascii() and value.isprintable():      # printable ASCII has none of them (the common case)
        return value
    bad = next((ch for ch in value if unicodedata.category(ch) in ("Cc", "Cf", "Cs", "Cn")), None)
    if bad is not None:
        raise RequestError(ErrorCode.INVALID_TEXT,
                           f"{name} contains the control, format or unassigned character U+{ord(bad):04X} at "
                           f"position {value.index(bad)}")
    return value


def wire_epoch(sec: int, nanosec: int, name: str, code: ErrorCode = ErrorCode.INVALID_EPOCH) -> datetime | None:
    """The UTC epoch of a ``builtin_interfaces/Time`` (``sec``, ``nanosec``) as sent: None for the
    zero time ("no epoch"), else ``sec`` within int32 and ``nanosec`` in [0, 1e9) (nanoseconds
    rounded to the microsecond of a ``datetime``)."""
    if not -2**31 <= sec < 2**31:
        raise RequestError(code, f"{name}.sec = {sec} is outside the int32 range [-2^31, 2^31 - 1] of "
                                 "builtin_interfaces/Time")
    if not 0 <= nanosec < 1_000_000_000:
        raise RequestError(code, f"{name}.nanosec = {nanosec} is outside [0, 999999999]")
    if sec == 0 and nanosec == 0:
        return None
    return UNIX_EPOCH + timedelta(seconds=sec, microseconds=round(nanosec / 1000))


def sendable_epoch(epoch: datetime, name: str, code: ErrorCode = ErrorCode.INVALID_EPOCH) -> datetime:
    """An epoch a message can carry: within the int32 seconds of ``builtin_interfaces/Time``
    (:data:`WIRE_EPOCH_MIN` .. :data:`WIRE_EPOCH_MAX`) and not 1970-01-01T00:00:00Z exactly (the
    zero time means "no epoch")."""
    if not WIRE_EPOCH_MIN <= epoch <= WIRE_EPOCH_MAX:
        raise RequestError(code, f"{name} {epoch.isoformat()} is outside the builtin_interfaces/Time span "
                                 f"{WIRE_EPOCH_MIN.isoformat()} .. {WIRE_EPOCH_MAX.isoformat()} (int32 seconds)")
    if epoch == UNIX_EPOCH:
        raise RequestError(code, f"{name} is 1970-01-01T00:00:00Z exactly, the zero time that means 'no epoch' on "
                                 "the wire; shift it by a microsecond")
    return epoch


def finite_array(value, name: str, code: ErrorCode, shape: tuple | None = None) -> np.ndarray:
    """A float array of ``shape`` (``-1`` for any length) with only finite entries."""
    a = np.asarray(value, dtype=float)
    if shape is not None and not _fits(a.shape, shape):
        want = "x".join("K" if s == -1 else str(s) for s in shape)
        raise RequestError(code, f"{name} has shape {'x'.join(map(str, a.shape)) or 'scalar'}; expected {want}")
    finite = all(map(math.isfinite, a.ravel().tolist())) if a.size <= 64 else np.isfinite(a).all()   # small: floats
    if not finite:
        raise RequestError(code, f"{name} has NaN or Inf entries")
    return a


def _fits(found: tuple, shape: tuple) -> bool:
    """Whether an array of shape ``found`` has ``shape`` (``-1``: any length)."""
    if found == shape or shape == (-1,) and len(found) == 1:       # the common cases first
        return True
    return len(found) == len(shape) and all(s in (-1, n) for s, n in zip(shape, found))


def peak(a: np.ndarray) -> float:
    """The largest magnitude of a 1-D array's entries (0 for none), on Python floats."""
    return max(map(abs, a.tolist()), default=0.0)


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
    components = v.tolist() if v.shape == (size,) else ()
    if not components or not all(map(math.isfinite, components)):
        raise RequestError(code, f"{name} has NaN or Inf components")
    n = math.sqrt(sum(map(mul, components, components)))   # as a dot product: a denormal's square is zero
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


def zone(value: Zone, name: str, code: ErrorCode = ErrorCode.INVALID_ZONE) -> Zone:
    """A zone's fields: text name and body, a body of :data:`~att_msgs_py.types.ZONE_BODIES`, a unit
    sensor axis, a half-angle in (0, pi) (for ``earth_limb`` the margin beyond the limb, in
    [0, pi/2)), a unit direction for an ``inertial`` zone and none for the others; the zone
    with its vectors normalised."""
    text(value.name, f"{name}.name")
    text(value.body, f"{name}.body")
    label = f"{name} ('{value.name}')"
    if value.body not in ZONE_BODIES:
        raise RequestError(code, f"{label}.body '{value.body}' is not one of {', '.join(ZONE_BODIES)}")
    axis = unit_vector(value.sensor_axis, f"{label}.sensor_axis", code)
    limb = value.body == "earth_limb"
    h = value.half_angle
    if not (math.isfinite(h) and (0.0 <= h < math.pi / 2 if limb else 0.0 < h < math.pi)):
        what = "[0, pi/2) (the margin beyond the Earth's limb)" if limb else "(0, pi)"
        raise RequestError(code, f"{label}.half_angle = {h!r} rad is outside {what}")
    direction = None
    if value.body == "inertial":
        if value.direction is None:
            raise RequestError(code, f"{label}.direction is the zero vector; an inertial zone needs a unit direction")
        direction = unit_vector(value.direction, f"{label}.direction", code)
    elif value.direction is not None:
        raise RequestError(code, f"{label}.direction is given for body '{value.body}'; only an inertial zone has "
                                 "one (send zero)")
    return Zone(value.name, value.body, axis, float(value.half_angle), bool(value.keep_in), direction)
