"""Requests for a slew that ends on a pointing mode: planned by time_optimal, smooth_collocation
or the first plan only, not with a semi-free goal, the mode checked field by field; the goal's law
is the controller's."""
from __future__ import annotations

import math
import pickle
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import PointingMode, Stage
from att_planner.guidance import reference
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.service.moving_goal import goal_law
from att_planner.service.planning import plan_maneuver
from att_planner.service.requests import ManeuverRequest, validate_maneuver
from att_planner.service.worker import run_isolated, warm_up
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

LEO = scen.load("leo_momentum")
NADIR = PointingMode("nadir")


def validate(method="time_optimal", mode=NADIR, **fields):
    req = ManeuverRequest(LEO.frame_id, rot.IDENTITY, rot.IDENTITY, np.array([0.0, 0.0, 1.0]), [], method=method,
                          time_budget=10.0, spacecraft=LEO.name, end_pointing=mode, **fields)
    return validate_maneuver(req, frame_id=LEO.frame_id, default_spacecraft=LEO.name, default_method="",
                             default_budget=10.0)


def test_the_goal_is_the_controllers_law_shifted_by_the_plans_epoch():
    later = LEO.epoch.replace(second=LEO.epoch.second + 30)
    motion = goal_law(PointingMode("nadir"), LEO, later, rot.IDENTITY)
    law = law_of(PointingMode("nadir"), PointingGeometry.of(world.Environment.from_scenario(LEO)), 0.0, rot.IDENTITY)
    q, w = motion(100.0)
    ref = reference(law.attitude, 130.0)
    assert rot.angle_between(q, ref.q_RN) < 1e-12 and np.allclose(w, ref.omega_RN_R, atol=1e-15)


def test_a_valid_request_carries_the_moving_goal_and_a_first_guess_of_its_end():
    valid = validate()
    problem = valid.problem
    assert problem.goal_motion is not None
    start = replace(problem, q_final=problem.goal_motion(0.0)[0])      # where the goal is at the start
    arrival = start.slew_time_bound()
    assert arrival > 60.0
    assert rot.angle_between(problem.q_final, problem.goal_motion(arrival)[0]) < 1e-9


@pytest.mark.parametrize("fields, code, words", [
    ({"method": "slepian_minimum_time"}, ErrorCode.INVALID_OPTION, "time_optimal"),
    ({"semi_free": True, "sensor_target": np.array([1.0, 0.0, 0.0])}, ErrorCode.INVALID_OPTION, "semi_free"),
    ({"mode": PointingMode("sideways")}, ErrorCode.INVALID_POINTING, "pointing.kind"),
    ({"mode": PointingMode("nadir", primary_axis=np.array([0.0, 0.0, math.nan]))}, ErrorCode.INVALID_POINTING,
     "pointing.primary_axis"),
])
def test_bad_end_pointing_requests_are_refused_naming_the_field(fields, code, words):
    with pytest.raises(RequestError) as err:
        validate(**fields)
    assert err.value.code == code and words in err.value.message


def test_the_goal_travels_to_a_child_process_as_its_series_and_is_met_there():
    """The law's sky does not pickle; its series does, within 1e-9 (quaternion components) and
    1e-11 rad/s of it over the window, and the planner's child process meets the goal the parent
    verifies against the law."""
    valid = validate()
    goal = valid.problem.goal_motion
    copy = pickle.loads(pickle.dumps(goal))
    assert copy.law is None
    for t in np.linspace(0.0, goal.window, 37):
        (q, w), (q_copy, w_copy) = goal(t), copy(t)
        assert np.abs(q - np.sign(q @ q_copy) * q_copy).max() < 1e-9 and np.abs(w - w_copy).max() < 1e-11
    warm_up()
    outcome = plan_maneuver(validate(), runner=run_isolated)
    assert outcome.code == ErrorCode.OK and outcome.stage == Stage.METHOD, outcome.message
    assert [s.name for s in outcome.stages] == [Stage.FIRST, Stage.METHOD]      # the first plan ends on it too
    assert outcome.stages[0].verified
    ver = outcome.plan.verification
    assert ver.final_attitude_error < 1e-4 and ver.final_rate < 1e-6
