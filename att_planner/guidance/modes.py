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
from att_planner.guidance.strip import MAX_SCAN_SPEED_M_S, Strip, StripLaw

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
    if kind == "strip":
        return _strip_law(mode, geometry, t, primary_axis, secondary_axis, yaw)
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


def _strip_law(mode: PointingMode, geometry: PointingGeometry, t: float, primary_axis, secondary_axis,
               yaw: float) -> StripLaw:
    """The law of a strip mode (the strip between its two points at the mode's altitude, scanned from
    ``scan_start``), with an attitude at ``t``."""
    lat0 = _angle(mode.latitude, "pointing.latitude", -math.pi / 2, math.pi / 2)
    lon0 = _angle(mode.longitude, "pointing.longitude", -math.pi, math.pi)
    lat1 = _angle(mode.end_latitude, "pointing.end_latitude", -math.pi / 2, math.pi / 2)
    lon1 = _angle(mode.end_longitude, "pointing.end_longitude", -math.pi, math.pi)
    altitude = _angle(mode.altitude, "pointing.altitude", MIN_ALTITUDE, MAX_ALTITUDE)
    speed = validation.number(mode.scan_speed, "pointing.scan_speed", BAD, 0.0, MAX_SCAN_SPEED_M_S)
    scan_start = validation.number(mode.scan_start, "pointing.scan_start", BAD, -math.inf, math.inf)
    if speed == 0.0:
        raise RequestError(BAD, "pointing.scan_speed: a strip is scanned at a speed > 0 m/s, not 0")
    if yaw != 0.0:
        raise RequestError(BAD, f"pointing.yaw: a strip's law keeps the detector along the strip; yaw is 0, "
                                f"not {yaw:.6g} rad")
    if np.linalg.norm(np.cross(primary_axis, secondary_axis)) < 1e-3:
        raise RequestError(BAD, "pointing.secondary_axis is parallel to pointing.primary_axis: the detector's "
                                "along-track axis must lie across the boresight")
    try:
        strip = Strip.between(lat0, lon0, lat1, lon1, altitude, speed)
    except ValueError as err:
        raise RequestError(BAD, f"pointing.end_latitude, pointing.end_longitude: {err}") from None
    law = StripLaw(geometry, strip, primary_axis, secondary_axis, scan_start)
    if not np.all(np.isfinite(law.attitude(t))):
        raise RequestError(BAD, "pointing: the strip's aim point has no attitude now")
    return law


def strip_mode(strip: Strip, primary_axis, secondary_axis, scan_start: float) -> PointingMode:
    """The pointing mode of ``strip`` scanned from sim time ``scan_start`` (s) with the boresight
    ``primary_axis`` and the detector's along-track axis ``secondary_axis`` (body axes): what a
    controller hands over to at the end of a slew onto the strip."""
    (lat0, lon0), (lat1, lon1) = strip.geodetic(0.0), strip.geodetic(strip.length_m)
    return PointingMode("strip", primary_axis=np.asarray(primary_axis, float),
                        secondary_axis=np.asarray(secondary_axis, float), latitude=lat0, longitude=lon0,
                        altitude=strip.altitude_m, end_latitude=lat1, end_longitude=lon1,
                        scan_speed=strip.scan_speed_m_s, scan_start=float(scan_start))


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
