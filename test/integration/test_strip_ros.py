"""A strip imaged through the nodes: ImageStrip over the planner's service answers the verified slew
onto the strip's first point and the strip's pointing mode (``pointing_after``: the scan from the
arrival); ExecuteManeuver with it flies the slew on the estimate, hands over to the strip's law at
the planned instant and follows the scan. The slew is planned to start 9 s of sim time after the
estimate it starts from and is executed at once: the controller holds the plan's first attitude
until its instant (a plan onto a moving goal runs on its own clock). Checked from the MCAP: the
controller on the strip's law through the scan within 0.01 deg of its estimate, the truth within
0.02 deg of the law recomputed from the answered mode, the wheel torque within its limit."""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
import rclpy

from att_msgs.msg import AttitudeEstimate
from att_msgs.srv import ImageStrip
from att_msgs_py import convert, qos, topics
from att_msgs_py.log import read_log
from att_msgs_py.types import ControlMode
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

pytestmark = pytest.mark.ros

SWIFT = scen.load("swift_demo")
GEOMETRY = PointingGeometry.of(world.Environment.from_scenario(SWIFT))
# s of sim time from the estimate to the slew's planned start: the controller starts a plan onto a moving goal
# at most max_start_epoch_error_s (10 s) from its instant, so the goal may reach it from 1 s before the
# release of the held simulator (the estimate's own time, as when no state came in between) to 19 s after
LEAD = 9.0
ARRIVAL = 95.0               # s after the planned start where the strip's start is placed (the slew takes about 93 s)
TOLERANCE = math.radians(0.01)


def spin_until(node, done, timeout: float, what: str) -> None:
    end = time.monotonic() + timeout
    while not done() and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    assert done(), f"{what} within {timeout:g} s"


def test_a_strip_is_planned_flown_on_its_law_and_scanned_through_the_nodes(ros_suite):
    params = {"simulator": {"real_time_factor": 0.0},
              "controller": {"tracking_kp": 10.0, "tracking_kd": 60.0}}       # the imaging gains
    with ros_suite("swift_demo", params=params, name="strip") as suite:
        node = suite.client
        estimates = []
        node.create_subscription(AttitudeEstimate, topics.ESTIMATE,
                                 lambda m: estimates.append(convert.estimate_from_msg(m)), qos.STREAM_QOS)
        spin_until(node, lambda: estimates, 30.0, "an estimate")
        with node.simulator_held():
            now = estimates[-1]                      # at rest (idle): a later estimate differs by noise only
            start = now.t + LEAD
            lat, lon = site_in_view(GEOMETRY, start + ARRIVAL, math.radians(15.0), math.radians(90.0))
            req = ImageStrip.Request(initial_attitude=convert.quaternion(now.q),
                                     start_latitude_deg=math.degrees(lat), start_longitude_deg=math.degrees(lon),
                                     by_azimuth=True, azimuth_deg=45.0, length_m=60e3, method="graph_smooth",
                                     time_budget=30.0, epoch=convert.time_msg(start))
            req.header.frame_id = SWIFT.frame_id
            req.sensor_axis.y = req.along_track_axis.z = 1.0
            answer = node.image_strip(req)
            assert answer.success, answer.message
        mode = convert.pointing_from_msg(answer.pointing_after)
        scan_start, scan_end = start + answer.image_start, start + answer.image_end
        assert mode.kind == "strip" and mode.scan_start == pytest.approx(scan_start, abs=1e-6)
        result = node.execute(answer.plan.plan_id, timeout=300.0, pointing_after=mode)
        assert result.success, result.message
        spin_until(node, lambda: estimates[-1].t > scan_end + 1.0, 120.0, "the scan's end")
        assert all(suite.suite.alive().values())
        suite.stop()

    log = read_log(suite.mcap, topics=[topics.STATE, topics.CONTROLLER_STATUS])
    status, state = log[topics.CONTROLLER_STATUS], log[topics.STATE]
    t = np.asarray(status["header.stamp"])
    scanning = (t >= scan_start) & (t <= scan_end)
    assert scanning.sum() > 10
    assert set(np.asarray(status["guidance"])[scanning]) == {"strip"}
    assert set(np.asarray(status["mode"])[scanning]) == {ControlMode.POINTING}
    error = np.asarray(status["attitude_error"])[scanning]
    assert error.max() < TOLERANCE, np.degrees(error.max())          # on the estimate, no jump at the hand-over
    law = law_of(mode, GEOMETRY, scan_start, rot.IDENTITY)            # the law the answer names
    ts, q = np.asarray(state["header.stamp"]), np.asarray(state["attitude"])
    flown = (ts >= scan_start) & (ts <= scan_end)
    truth = [rot.angle_between(qk, law.attitude(tk)) for qk, tk in zip(q[flown], ts[flown])]
    assert max(truth) < 2 * TOLERANCE, np.degrees(max(truth))
    handover = (ts > scan_start - 1.0) & (ts < scan_start + 5.0)
    torque = np.asarray(state["wheel_torques"])[handover]
    print(f"slew {answer.plan.duration:.1f} s, scan {scan_end - scan_start:.1f} s; on the estimate "
          f"{np.degrees(error.max()):.4f} deg, truth {np.degrees(max(truth)):.4f} deg; hand-over wheel torque "
          f"{np.abs(torque).max():.4f} N m")
    assert np.abs(torque).max() < SWIFT.spacecraft.wheel_torque_max
