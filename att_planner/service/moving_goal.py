"""Slews that end on a moving target: the goal of a maneuver request with ``end_pointing``.

The plan must reach, at its final time, the attitude and body rate of the pointing law the
controller will hand over to (:mod:`att_planner.guidance`): the law of the scenario's own models
(orbit, field, Sun — the controller's), at sim time ``offset + t`` for plan time ``t``, ``offset``
the plan's epoch after the scenario's (a scenario without an epoch: after the wire's zero time, as
the suite stamps its messages with the sim time); a ground site's attitude and rate in closed form from its line
of sight and the line of sight's derivative (:mod:`att_planner.guidance.ground_arrival`), every other
law's rate by the central differences of :func:`att_planner.guidance.reference`; a strip's first
point at the scan's rate (:func:`att_planner.guidance.strip.strip_start_goal`, :func:`strip_goal_law`).
:class:`att_planner.problem.MovingGoal` holds the law and its Chebyshev series
over the problem's window: the time-optimal method meets the series exactly at t_f
(:func:`att_planner.methods.time_optimal.model.moving_goal_values`, in a child process the series
is all it gets), the verification measures against the law itself.
"""
from __future__ import annotations

from collections.abc import Callable
from datetime import datetime

import numpy as np

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import PointingMode
from att_msgs_py.validation import UNIX_EPOCH
from att_planner.guidance import reference
from att_planner.guidance.ground_arrival import ground_motion
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.guidance.strip import Strip, strip_start_goal
from att_sim.models import world
from att_sim.models.scenario import Scenario


def onboard_geometry(scenario: Scenario, epoch: datetime | None) -> tuple[PointingGeometry, float]:
    """The scenario's onboard pointing geometry and the request's ``offset`` (s): sim time of plan time 0."""
    offset = 0.0 if epoch is None else (epoch - (scenario.epoch or UNIX_EPOCH)).total_seconds()
    return PointingGeometry.of(world.Environment.from_scenario(scenario)), offset


def goal_law(mode: PointingMode, scenario: Scenario, epoch: datetime | None,
             q_start: np.ndarray) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
    """``t ↦ (q, ω)`` of ``mode``'s law at plan time ``t`` (RequestError 314 for a bad mode)."""
    if mode.kind == "strip":
        raise RequestError(ErrorCode.INVALID_POINTING, "end_pointing.kind strip: a slew onto a strip is asked "
                                                       "with ImageStrip (its scan starts at the arrival)")
    geometry, offset = onboard_geometry(scenario, epoch)
    law = law_of(mode, geometry, offset, q_start)
    if mode.kind == "ground":
        ground = ground_motion(geometry, mode.latitude, mode.longitude, mode.altitude, law.primary_B,
                               law.secondary_B, law.secondary_N, law.yaw)
        return lambda t: ground(offset + t)

    def motion(t: float) -> tuple[np.ndarray, np.ndarray]:
        ref = reference(law.attitude, offset + t)
        return ref.q_RN, ref.omega_RN_R

    return motion


def strip_goal_law(strip: Strip, scenario: Scenario, epoch: datetime | None, primary_B, secondary_B
                   ) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
    """``t ↦ (q, ω)`` at plan time ``t``: the strip's first point at its scan's rate, the scan starting at ``t``."""
    geometry, offset = onboard_geometry(scenario, epoch)
    goal = strip_start_goal(geometry, strip, primary_B, secondary_B)
    return lambda t: goal(offset + t)
