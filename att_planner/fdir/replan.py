"""The brake before a re-plan after a wheel loss (no ROS): the one policy of the in-process recovery and the node.

When the healthy wheels change during a maneuver, :meth:`Brake.begin` ends it and holds the estimated
attitude at rest on the healthy wheels (:meth:`att_planner.control.controller.Controller.hold`, the
allocation already on them); :meth:`Brake.poll`, at each step, says when the estimated rate is below
half the controller's start tolerance (``max_start_rate_error``: the plan from rest will start) and
the rest of the maneuver can be planned for the healthy wheels' envelope, or that braking took longer
than :data:`BRAKE_LIMIT_S` (safe mode). :func:`utc_epoch` is the epoch (s, ns) of a sim time, which a
re-plan among the real sky's zones starts at. The why is in docs/decisions/replan-after-wheel-loss.md;
the in-process flight (:mod:`att_planner.tools.fault_flight`) plans in its process, the controller node
asks the planner service with the healthy wheels (``PlanManeuver.healthy_wheels``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime, timedelta

import numpy as np

from att_msgs_py.types import ControlMode, ManeuverResult

BRAKE_LIMIT_S = 120.0     # s of sim time the hold may take to bring the rate under the start tolerance
HOLD_MESSAGE = "a wheel isolated: braking to re-plan on the healthy wheels"

WAIT, REPLAN, SAFE, IDLE = "wait", "replan", "safe", "idle"     # what :meth:`Brake.poll` says


@dataclass
class Brake:
    """The brake in progress (``since``: its start in sim time, None: not braking) and why it gave up."""

    since: float | None = None
    why: str = ""

    def begin(self, controller, t: float) -> ManeuverResult | None:
        """Hold the latest attitude on the healthy wheels from sim time ``t`` (the maneuver in flight
        ended: its result); nothing in safe mode (its own law flies)."""
        if controller.mode == ControlMode.SAFE:
            return None
        self.since = t
        return controller.hold(HOLD_MESSAGE)

    def poll(self, controller, t: float) -> str:
        """At sim time ``t``: :data:`REPLAN` once braked (the brake ends), :data:`SAFE` when braking
        took over :data:`BRAKE_LIMIT_S` (``why`` says so; the brake ends), :data:`WAIT` while braking,
        :data:`IDLE` when not braking (or safe mode took over meanwhile: the brake ends)."""
        if self.since is None or controller.state is None:
            return IDLE
        if controller.mode == ControlMode.SAFE:
            self.since = None
            return IDLE
        rate = float(np.linalg.norm(controller.state.omega))
        if rate > 0.5 * controller.context.max_start_rate_error:
            if t - self.since > BRAKE_LIMIT_S:
                self.since, self.why = None, f"the rate stayed at {rate:.3g} rad/s for {BRAKE_LIMIT_S:g} s of braking"
                return SAFE
            return WAIT
        self.since = None
        return REPLAN


def utc_epoch(epoch: datetime | None, t: float) -> tuple[int, int]:
    """(s, ns) since 1970 of sim time ``t`` after the scenario's ``epoch`` ((0, 0): no epoch)."""
    if epoch is None:
        return 0, 0
    at = (epoch + timedelta(seconds=float(t))).timestamp()
    return math.floor(at), round((at - math.floor(at)) * 1e9)
