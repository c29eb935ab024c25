"""Slews that end on a moving ground site, one per geometry and method (time_optimal,
smooth_collocation and the first plan): planned through the planner service,
the plan's controls integrated through the prediction model end on the site's line of sight and
rate at t_f, recomputed here from the pointing law (its attitude, central differences of it)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import PointingMode, Stage
from att_planner.guidance import reference
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.problem import GOAL_FIT_ATTITUDE, GOAL_FIT_RATE
from att_planner.service.planning import plan_maneuver
from att_planner.service.requests import ManeuverRequest, validate_maneuver
from att_planner.verification import predict
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

LEO = scen.load("leo_observatory")       # the payload on body +y, as earth_observation_day
GEOMETRY = PointingGeometry.of(world.Environment.from_scenario(LEO))
ARRIVAL = 300.0                          # s: where the site is placed in view (the slews take 345-390 s)
SENSOR, ALONG_TRACK = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])

# name: (off nadir deg, azimuth deg from along-track, secondary direction, yaw deg)
GEOMETRIES = {"nadir": (0.0, 0.0, "velocity", 0.0), "20_ahead": (20.0, 0.0, "velocity", 0.0),
              "20_behind": (20.0, 180.0, "velocity", 0.0), "28_ahead": (28.0, 0.0, "velocity", 0.0),
              "28_behind": (28.0, 180.0, "velocity", 0.0), "strip_yaw": (20.0, 90.0, "ground_velocity", 5.0)}


def ground_mode(geometry: str) -> PointingMode:
    off_nadir, azimuth, secondary, yaw = GEOMETRIES[geometry]
    lat, lon = site_in_view(GEOMETRY, ARRIVAL, math.radians(off_nadir), math.radians(azimuth))
    return PointingMode("ground", primary_axis=SENSOR, secondary_axis=ALONG_TRACK, secondary=secondary,
                        latitude=lat, longitude=lon, altitude=0.0, yaw=math.radians(yaw))


def validate(mode: PointingMode, method: str = "time_optimal"):
    req = ManeuverRequest(LEO.frame_id, rot.IDENTITY, rot.IDENTITY, SENSOR, [], method=method, time_budget=60.0,
                          spacecraft=LEO.name, end_pointing=mode)
    return validate_maneuver(req, frame_id=LEO.frame_id, default_spacecraft=LEO.name, default_method="",
                             default_budget=60.0)


def arrival_errors(valid, plan, mode: PointingMode) -> tuple[float, float]:
    """The predicted end against the law at t_f: attitude error (rad) and rate error (rad/s, body axes)."""
    traj = predict(valid.problem, plan)
    law = law_of(mode, GEOMETRY, 0.0, rot.IDENTITY)
    goal = reference(law.attitude, float(traj.t[-1]), h=0.01)
    q_end = traj.q_BN[-1]
    omega_goal_B = rot.dcm_BN(q_end) @ rot.dcm_NB(goal.q_RN) @ goal.omega_RN_R
    return float(rot.angle_between(q_end, goal.q_RN)), float(np.linalg.norm(traj.omega_BN_B[-1] - omega_goal_B))


def test_the_goal_series_follows_a_ground_site_over_the_whole_window():
    """A pass turns the line of sight within a minute: the series takes a high degree to stay on it."""
    goal = validate(ground_mode("nadir")).problem.goal_motion
    assert goal.kind == "ground" and len(goal.coefficients) - 1 > 16
    assert goal.fit_error[0] <= GOAL_FIT_ATTITUDE and goal.fit_error[1] <= GOAL_FIT_RATE
    law = goal.law
    goal.law = None                      # the series alone, as a planner's child process sees it
    for t in np.linspace(0.0, goal.window, 301):
        (q, w), (q_law, w_law) = goal(t), law(t)
        assert rot.angle_between(q, q_law) < 1e-5 and np.linalg.norm(w - w_law) < 1e-7


@pytest.mark.parametrize("method", ["time_optimal", "smooth_collocation", "graph_smooth"])
@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_the_slew_ends_on_the_moving_site(geometry, method):
    """Each method's plan (graph_smooth: the first plan's construction) is the answer, verified."""
    mode = ground_mode(geometry)
    valid = validate(mode, method)
    outcome = plan_maneuver(valid)
    assert outcome.code == ErrorCode.OK and outcome.stage == Stage.METHOD, outcome.message
    assert all(stage.verified for stage in outcome.stages)
    ver = outcome.plan.verification
    assert ver.goal == "ground"
    attitude, rate = arrival_errors(valid, outcome.plan, mode)
    assert attitude < math.radians(0.05) and rate < math.radians(0.01), (math.degrees(attitude), math.degrees(rate))
    assert ver.final_attitude_error == pytest.approx(attitude, abs=1e-6)
    assert ver.torque_ratio <= 1.0 + 1e-6


def test_a_mode_without_an_attitude_inside_the_window_is_refused(monkeypatch):
    """The mode is checked now by its law; a ground site whose line of sight meets the secondary
    direction later in the window (the goal is fitted there) is refused, naming the field."""
    from att_planner.service import requests

    def parallel_later(*args):
        def motion(t):
            if t > 10.0:
                raise ValueError("the primary and secondary directions are parallel: no attitude about the primary")
            return rot.IDENTITY, np.zeros(3)
        return motion

    monkeypatch.setattr(requests, "goal_law", parallel_later)
    with pytest.raises(RequestError) as err:
        validate(ground_mode("nadir"))
    assert err.value.code == ErrorCode.INVALID_POINTING and "end_pointing (ground)" in err.value.message
    assert "parallel" in err.value.message
