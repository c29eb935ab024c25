"""Slews that end on a moving target (issue 15): the goal of a maneuver request with ``end_pointing``.

The plan must reach, at its final time, the attitude and body rate of the pointing law the
controller will hand over to (:mod:`att_planner.guidance`): the law of the scenario's own models
(orbit, field, Sun — the controller's), at sim time ``offset + t`` for plan time ``t``, ``offset``
the plan's epoch after the scenario's. :class:`MovingGoal` holds the law and its Chebyshev series
over the problem's window: the time-optimal method meets the series exactly at t_f
(:func:`att_planner.methods.time_optimal.model.moving_goal_values`, in a child process the series
is all it gets), the verification measures against the law itself.
"""
from __future__ import annotations

from collections.abc import Callable
from datetime import datetime

import numpy as np

from att_msgs_py.types import PointingMode
from att_planner.guidance import reference
from att_planner.guidance.laws import Sky
from att_planner.guidance.modes import law_of
from att_planner.zones import clenshaw
from att_sim import world
from att_sim.scenario import Scenario

DEGREE = 16              # of the series of the attitude (sign-continuous) and the rate


class MovingGoal:
    """``t ↦ (q, ω)``: the law (in this process) or its series over ``[0, window]`` (after pickling)."""

    def __init__(self, law: Callable[[float], tuple[np.ndarray, np.ndarray]], window: float):
        self.law, self.window = law, float(window)
        n = 2 * (DEGREE + 1)
        x = np.sort(np.cos(np.pi * (np.arange(n) + 0.5) / n))         # Chebyshev points of the first kind
        samples = []
        for t in 0.5 * (x + 1.0) * self.window:
            q, w = law(float(t))
            if samples and np.dot(q, samples[-1][:4]) < 0:
                q = -q
            samples.append(np.concatenate([q, w]))
        self.coefficients = np.polynomial.chebyshev.chebfit(x, np.array(samples), DEGREE)   # (DEGREE + 1, 7)

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        if self.law is not None:
            return self.law(t)
        value = clenshaw(np.array([[2.0 * t / self.window - 1.0]]), list(self.coefficients))[0]
        return value[:4] / np.linalg.norm(value[:4]), value[4:]

    def __getstate__(self) -> dict:
        return {**self.__dict__, "law": None}          # the law's sky does not travel: its series does


def goal_law(mode: PointingMode, scenario: Scenario, epoch: datetime | None,
             q_start: np.ndarray) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
    """``t ↦ (q, ω)`` of ``mode``'s law at plan time ``t`` (RequestError 314 for a bad mode)."""
    offset = 0.0 if epoch is None or scenario.epoch is None else (epoch - scenario.epoch).total_seconds()
    law = law_of(mode, Sky.of(world.Environment.from_scenario(scenario)), offset, q_start)

    def motion(t: float) -> tuple[np.ndarray, np.ndarray]:
        ref = reference(law.attitude, offset + t)
        return ref.q, ref.omega

    return motion
