"""The planner's problem type (no ROS): what every planning method is asked.

Every method is a pure function ``plan(problem: ManeuverProblem, **options) -> Plan`` in the style
of ``scipy.optimize``: a problem and options in, one result type out
(:class:`att_msgs_py.types.Plan`: samples, status, message, iterations, wall time, statistics).
The registry of :mod:`att_planner.methods` names them and their options; the planner service
(:mod:`att_planner.service`) validates requests into problems, runs a method, verifies its plan
(:mod:`att_planner.verification`) and answers.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import Cone
from att_sim.dynamics import Spacecraft


@dataclass
class ManeuverProblem:
    """Reorientation of a body-fixed sensor among keep-out cones, from rest to rest.

    Attitudes are body-to-inertial quaternions [x, y, z, w]. ``spacecraft.body_torque_max`` is the
    per-axis torque bound T̄ (N m). ``deadline`` is a ``time.monotonic()`` instant after which a
    method must stop and return its best plan so far (``None``: no limit).

    * ``sensor_target``: semi-free final attitude, only the sensor must reach this inertial
      direction (rotation about it free); None: the full final attitude ``q_final`` is imposed.
    * ``targets``: name → attitude, every one to be passed through once, in any order, on the way
      from ``q_initial`` to ``q_final`` (a schedule; Olivares & Staffetti 2018: at a passage the
      attitude is the target's and the body rate about body z is zero).
    * ``rate_max`` (rad/s per body axis) and ``wheel_momentum_max`` (N m s per wheel, the momentum
      the wheels store producing a body-torque plan with zero total momentum): bounds a plan must
      keep, checked by the verification; infinite when not imposed.
    """

    spacecraft: Spacecraft
    q_initial: np.ndarray
    q_final: np.ndarray
    sensor_axis: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    cones: list[Cone] = field(default_factory=list)
    deadline: float | None = None
    sensor_target: np.ndarray | None = None
    targets: dict = field(default_factory=dict)
    rate_max: float = math.inf
    wheel_momentum_max: float = math.inf

    def time_left(self) -> float:
        return np.inf if self.deadline is None else self.deadline - time.monotonic()
