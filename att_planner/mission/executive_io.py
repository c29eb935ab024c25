"""What the mission executive (:mod:`att_planner.mission.executive`) takes and returns.

Events say what happened; each carries ``t``, the sim time of the latest state heard when it is
delivered, and ``q_BN``, that state's attitude of the body relative to inertial ([x, y, z, w]).
Actions say what to do; an action that awaits an answer carries the ``request`` number its answer
repeats.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from att_msgs_py.types import MissionEvent, PointingMode


@dataclass(frozen=True, kw_only=True)
class ExecutiveEvent:
    """What every event carries: the latest state heard (sim time ``t``, attitude ``q_BN``)."""

    t: float
    q_BN: np.ndarray


@dataclass(frozen=True, kw_only=True)
class Tick(ExecutiveEvent):
    """A state of the spacecraft was heard: sim time ``t`` passed."""


@dataclass(frozen=True, kw_only=True)
class EstimateHealth(ExecutiveEvent):
    """The attitude estimate became converged (or stopped being)."""

    converged: bool


@dataclass(frozen=True, kw_only=True)
class PlanReturned(ExecutiveEvent):
    """The planner's plan for request ``request``: its duration (s), method, wall time to plan (s)
    and the verified smallest margin to the zones (rad)."""

    request: int
    plan_id: str
    duration: float
    method: str = ""
    solve_seconds: float = 0.0
    min_cone_margin: float = 0.0
    pointing_after: PointingMode | None = None     # a strip's scan from the arrival, when the planner says it


@dataclass(frozen=True, kw_only=True)
class PlanRefused(ExecutiveEvent):
    """The planner refused request ``request`` with an error code."""

    request: int
    code: int
    message: str = ""


@dataclass(frozen=True, kw_only=True)
class ControllerAnswer(ExecutiveEvent):
    """The controller's answer to request ``request``: success, or an error code and message."""

    request: int
    success: bool
    code: int = 0
    message: str = ""


@dataclass(frozen=True, kw_only=True)
class ManeuverEnded(ControllerAnswer):
    """The controller's result of the maneuver started by request ``request``."""


@dataclass(frozen=True, kw_only=True)
class PointingSet(ControllerAnswer):
    """The controller's answer to the hold asked by request ``request``."""


# ---- actions (what to do) ----

@dataclass(frozen=True)
class Report:
    """Publish this mission event."""

    event: MissionEvent


@dataclass(frozen=True)
class Log:
    """Say ``text`` at sim time ``t``."""

    t: float
    text: str


@dataclass(frozen=True)
class WaitUntil:
    """Answer with a :class:`Tick` once a state at or after sim time ``t`` is heard."""

    t: float


@dataclass(frozen=True)
class RequestPlan:
    """Plan the slew from ``q_from_BN`` to ``q_to_BN`` starting at sim time ``t_start`` among the
    mission's zones where they are then, in ``time_budget`` s of wall time; answer
    :class:`PlanReturned` or :class:`PlanRefused`. With ``end_pointing`` the slew ends on that mode's
    attitude and rate at its arrival (``q_to_BN``: where the mode points about then, a first guess)."""

    request: int
    target: str
    q_from_BN: np.ndarray
    q_to_BN: np.ndarray
    t_start: float
    time_budget: float
    end_pointing: PointingMode | None = None


@dataclass(frozen=True)
class StartManeuver:
    """Fly plan ``plan_id`` (``duration`` s) now, handing over to ``pointing_after`` (None: hold its
    end); answer :class:`ManeuverEnded` when the controller reports it done."""

    request: int
    plan_id: str
    duration: float
    pointing_after: PointingMode | None = None


@dataclass(frozen=True)
class SetPointing:
    """Hold in the controller's inertial pointing mode at ``q_BN`` (None: the attitude of the
    moment); answer :class:`PointingSet`."""

    request: int
    q_BN: np.ndarray | None = None


class Awaited(NamedTuple):
    """What the executive waits for: the answer to ``action`` (of a type of ``answers``; none for a
    :class:`~.executive_io.WaitUntil`: the time) and what follows it."""

    action: object
    then: Callable
    answers: tuple = ()


RESULTS = (PlanReturned, PlanRefused, ManeuverEnded, PointingSet)
