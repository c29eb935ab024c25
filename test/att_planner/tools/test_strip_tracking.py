"""A slew onto a strip flown in process (simulator, sensors, MEKF, controller on the estimate), as the
ground-site hand-over tests fly theirs (:mod:`test_ground_handover`): the first plan ends on the
strip's first point at the scan's rate, the controller hands over to the strip's law at the plan's
end without a jump and follows the scan within 0.01 deg on the estimate, the wheels' torque within
their limit at the hand-over. The strip runs 45 deg off north from a point 20 deg off nadir across
the track (a strip with yaw), scanned at the sub-satellite point's ground speed. The controller is
handed the strip's pointing mode as the planner answers it (``pointing_after``, the wire's form);
a plan started half a second after its planned instant runs on its own clock and hands over just
the same, one started later than ``max_start_epoch_error_s`` is refused."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import ControlMode
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.strip import StripLaw
from att_planner.service.imaging import ImageStripRequest, plan_image, validate_image_strip
from att_planner.tools.closed_loop import ClosedLoop
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

SWIFT = scen.load("swift_demo")
GEOMETRY = PointingGeometry.of(world.Environment.from_scenario(SWIFT))
IMAGING_GAINS = {"tracking_kp": 10.0, "tracking_kd": 60.0}
SENSOR, ALONG_TRACK = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
LEAD = 70.0             # s after the plan's start where the strip's start is placed (the slews take 70-100 s)
POINTING_TOLERANCE = math.radians(0.01)


def strip_from_the_estimate():
    """A loop flown until its estimate converges, and the first plan onto the strip from there:
    (loop, its time then, the checked request, the planned image)."""
    loop = ClosedLoop(SWIFT, overrides={"controller": IMAGING_GAINS})
    loop.run(20.0)                                       # the estimate converges
    assert loop.estimator is not None and loop.controller.measured is not None     # flown on the estimate
    t0 = loop.controller.state.t
    lat, lon = site_in_view(GEOMETRY, t0 + LEAD, math.radians(20.0), math.radians(90.0))
    req = ImageStripRequest(SWIFT.frame_id, loop.controller.state.q, SENSOR, ALONG_TRACK, method="graph_smooth",
                            time_budget=30.0, spacecraft=SWIFT.name, epoch=(int(t0), round(t0 % 1 * 1e9)),
                            start_latitude_deg=math.degrees(lat), start_longitude_deg=math.degrees(lon),
                            by_azimuth=True, azimuth_deg=45.0, length_m=150e3)
    valid = validate_image_strip(req, frame_id=SWIFT.frame_id, default_spacecraft=SWIFT.name, default_method="",
                                 default_budget=30.0, min_elevation_deg=45.0)
    outcome = plan_image(valid)
    assert outcome.code == 0, outcome.message
    return loop, t0, valid, outcome


@pytest.mark.slow
@pytest.mark.parametrize("late", [0.0, 0.5])
def test_a_slew_onto_a_strip_hands_over_and_follows_the_scan(late):
    loop, t0, valid, outcome = strip_from_the_estimate()
    plan = outcome.plan
    ver = plan.verification
    assert ver.goal == "strip" and ver.final_attitude_error < math.radians(0.05) and ver.final_rate < math.radians(0.01)
    end = t0 + plan.duration
    law = StripLaw(GEOMETRY, valid.strip, SENSOR, ALONG_TRACK, end)
    goal = law.reference(end)
    assert rot.angle_between(plan.q[-1], goal.q_RN) < 1e-5
    assert np.linalg.norm(plan.omega[-1] - goal.omega_RN_R) < 1e-6 < 0.05 * np.linalg.norm(goal.omega_RN_R)

    assert outcome.pointing_after.kind == "strip" and outcome.pointing_after.scan_start == pytest.approx(end)
    loop.run(late)
    assert loop.execute(plan, after=outcome.pointing_after) is None
    scan = valid.strip.duration_s
    loop.run(plan.duration + scan + 1.0 - late)
    trace = loop.trace.arrays()
    t, error, modes, torques = trace["t"], trace["attitude_error"], trace["mode"], trace["wheel_torques"]
    assert loop.controller.pointing.name == "strip" and np.all(modes[t > end + 0.06] == ControlMode.POINTING)
    handover = (t > end - 5.0) & (t < end + 5.0)
    scanning = (t >= end) & (t <= end + scan)
    print(f"t_f {plan.duration:.1f} s, arrival {np.degrees(ver.final_attitude_error):.2e} deg "
          f"{np.degrees(ver.final_rate):.2e} deg/s; scan {scan:.1f} s at {valid.strip.scan_speed_m_s:.0f} m/s, "
          f"{np.degrees(np.linalg.norm(goal.omega_RN_R)):.3f} deg/s; on the estimate "
          f"{np.degrees(error[scanning].max()):.4f} deg; hand-over wheel torque "
          f"{np.abs(torques[(t > end - 1.0) & (t < end + 5.0)]).max():.4f} N m")
    assert np.max(error[handover]) < POINTING_TOLERANCE, np.degrees(error[handover].max())      # no jump
    assert np.max(error[scanning]) < POINTING_TOLERANCE, np.degrees(error[scanning].max())
    # the truth on the strip too (the estimate's own error is a few 1e-3 deg)
    truth = [rot.angle_between(q, law.attitude(tt)) for q, tt in zip(trace["q_true"][scanning], t[scanning])]
    assert max(truth) < 2 * POINTING_TOLERANCE, np.degrees(max(truth))
    assert np.abs(torques[(t > end - 1.0) & (t < end + 5.0)]).max() < SWIFT.spacecraft.wheel_torque_max


def test_a_slew_onto_a_strip_started_too_late_is_refused():
    loop, _, _, outcome = strip_from_the_estimate()
    late = loop.controller.context.max_start_epoch_error + 1.0
    loop.run(late)
    refused = loop.execute(outcome.plan, after=outcome.pointing_after)
    assert refused is not None and refused.code == ErrorCode.PLAN_CONTEXT, refused
    assert "max_start_epoch_error_s" in refused.message and f"{late:.1f} s later" in refused.message, refused.message
