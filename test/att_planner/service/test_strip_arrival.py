"""Slews onto a strip's first point at the scan's rate, one per method, for a strip 45 deg east of
north from a point 20 deg off nadir across the track (yaw steering): planned through the imaging
service, the plan's controls integrated through the prediction model end on the strip's reference
(recomputed here from the strip's law) within 0.05 deg and 0.01 deg/s, the scan seen above the
minimum elevation and within the body's limits. time_optimal and the first plan on aeos (from nadir
at the epoch); smooth_collocation on leo_observatory (payload +y, from the identity, as the
ground-site slews; scanning at 3 km/s), where its NLP converges: on aeos it stops at IPOPT's
iteration limit onto a site as onto a strip, and the service answers with the first plan."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import PointingMode, Stage
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry, directions
from att_planner.guidance.modes import law_of
from att_planner.guidance.strip import StripLaw
from att_planner.service.imaging import ImageStripRequest, plan_image, validate_image_strip
from att_planner.verification import predict
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

RATE_MAX = math.radians(5.0)
# scenario: (boresight, along-track axis, s ahead where the strip's start is placed, minimum elevation deg,
# scan speed m/s: 0 the sub-satellite point's; leo_observatory's 0.25 N m cannot follow that one near the pass)
SETUPS = {"aeos": (np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), 60.0,
                   math.degrees(math.atan2(800.0, 500.0)), 0.0),
          "leo_observatory": (np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), 300.0, 30.0, 3000.0)}
SCENARIOS = {name: scen.load(name) for name in SETUPS}
GEOMETRIES = {name: PointingGeometry.of(world.Environment.from_scenario(sc)) for name, sc in SCENARIOS.items()}


def strip_request(name: str, method: str) -> ImageStripRequest:
    boresight, along, ahead, _, speed = SETUPS[name]
    geometry = GEOMETRIES[name]
    q0 = (law_of(PointingMode("nadir", primary_axis=boresight, secondary_axis=along), geometry, 0.0,
                 rot.IDENTITY).attitude(0.0) if name == "aeos" else rot.IDENTITY)
    lat, lon = site_in_view(geometry, ahead, math.radians(20.0), math.radians(90.0))
    return ImageStripRequest("", q0, boresight, along, method=method, time_budget=120.0,
                             start_latitude_deg=math.degrees(lat), start_longitude_deg=math.degrees(lon),
                             by_azimuth=True, azimuth_deg=45.0, length_m=40e3, scan_speed_m_s=speed)


@pytest.mark.parametrize("name, method", [("aeos", "time_optimal"), ("aeos", "graph_smooth"),
                                          ("leo_observatory", "smooth_collocation")])
def test_the_slew_ends_on_the_strip_s_start_at_the_scan_s_rate(name, method):
    sc, geometry = SCENARIOS[name], GEOMETRIES[name]
    boresight, along, _, min_elevation_deg, _ = SETUPS[name]
    valid = validate_image_strip(strip_request(name, method), frame_id=sc.frame_id, default_spacecraft=sc.name,
                                 default_method="", default_budget=120.0, min_elevation_deg=min_elevation_deg,
                                 rate_max=RATE_MAX)
    outcome = plan_image(valid)
    assert outcome.code == ErrorCode.OK and outcome.stage == Stage.METHOD, outcome.message
    plan = outcome.plan
    ver = plan.verification
    print(name, method, f"t_f {plan.duration:.1f} s, {math.degrees(ver.final_attitude_error):.2e} deg, "
                  f"{math.degrees(ver.final_rate):.2e} deg/s")
    assert ver.goal == "strip" and ver.final_attitude_error < math.radians(0.05) and ver.final_rate < math.radians(0.01)
    traj = predict(valid.maneuver.problem, plan)
    t_f = float(traj.t[-1])
    ref = StripLaw(geometry, valid.strip, boresight, along, t_f).reference(t_f)
    q_end = traj.q_BN[-1]
    omega_B = rot.dcm_BN(q_end) @ rot.dcm_NB(ref.q_RN) @ ref.omega_RN_R
    assert rot.angle_between(q_end, ref.q_RN) < math.radians(0.05)
    assert np.linalg.norm(traj.omega_BN_B[-1] - omega_B) < math.radians(0.01) < np.linalg.norm(ref.omega_RN_R)
    # the yaw: the strip runs 45 deg off north, the along-track axis follows it, not the ground track
    dcm_NB = rot.dcm_NB(q_end)
    boresight_N, along_N = dcm_NB @ boresight, dcm_NB @ along
    track = directions(geometry)["ground_velocity"](t_f)
    track = track - boresight_N * (track @ boresight_N)
    yaw = math.degrees(math.acos(abs(along_N @ track) / np.linalg.norm(track)))
    assert yaw > 30.0, yaw
    assert outcome.image_start == pytest.approx(t_f)
    assert outcome.image_end == pytest.approx(t_f + valid.strip.duration_s)
    assert outcome.lowest_elevation >= math.radians(min_elevation_deg)
    assert np.abs(plan.torque).max() <= sc.spacecraft.body_torque_max * (1 + 1e-9)
