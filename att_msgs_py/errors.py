"""Error codes of every suite service and action (listed in README "Errors and limits").

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
    SIZE_LIMIT = 132              # arrays or cone lists above the documented caps
    INVALID_TIME_BUDGET = 140
    # planner: solving
    SOLVER_FAILED = 200           # the method failed and no fallback plan was possible
    VERIFICATION_FAILED = 201     # the plan did not survive integration through the dynamics
    # controller
    UNKNOWN_PLAN = 300
    INVALID_PLAN = 301
    BUSY = 302                    # a maneuver is executing: mode change or second goal refused
    INVALID_MODE = 303
    NO_STATE = 304                # no recent spacecraft state
    ABORTED = 305                 # maneuver cancelled or stopped by safe mode
    # simulator
    INVALID_RESET = 400


class RequestError(ValueError):
    """A request rejected before any numerics: an error code and a sentence naming the field."""

    def __init__(self, code: ErrorCode, message: str):
        super().__init__(message)
        self.code = ErrorCode(code)
        self.message = message
