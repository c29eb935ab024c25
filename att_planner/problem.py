"""The planner's plain-data request and result types (no ROS).

Every maneuver method is a pure function ``plan(problem: ManeuverProblem, **options) ->
ManeuverPlan``, in the style of ``scipy.optimize``: it takes a problem and options and returns a
result object with the solution, a status, a message and statistics. The planner node converts
messages to a :class:`ManeuverProblem`, calls the method, verifies the plan with
:mod:`att_planner.verify` and converts back.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from att_planner.cones import Cone
from att_sim.dynamics import Spacecraft


@dataclass
class ManeuverProblem:
    """Rest-to-rest reorientation of a body-fixed sensor among keep-out cones.

    Attitudes are body-to-inertial quaternions [x, y, z, w]. ``spacecraft.body_torque_max`` is the
    per-axis torque bound T̄ (N m). ``deadline`` is a ``time.monotonic()`` instant after which a
    method must stop and return its best plan so far (``None``: no limit).
    """

    spacecraft: Spacecraft
    q_initial: np.ndarray
    q_final: np.ndarray
    sensor_axis: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    cones: list[Cone] = field(default_factory=list)
    deadline: float | None = None
    # Semi-free final attitude: only the sensor must reach this inertial direction (rotation
    # about it free). None: the full final attitude q_final is imposed.
    sensor_target: np.ndarray | None = None

    def time_left(self) -> float:
        return np.inf if self.deadline is None else self.deadline - time.monotonic()


# Status values shared by every method (also the wire values of ManeuverPlan.status).
STATUS_OPTIMAL = "optimal"            # converged to a (local) optimum
STATUS_FEASIBLE = "feasible"          # a valid plan, optimality not proven / iteration limit
STATUS_BUDGET = "budget_expired"      # time budget ran out; best plan so far returned
STATUS_FALLBACK = "fallback"          # method failed; a safe fallback plan is returned
STATUS_FAILED = "failed"              # no plan


@dataclass
class ManeuverPlan:
    """A rest-to-rest plan as sampled body torques, with the planner's own reference states.

    ``torque[k]`` is applied from ``t[k]`` to ``t[k+1]`` ('zoh') or interpolated linearly
    ('linear'); ``t[0] = 0``, ``t[-1]`` is the maneuver duration. ``q``/``omega`` are the
    planner's predicted attitude and rate at ``t`` (the controller tracks them).
    """

    method: str
    t: np.ndarray
    torque: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    interpolation: str = "zoh"
    status: str = STATUS_FEASIBLE
    message: str = ""
    solve_seconds: float = 0.0
    stats: dict = field(default_factory=dict)

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])
