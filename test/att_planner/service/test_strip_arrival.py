"""Slews onto a strip's first point at the scan's rate on aeos, one per method (time_optimal,
smooth_collocation and the first plan), for a strip across the ground track (yaw steering):
planned through the imaging service, the plan's controls integrated through the prediction model
end on the strip's reference (recomputed here from the strip's law) within 0.05 deg and 0.01 deg/s,
the scan seen above the instrument's minimum elevation and within the body's limits."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import PointingMode
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry, directions
from att_planner.guidance.modes import law_of
from att_planner.guidance.strip import StripLaw
from att_planner.service.imaging import ImageStripRequest, plan_image, validate_image_strip
from att_planner.verification import predict
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

AEOS = scen.load("aeos")
GEOMETRY = PointingGeometry.of(world.Environment.from_scenario(AEOS))
BORESIGHT, ALONG = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
MIN_ELEVATION_DEG = math.degrees(math.atan2(800.0, 500.0))
RATE_MAX = math.radians(5.0)
ARRIVAL = 60.0                   # s: the strip's start is placed 20 deg off nadir across track then


def strip_request(method: str, azimuth_deg: float = 45.0) -> ImageStripRequest:
    q0 = law_of(PointingMode("nadir"), GEOMETRY, 0.0, rot.IDENTITY).attitude(0.0)
    lat, lon = site_in_view(GEOMETRY, ARRIVAL, math.radians(20.0), math.radians(90.0))
    return ImageStripRequest("", q0, BORESIGHT, ALONG, method=method, time_budget=120.0,
                             start_latitude_deg=math.degrees(lat), start_longitude_deg=math.degrees(lon),
                             by_azimuth=True, azimuth_deg=azimuth_deg, length_m=40e3)


def validate(req: ImageStripRequest):
    return validate_image_strip(req, frame_id=AEOS.frame_id, default_spacecraft=AEOS.name, default_method="",
                                default_budget=120.0, min_elevation_deg=MIN_ELEVATION_DEG, rate_max=RATE_MAX)


@pytest.mark.parametrize("method", ["time_optimal", pytest.param("smooth_collocation", marks=pytest.mark.slow),
                                    "graph_smooth"])
def test_the_slew_ends_on_the_strip_s_start_at_the_scan_s_rate(method):
    valid = validate(strip_request(method))
    outcome = plan_image(valid)
    assert outcome.code == ErrorCode.OK, outcome.message
    plan = outcome.plan
    ver = plan.verification
    print(method, f"t_f {plan.duration:.1f} s, {math.degrees(ver.final_attitude_error):.2e} deg, "
                  f"{math.degrees(ver.final_rate):.2e} deg/s")
    assert ver.goal == "strip" and ver.final_attitude_error < math.radians(0.05) and ver.final_rate < math.radians(0.01)
    traj = predict(valid.maneuver.problem, plan)
    t_f = float(traj.t[-1])
    ref = StripLaw(GEOMETRY, valid.strip, BORESIGHT, ALONG, t_f).reference(t_f)
    q_end = traj.q_BN[-1]
    omega_B = rot.dcm_BN(q_end) @ rot.dcm_NB(ref.q_RN) @ ref.omega_RN_R
    assert rot.angle_between(q_end, ref.q_RN) < math.radians(0.05)
    assert np.linalg.norm(traj.omega_BN_B[-1] - omega_B) < math.radians(0.01) < np.linalg.norm(ref.omega_RN_R)
    # the yaw: the strip runs 45 deg off north, the along-track axis follows it, not the ground track
    dcm_NB = rot.dcm_NB(q_end)
    boresight_N, along_N = dcm_NB @ BORESIGHT, dcm_NB @ ALONG
    track = directions(GEOMETRY)["ground_velocity"](t_f)
    track = track - boresight_N * (track @ boresight_N)
    yaw = math.degrees(math.acos(abs(along_N @ track) / np.linalg.norm(track)))
    assert yaw > 30.0, yaw
    assert outcome.image_start == pytest.approx(t_f)
    assert outcome.image_end == pytest.approx(t_f + valid.strip.duration_s)
    assert outcome.lowest_elevation >= math.radians(MIN_ELEVATION_DEG)
    assert np.abs(plan.torque).max() <= AEOS.spacecraft.body_torque_max * (1 + 1e-9)
