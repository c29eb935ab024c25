"""Checks of every measurement the estimator receives (no ROS): nothing on the bus is trusted.

Each check takes a measurement as :mod:`att_msgs_py.convert` read it and returns what the filter
uses, or raises :class:`~att_msgs_py.errors.RequestError`: 320 INVALID_MEASUREMENT (a field NaN/Inf,
of the wrong size or frame, a tracker quaternion off unit norm by more than 1e-3, an unknown
tracker, a field or rate beyond what a sensor can output) or 321 STALE_MEASUREMENT (a gyro stamp
that does not move forward). A quaternion within 1e-3 of unit norm is normalised.
"""
from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Mapping

import numpy as np

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.source_hold import Live, SourceHold
from att_msgs_py.types import GyroMeasurement, MagnetometerMeasurement, StarTrackerMeasurement, SunSensorMeasurement
from att_sim.models.sensor_specs import SensorSpecs

BAD = ErrorCode.INVALID_MEASUREMENT
MAX_RATE = 100.0          # rad/s: no gyro outputs more
MAX_FIELD = 1e-3          # T: the geomagnetic field is below 7e-5 T
SATURATION = 0.999        # of the range: a sample at or beyond it is saturated


def _time(t: float, what: str) -> float:
    if not (isinstance(t, float | int) and math.isfinite(t) and t >= 0):
        raise RequestError(BAD, f"{what} stamp {t!r} is not a finite time >= 0")
    return float(t)


class InputChecks:
    def __init__(self, specs: SensorSpecs, frame_id: str, body_frame_id: str):
        self.specs, self.frame_id, self.body_frame_id = specs, frame_id, body_frame_id

    def _frame(self, got: str, want: str, what: str) -> None:
        if got != want:
            raise RequestError(BAD, f"{what} header.frame_id '{str(got)[:64]}' is not '{want}'")

    def gyro(self, m: GyroMeasurement, last_t: float | None) -> tuple[np.ndarray, bool]:
        """The measured rate and whether it saturates (any axis at its range)."""
        t = _time(m.t, "gyro")
        self._frame(m.frame_id, self.body_frame_id, "gyro")
        omega = validation.finite_array(m.omega, "gyro angular_velocity", BAD, (3,))
        peak = validation.peak(omega)
        if peak > MAX_RATE:
            raise RequestError(BAD, f"gyro angular_velocity reaches {peak:.6g} rad/s; at most {MAX_RATE:g}")
        if last_t is not None and t <= last_t:
            raise RequestError(ErrorCode.STALE_MEASUREMENT, f"gyro stamp {t:.6g} s does not follow the last one "
                                                            f"({last_t:.6g} s)")
        limit = self.specs.gyro.range if self.specs.gyro is not None else math.inf
        return omega, peak >= SATURATION * limit

    def star_tracker(self, m: StarTrackerMeasurement) -> np.ndarray | None:
        """The sensor attitude of a valid measurement (None for an invalid one)."""
        _time(m.t, "star tracker")
        self._frame(m.frame_id, self.frame_id, "star tracker")
        names = [s.name for s in self.specs.star_trackers]
        if m.name not in names:
            raise RequestError(BAD, f"star tracker '{str(m.name)[:64]}' is not one of this spacecraft's "
                                    f"({', '.join(names) or 'none'})")
        if not isinstance(m.valid, bool | np.bool_):
            raise RequestError(BAD, "star tracker valid is not a bool")
        if not m.valid:
            return None
        q = validation.unit_quaternion(validation.finite_array(m.q, "star tracker attitude", BAD, (4,)),
                                       "star tracker attitude", BAD)
        validation.finite_array(m.covariance, "star tracker covariance", BAD, (3, 3))
        return q

    def magnetometer(self, m: MagnetometerMeasurement) -> np.ndarray:
        _time(m.t, "magnetometer")
        self._frame(m.frame_id, self.body_frame_id, "magnetometer")
        b = validation.finite_array(m.field, "magnetometer magnetic_field", BAD, (3,))
        if not 0.0 < np.linalg.norm(b) <= MAX_FIELD:
            raise RequestError(BAD, f"magnetometer magnetic_field is {np.linalg.norm(b):.3g} T; expected (0, "
                                    f"{MAX_FIELD:g}] T")
        if self.specs.magnetometer is None:
            raise RequestError(BAD, "this spacecraft has no magnetometer")
        return b

    def sun_sensors(self, m: SunSensorMeasurement) -> np.ndarray:
        _time(m.t, "sun sensors")
        self._frame(m.frame_id, self.body_frame_id, "sun sensors")
        if self.specs.sun_sensors is None:
            raise RequestError(BAD, "this spacecraft has no sun sensors")
        n = len(self.specs.sun_sensors.normals)
        values = validation.finite_array(m.values, "sun sensor values", BAD, (n,))
        if np.any(values < 0) or np.any(values > 2.0):
            raise RequestError(BAD, "sun sensor values must lie in [0, 2] (1 at normal incidence)")
        return values


class DipoleLog:
    """The magnetorquer commands issued (stamp, whether any coil was on): a magnetometer sample is
    clean when the last command stamped before it commanded no dipole (the coils were off over the
    step it ends). Without a command on record every sample is clean."""

    def __init__(self, size: int = 256):
        self.commands: deque[tuple[float, bool]] = deque(maxlen=size)

    def record(self, t: float, dipole) -> None:
        self.commands.append((float(t), any(np.asarray(dipole, float).tolist())))     # NaN counts as on, as numpy's

    def clean(self, t: float) -> bool:
        on = next((on for stamp, on in reversed(self.commands) if stamp < t - 1e-9), False)   # the last before t
        return not on


class Sources:
    """One publisher per input kind (:class:`~att_msgs_py.source_hold.SourceHold`): a message from
    a publisher other than the held one of its kind is refused while the held one is in the ROS graph,
    however long it is silent; once it has left the graph the next accepted one is held (a
    restarted sensor or simulator). ``live`` maps each kind to its topic's publishers in the graph."""

    def __init__(self, live: Mapping[str, Live] | None = None):
        self.live = dict(live or {})
        self.holds: dict[str, SourceHold] = {}

    def hold(self, kind: str) -> SourceHold:
        if kind not in self.holds:
            self.holds[kind] = SourceHold(self.live.get(kind))
        return self.holds[kind]

    def guarded(self, kind: str, source: bytes | None, call: Callable, *args):
        """``call(*args)`` (a core input that raises RequestError when it refuses) if ``source`` may
        give ``kind``; ``source`` is held once the call accepted it. RequestError (320) for a
        second publisher while the held one is in the graph."""
        hold = self.hold(kind)
        if not hold.check(source).admitted:
            raise RequestError(BAD, hold.refusal(kind))
        result = call(*args)
        hold.take(source)
        return result
