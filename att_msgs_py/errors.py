"""Error codes of every suite service and action (their meanings: :mod:`att_msgs_py.error_meanings`).

A rejected request carries one of these codes and a sentence naming the field and the reason.
"""
from __future__ import annotations

from enum import IntEnum


class ErrorCode(IntEnum):
    OK = 0
    # planner: request validation
    INVALID_ATTITUDE = 100        # NaN/Inf, zero or far-from-unit quaternion
    INVALID_FRAME = 101           # header.frame_id is not the planner's inertial frame
    INVALID_SENSOR_AXIS = 110     # zero, non-finite or non-unit sensor axis / sensor target
    INVALID_CONE = 111            # bad cone direction or half-angle
    SENSOR_IN_CONE = 112          # start or goal boresight inside a keep-out cone
    INFEASIBLE = 113              # the cones leave no path / the method found none
    INVALID_SPACECRAFT = 120      # inertia not SPD / triangle inequality, limits <= 0
    UNKNOWN_SPACECRAFT = 121      # no such configuration
    UNKNOWN_METHOD = 130
    INVALID_OPTION = 131          # option name unknown or value out of range
    SIZE_LIMIT = 132              # arrays, samples, cone lists or strings above the documented caps
    INVALID_TEXT = 133            # a string with control characters (or not UTF-8)
    INVALID_TIME_BUDGET = 140
    # planner: the real sky (epoch, orbit, moving zones)
    INVALID_EPOCH = 150           # an epoch that does not parse, or outside the ephemeris span (1900-2050)
    INVALID_ORBIT = 151           # a TLE that fails to parse or its checksum, bad Keplerian elements
    ORBIT_TOO_LOW = 152           # the orbit decays or is below 150 km during the maneuver
    INVALID_ZONE = 153            # an unknown body, a bad sensor axis, half-angle or direction of a zone
    ZONE_AT_END = 154             # the start or goal violates a zone (keep-out entered / keep-in left)
    CONTRADICTORY_ZONES = 155     # zones no direction can satisfy together (e.g. keep-in inside keep-out)
    INVALID_WHEEL_SPEEDS = 160    # wheel_speeds of the wrong length, not finite, or beyond the wheels' limit
    INVALID_OBSERVATION = 161     # a schedule's dwell or window: wrong length, not finite, negative, or too short
    INVALID_SITE = 162            # an imaging site or strip: NaN/Inf, out of range, zero length, absurd scan speed
    SITE_NOT_VISIBLE = 163        # the site or strip is below the minimum elevation where it would be imaged
    INVALID_WHEEL_SET = 164       # healthy_wheels of the wrong length, or wheels that cannot control the attitude
    # planner: solving
    SOLVER_FAILED = 200           # the method failed and no fallback plan was possible
    VERIFICATION_FAILED = 201     # the plan did not survive integration through the dynamics
    WHEEL_SATURATION = 202        # no slower plan keeps every wheel within its speed limit
    # controller
    UNKNOWN_PLAN = 300
    INVALID_PLAN = 301
    BUSY = 302                    # a maneuver is executing: mode change or second goal refused
    INVALID_MODE = 303
    NO_STATE = 304                # no recent spacecraft state
    ABORTED = 305                 # maneuver cancelled, stopped by safe mode, or its controller fell silent
    PLAN_NOT_AUTHENTIC = 306      # no signature, an unknown key, or a signature that does not verify
    PLAN_ID_REUSED = 307          # a plan id already taken by a different plan
    WRONG_SPACECRAFT = 308        # a plan made for another spacecraft configuration
    PLAN_CONTEXT = 309            # the plan starts far from the current attitude, rate or its instant
    INVALID_STATE = 310           # a state message with a bad field (discarded, reported)
    STATE_TIME_JUMP = 311         # a state stamp backward or far forward (discarded, reported)
    MODE_NOT_AUTHENTIC = 312      # a mode request unsigned, wrongly signed or replayed (require_signed_modes)
    ESTIMATE_UNHEALTHY = 313      # state_source estimate: the attitude estimate is not usable (initialising, diverged)
    INVALID_POINTING = 314        # a pointing mode with a bad field (kind, axes, target) or no attitude now
    # estimator
    INVALID_MEASUREMENT = 320     # a sensor message with a bad field (discarded, reported)
    STALE_MEASUREMENT = 321       # a measurement older than the filter's history, or a gyro stamp not moving forward
    INVALID_FAULT_REPORT = 322    # a fault report of a fault the table does not declare, or with another response
    # simulator
    INVALID_RESET = 400
    INVALID_COMMAND = 401         # actuator command with a bad field or stamp (refused, reported)
    COMMAND_LIMIT = 402           # actuator command far beyond its limit (refused, reported)
    INVALID_FAULT = 403           # a fault to inject with a bad field (component, index, kind, parameter, time)
    FAULT_INJECTION_DISABLED = 404  # a fault injection request to a scenario without allow_fault_injection
    # nodes and tools: configuration
    INVALID_PARAMETER = 500       # a parameter of the wrong type or out of range
    INVALID_CONFIG = 501          # an unknown scenario, a YAML that is not a scenario, a missing file
    VERSION_MISMATCH = 502        # a Dask worker of a campaign runs another suite version than its client


MAX_MESSAGE_LENGTH = 400       # characters of a refusal message or a log line (longer: clipped)


def clip(text: str, limit: int = MAX_MESSAGE_LENGTH) -> str:
    """``text`` cut to ``limit`` characters (a refusal or log line never grows with its input)."""
    text = str(text)
    return text if len(text) <= limit else text[: limit - 15] + f"... (+{len(text) - limit + 15} chars)"


class RequestError(ValueError):
    """A request rejected before any numerics: an error code and a sentence naming the field."""

    def __init__(self, code: ErrorCode, message: str):
        message = clip(message)
        super().__init__(message)
        self.code = ErrorCode(code)
        self.message = message


class ConfigError(RequestError):
    """A parameter or configuration file that cannot be used: one line naming it and what is
    expected (nodes print it and exit 2, without a traceback)."""
