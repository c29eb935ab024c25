"""smooth_collocation onto a moving ground site: it ends on the site's attitude and rate and, where
the site's tracking torque stays within the bound, at that torque (no step at the hand-over)."""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import PointingMode, Status
from att_planner.guidance import reference
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.methods.time_optimal.model import ties_end_torque
from att_planner.methods.time_optimal.smooth import plan_smooth_collocation
from att_planner.service.requests import ManeuverRequest, validate_maneuver
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

SWIFT = scen.load("swift_demo")


def test_the_smooth_plan_ends_at_the_torque_that_tracks_the_site():
    geometry = PointingGeometry.of(world.Environment.from_scenario(SWIFT))
    lat, lon = site_in_view(geometry, 70.0, math.radians(20.0), math.radians(90.0))
    mode = PointingMode("ground", primary_axis=np.array([0.0, 1.0, 0.0]), secondary_axis=np.array([0.0, 0.0, 1.0]),
                        secondary="ground_velocity", latitude=lat, longitude=lon)
    req = ManeuverRequest(SWIFT.frame_id, rot.IDENTITY, rot.IDENTITY, np.array([0.0, 1.0, 0.0]), [],
                          method="smooth_collocation", time_budget=30.0, spacecraft=SWIFT.name, end_pointing=mode)
    problem = validate_maneuver(req, frame_id=SWIFT.frame_id, default_spacecraft=SWIFT.name, default_method="",
                                default_budget=30.0).problem
    problem.deadline = None
    assert ties_end_torque(problem)
    plan = plan_smooth_collocation(problem)
    assert plan.status == Status.OPTIMAL, plan.message
    assert plan.verification.final_attitude_error < math.radians(0.05)
    assert plan.verification.final_rate < math.radians(0.01)
    law = law_of(mode, geometry, 0.0, rot.IDENTITY)
    ref = reference(law.attitude, plan.duration, h=0.05)
    J = SWIFT.spacecraft.inertia
    tracking = J @ ref.omega_dot_RN_R + np.cross(ref.omega_RN_R, J @ ref.omega_RN_R)
    assert np.abs(tracking).max() > 1e-3                           # a torque to meet, not zero
    assert np.abs(plan.torque[-1] - tracking).max() < 1e-2 * SWIFT.spacecraft.body_torque_max
