"""The size caps of everything the suite receives, and their check on a message before it is read.

Every array and string a node receives has a declared cap here (docs/limits.md); the
field checks of the receivers (:mod:`att_msgs_py.validation`, the planner's request checks, the
controller's plan checks, the simulator's command checks) use these same constants.
:func:`check` compares the element counts of a message's fields with a table of caps (the tables
below, one per received message type) *before* the message is converted to numpy or planned
with: the cost of refusing a message is a ``len()`` per field, whatever its size, so an oversized
request is answered at once and nothing of it is kept (a refused message is never converted). A
field over its cap is refused as SIZE_LIMIT with a sentence naming the field, its count and the cap.

A table maps a field path to its cap: ``"zones"`` (a sequence or a string of the message),
``"header.frame_id"`` (a nested field), ``"zones[].name"`` (that field of every element, checked
after the sequence's own count, so at most the sequence's cap of elements is visited). Nothing here
imports ROS: any object with the message's attributes is checked.
"""
from __future__ import annotations

from collections.abc import Mapping

from att_msgs_py.errors import ErrorCode, RequestError

MAX_NAME_LENGTH = 128          # names, ids and frames
MAX_TEXT_LENGTH = 1000         # free text (plan messages, estimator notes)
MAX_PLAN_SAMPLES = 20_000      # knots of a plan (about 1.8 MB on the wire)
MAX_PLAN_BYTES = 4 * 1024 * 1024   # serialized ManeuverPlan
MAX_CONES = 16                 # keep-out cones of a request or a plan
MAX_ZONES = 16                 # zones of a request or a plan (besides its cones): each is a constraint at every sample
MAX_OPTIONS = 16               # method options of a request
MAX_TARGETS = 20               # schedule targets (the order search is exponential in their number)
MAX_TLE_LENGTH = 80            # characters of a TLE line (69 are used; trailing blanks are dropped)
MAX_WHEELS = 16                # reaction wheels of a state, command, reset or wheel speed measurement
MAX_SUN_SENSORS = 64           # coarse sun sensor cells of one measurement
MAX_SIGNATURE_BYTES = 256      # a plan's or a mode request's signature (Ed25519: 64)

_HEADER = {"header.frame_id": MAX_NAME_LENGTH}
_ZONES = {"zones": MAX_ZONES, "zones[].name": MAX_NAME_LENGTH, "zones[].body": MAX_NAME_LENGTH}
_POINTING = {"kind": MAX_NAME_LENGTH, "secondary": MAX_NAME_LENGTH}


def _under(prefix: str, table: Mapping[str, int]) -> dict[str, int]:
    """``table`` for the field ``prefix`` of a message (``"plan."``)."""
    return {prefix + path: cap for path, cap in table.items()}


PLAN_MANEUVER = {**_HEADER, "cones": MAX_CONES, "cones[].name": MAX_NAME_LENGTH, "method": MAX_NAME_LENGTH,
                 "spacecraft": MAX_NAME_LENGTH, "option_names": MAX_OPTIONS, "option_values": MAX_OPTIONS,
                 "option_names[]": MAX_NAME_LENGTH, **_ZONES, "tle_line1": MAX_TLE_LENGTH,
                 "tle_line2": MAX_TLE_LENGTH, "wheel_speeds": MAX_WHEELS, "healthy_wheels": MAX_WHEELS,
                 **_under("end_pointing.", _POINTING)}
PLAN_SCHEDULE = {**_HEADER, "target_names": MAX_TARGETS, "targets": MAX_TARGETS, "target_names[]": MAX_NAME_LENGTH,
                 "spacecraft": MAX_NAME_LENGTH, **_ZONES, "tle_line1": MAX_TLE_LENGTH, "tle_line2": MAX_TLE_LENGTH,
                 "dwell_times": MAX_TARGETS, "window_opens": MAX_TARGETS, "window_closes": MAX_TARGETS}
IMAGE_TARGET = {**_HEADER, "method": MAX_NAME_LENGTH, "spacecraft": MAX_NAME_LENGTH, "wheel_speeds": MAX_WHEELS,
                **_ZONES}
IMAGE_STRIP = IMAGE_TARGET
MANEUVER_PLAN = {**_HEADER, "plan_id": MAX_NAME_LENGTH, "method": MAX_NAME_LENGTH, "status": MAX_NAME_LENGTH,
                 "message": MAX_TEXT_LENGTH, "spacecraft": MAX_NAME_LENGTH, "control_kind": MAX_NAME_LENGTH,
                 "interpolation": MAX_NAME_LENGTH, "times": MAX_PLAN_SAMPLES, "attitudes": MAX_PLAN_SAMPLES,
                 "rates": MAX_PLAN_SAMPLES, "torques": MAX_PLAN_SAMPLES, "cones": MAX_CONES,
                 "cones[].name": MAX_NAME_LENGTH, **_ZONES, "verification.cone_margins": MAX_CONES + MAX_ZONES,
                 "spacecraft_digest": MAX_NAME_LENGTH, "key_id": MAX_NAME_LENGTH,
                 "signature": MAX_SIGNATURE_BYTES}
EXECUTE_MANEUVER = {"plan_id": MAX_NAME_LENGTH, **_under("pointing_after.", _POINTING)}   # + plan when inline
SET_CONTROLLER_MODE = {**_under("pointing.", _POINTING), "key_id": MAX_NAME_LENGTH, "signature": MAX_SIGNATURE_BYTES}
SPACECRAFT_STATE = {**_HEADER, "body_frame_id": MAX_NAME_LENGTH, "wheel_speeds": MAX_WHEELS,
                    "wheel_torques": MAX_WHEELS}
ATTITUDE_ESTIMATE = {**_HEADER, "body_frame_id": MAX_NAME_LENGTH, "message": MAX_TEXT_LENGTH}
ACTUATOR_COMMAND = {**_HEADER, "wheel_torques": MAX_WHEELS, "plan_id": MAX_NAME_LENGTH}
RESET_SIMULATOR = {"wheel_speeds": MAX_WHEELS}
INJECT_FAULT = {"component": MAX_NAME_LENGTH, "kind": MAX_NAME_LENGTH, "bias_rad": 3}
JOINT_STATE = {**_HEADER, "name": MAX_WHEELS, "name[]": MAX_NAME_LENGTH, "position": MAX_WHEELS,
               "velocity": MAX_WHEELS, "effort": MAX_WHEELS}
STAR_TRACKER = {**_HEADER, "sensor_frame_id": MAX_NAME_LENGTH}
SUN_SENSORS = {**_HEADER, "values": MAX_SUN_SENSORS}
HEADER_ONLY = _HEADER          # Imu, MagneticField: fixed-size fields besides their header
FAULT_STATUS = {**_HEADER, "fault_id": MAX_NAME_LENGTH, "component": MAX_NAME_LENGTH, "detector": MAX_NAME_LENGTH,
                "evidence": 400, "response": MAX_NAME_LENGTH}


def inline_plan(table: Mapping[str, int] = EXECUTE_MANEUVER) -> dict[str, int]:
    """An ExecuteManeuver goal's caps with its inline plan's (``plan.`` + :data:`MANEUVER_PLAN`)."""
    return {**table, **_under("plan.", MANEUVER_PLAN)}


def _values(obj, path: str) -> list:
    """The values at ``path`` of ``obj`` (one, or one per element after a ``[]``)."""
    values = [obj]
    for part in path.split("."):
        each = part.endswith("[]")
        name = part[:-2] if each else part
        values = [getattr(v, name) for v in values] if name else values
        if each:
            values = [e for v in values for e in v]
    return values


def issue(msg, table: Mapping[str, int], what: str = "") -> RequestError | None:
    """The first field of ``msg`` above its cap in ``table`` (SIZE_LIMIT naming ``what.field``), or None."""
    for path, cap in table.items():
        for value in _values(msg, path):
            n = len(value)
            if n > cap:
                unit = "characters" if isinstance(value, str) else "bytes" if isinstance(value, bytes) else "entries"
                name = f"{what}.{path}" if what else path
                return RequestError(ErrorCode.SIZE_LIMIT, f"{name} has {n} {unit}; at most {cap}")
    return None


def check(msg, table: Mapping[str, int], what: str = "") -> None:
    """Raise :func:`issue`'s RequestError, if any."""
    err = issue(msg, table, what)
    if err is not None:
        raise err
