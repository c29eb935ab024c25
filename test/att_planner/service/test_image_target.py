"""ImageTarget through the service core on swift_demo (the first plan, from the identity): a site
100 s ahead is reached on its line of sight and rate and seen above the minimum elevation through
the dwell; one 120 s ahead is reached when it is still too low (the slew takes 87 s), refused as
SITE_NOT_VISIBLE with the plan's arrival and the elevation found."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_planner.guidance import reference
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.service.imaging import ImageTargetRequest, elevation, plan_image, validate_image_target
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

SWIFT = scen.load("swift_demo")
GEOMETRY = PointingGeometry.of(world.Environment.from_scenario(SWIFT))
SENSOR, ALONG = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
MIN_ELEVATION_DEG = 58.0
DWELL = 10.0


def planned(ahead: float):
    lat, lon = site_in_view(GEOMETRY, ahead, math.radians(20.0), math.radians(90.0))
    req = ImageTargetRequest("", rot.IDENTITY, SENSOR, ALONG, method="graph_smooth", latitude_deg=math.degrees(lat),
                             longitude_deg=math.degrees(lon), dwell_s=DWELL)
    valid = validate_image_target(req, frame_id=SWIFT.frame_id, default_spacecraft=SWIFT.name, default_method="",
                                  default_budget=20.0, min_elevation_deg=MIN_ELEVATION_DEG)
    return valid, plan_image(valid)


def test_a_site_in_view_is_reached_and_seen_through_the_dwell():
    valid, outcome = planned(100.0)
    assert outcome.code == ErrorCode.OK, outcome.message
    plan, ver = outcome.plan, outcome.plan.verification
    assert ver.goal == "ground"
    assert ver.final_attitude_error < math.radians(0.05) and ver.final_rate < math.radians(0.01)
    law = law_of(valid.mode, GEOMETRY, 0.0, rot.IDENTITY)
    goal = reference(law.attitude, plan.duration, h=0.01)
    assert rot.angle_between(plan.q[-1], goal.q_RN) < 1e-5
    assert outcome.image_start == pytest.approx(plan.duration) and outcome.image_end == pytest.approx(
        plan.duration + DWELL)
    site = valid.sites_E(0.0, np.zeros(1))
    seen = elevation(GEOMETRY, np.repeat(site, 3, axis=0), plan.duration + np.array([0.0, DWELL / 2, DWELL]))
    assert seen.min() == pytest.approx(outcome.lowest_elevation, abs=1e-3) and seen.min() > math.radians(58.0)


def test_a_site_too_low_at_the_arrival_is_refused_as_not_visible():
    _, outcome = planned(120.0)
    assert outcome.code == ErrorCode.SITE_NOT_VISIBLE, outcome.message
    assert "the slew arrives at" in outcome.message and "below the instrument's 58.0 deg" in outcome.message
    assert outcome.lowest_elevation < math.radians(MIN_ELEVATION_DEG)


def test_the_request_s_zones_are_kept_by_the_slew_and_a_hostile_zone_is_refused():
    """A keep-out zone of a star tracker's axis (body −z) about the direction it sees at the start:
    the slew leaves it, the problem carries it and its margin over the plan's samples, recomputed here,
    is what the verification says (≥ 0). A zone with a NaN half-angle is refused naming it."""
    from att_msgs_py.errors import RequestError
    from att_msgs_py.types import Zone

    tracker = np.array([0.0, 0.0, -1.0])
    seen = rot.dcm_NB(rot.IDENTITY) @ tracker
    zone = Zone("tracker_keep_out", "inertial", tracker, math.radians(5.0), direction=seen)
    lat, lon = site_in_view(GEOMETRY, 100.0, math.radians(20.0), math.radians(90.0))
    common = dict(method="graph_smooth", latitude_deg=math.degrees(lat), longitude_deg=math.degrees(lon), dwell_s=DWELL)
    q0 = rot.from_axis_angle([1.0, 0.0, 0.0], math.radians(8.0))       # 8 deg from the zone's axis: outside it
    req = ImageTargetRequest("", q0, SENSOR, ALONG, zones=[zone], **common)
    valid = validate_image_target(req, frame_id=SWIFT.frame_id, default_spacecraft=SWIFT.name, default_method="",
                                  default_budget=20.0, min_elevation_deg=MIN_ELEVATION_DEG)
    outcome = plan_image(valid)
    assert outcome.code == ErrorCode.OK, outcome.message
    plan = outcome.plan
    assert [z.name for z in valid.maneuver.problem.zones] == ["tracker_keep_out"]        # the node signs them in
    margins = [math.acos(np.clip((rot.dcm_NB(q) @ tracker) @ seen, -1, 1)) - zone.half_angle for q in plan.q]
    assert min(margins) >= plan.verification.min_cone_margin - 1e-6 and plan.verification.min_cone_margin >= 0.0
    bad = ImageTargetRequest("", q0, SENSOR, ALONG, zones=[Zone("bad", "inertial", tracker, math.nan, direction=seen)],
                             **common)
    with pytest.raises(RequestError, match="bad"):
        validate_image_target(bad, frame_id=SWIFT.frame_id, default_spacecraft=SWIFT.name, default_method="",
                              default_budget=20.0, min_elevation_deg=MIN_ELEVATION_DEG)
