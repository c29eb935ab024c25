"""The first plan onto a moving goal: from rest on the start to the goal's attitude and rate at
t_f exactly, within the torque bound, no longer than it must be; refused without a moving goal."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from att_msgs_py.types import PointingMode, Status
from att_planner.methods.onto_moving_goal import DURATION_TOLERANCE, bound_ratio, plan_onto_moving_goal, profile
from att_planner.problem import ManeuverProblem
from att_planner.service.requests import ManeuverRequest, validate_maneuver
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

LEO = scen.load("leo_momentum")


def nadir_problem(q0) -> ManeuverProblem:
    req = ManeuverRequest(LEO.frame_id, q0, q0, np.array([0.0, 0.0, 1.0]), [], method="time_optimal",
                          time_budget=10.0, spacecraft=LEO.name, end_pointing=PointingMode("nadir"))
    return validate_maneuver(req, frame_id=LEO.frame_id, default_spacecraft=LEO.name, default_method="",
                             default_budget=10.0).problem


def test_the_plan_starts_at_rest_and_ends_on_the_goal_at_its_rate_within_the_torque_bound():
    problem = nadir_problem(rot.from_axis_angle([0.3, 1.0, 0.2], math.radians(70.0)))
    plan = plan_onto_moving_goal(problem)
    assert plan.status == Status.FEASIBLE, plan.message
    q_goal, omega_goal = problem.goal_motion(plan.duration)
    assert rot.angle_between(plan.q[0], problem.q_initial) < 1e-12 and np.abs(plan.omega[0]).max() < 1e-15
    assert rot.angle_between(plan.q[-1], q_goal) < 1e-9 and np.abs(plan.omega[-1] - omega_goal).max() < 1e-12
    assert np.abs(plan.torque).max() <= LEO.spacecraft.body_torque_max
    # the rates are the attitudes' derivative: q(t + dt) from q(t) and the mean of the two rates
    dt = np.diff(plan.t)
    for k in range(0, len(plan.t) - 1, 97):
        q_next = rot.multiply(plan.q[k], rot.exp_map(0.5 * (plan.omega[k] + plan.omega[k + 1]) * dt[k]))
        assert rot.angle_between(q_next, plan.q[k + 1]) < 1e-6
    # the shortest duration within the bound: a little shorter breaks it
    _, q, omega, torque = profile(problem, plan.duration * (1 - 4 * DURATION_TOLERANCE))
    assert bound_ratio(problem, omega, torque, q) > 1.0


def test_a_problem_without_a_moving_goal_is_refused():
    problem = nadir_problem(rot.IDENTITY)
    plan = plan_onto_moving_goal(replace(problem, goal_motion=None))
    assert plan.status == Status.FAILED and "no moving goal" in plan.message
