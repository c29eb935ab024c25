"""A requested pointing mode turned into a pointing law, checked field by field (no ROS).

:func:`law_of` validates a :class:`att_msgs_py.types.PointingMode` as every input of the suite
(:mod:`att_msgs_py.validation`): a known kind and secondary, unit body axes that are not parallel,
finite angles in range (latitude in [−π/2, π/2], longitude and yaw in [−π, π], altitude in
[−500 m, 100 km]), a unit inertial direction where one is needed, a quaternion within 1e-3 of unit
norm (or all zero: the current attitude); then builds the law of :mod:`.laws` on the onboard
:class:`.laws.PointingGeometry` and checks it has an attitude now (the primary and secondary
directions not parallel).
Every refusal is :class:`~att_msgs_py.errors.RequestError` 314 INVALID_POINTING naming the field.
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import POINTING_KINDS, SECONDARY_KINDS, PointingMode
from att_planner.guidance.laws import (
    FixedAttitude,
    PointingGeometry,
    TwoVectorLaw,
    directions,
    ground_line_of_sight,
    two_vector_attitude,
)

BAD = ErrorCode.INVALID_POINTING
MIN_ALTITUDE = -500.0          # m: the shores of the Dead Sea are at -430 m
MAX_ALTITUDE = 100e3           # m: a ground target is on the ground (or a mountain, or a balloon)


def _axis(value, name: str) -> np.ndarray:
    return validation.unit_vector(validation.finite_array(value, name, BAD, (3,)), name, BAD)


def _angle(value, name: str, low: float, high: float) -> float:
    return validation.number(value, name, BAD, low, high)


def law_of(mode: PointingMode, geometry: PointingGeometry, t: float, q_BN: np.ndarray):
    """The pointing law of ``mode`` on ``geometry``, with an attitude at ``t`` (``q_BN``: the current
    body attitude, held by an inertial mode without one); RequestError 314 otherwise."""
    kind = validation.text(mode.kind, "pointing.kind", BAD)
    if kind not in POINTING_KINDS:
        raise RequestError(BAD, f"pointing.kind '{kind[:40]}' is not one of {', '.join(POINTING_KINDS)}")
    if kind == "inertial":
        q = validation.finite_array(mode.attitude, "pointing.attitude", BAD, (4,))
        return FixedAttitude(np.array(q_BN, float) if not np.any(q) else
                             validation.unit_quaternion(q, "pointing.attitude", BAD))
    primary_axis = _axis(mode.primary_axis, "pointing.primary_axis")
    secondary_axis = _axis(mode.secondary_axis, "pointing.secondary_axis")
    yaw = _angle(mode.yaw, "pointing.yaw", -math.pi, math.pi)
    named = directions(geometry)
    if kind == "ground":
        primary = ground_line_of_sight(geometry,
                                       _angle(mode.latitude, "pointing.latitude", -math.pi / 2, math.pi / 2),
                                       _angle(mode.longitude, "pointing.longitude", -math.pi, math.pi),
                                       _angle(mode.altitude, "pointing.altitude", MIN_ALTITUDE, MAX_ALTITUDE))
    elif kind == "inertial_target":
        target = _axis(mode.target_direction, "pointing.target_direction")
        primary = lambda t: target                                  # noqa: E731
    elif kind == "sun" and "sun" not in named:
        raise RequestError(BAD, "pointing.kind sun needs the scenario's epoch (the Sun's position)")
    else:
        primary = named[kind]
    secondary = _secondary(mode, named)
    law = TwoVectorLaw(kind, primary_axis, secondary_axis, primary, secondary, yaw)
    try:
        two_vector_attitude(primary_axis, secondary_axis, primary(t), secondary(t))
    except ValueError as err:
        raise RequestError(BAD, f"pointing: {err} (primary {kind}, secondary {mode.secondary}) now") from None
    return law


def _secondary(mode: PointingMode, named: dict):
    which = validation.text(mode.secondary, "pointing.secondary", BAD)
    if which not in SECONDARY_KINDS:
        raise RequestError(BAD, f"pointing.secondary '{which[:40]}' is not one of {', '.join(SECONDARY_KINDS)}")
    if which == "inertial":
        direction = _axis(mode.secondary_direction, "pointing.secondary_direction")
        return lambda t: direction
    if which not in named:
        raise RequestError(BAD, f"pointing.secondary {which} needs the scenario's epoch (the Sun's position)")
    return named[which]
