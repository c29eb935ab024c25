"""A wheel seized mid-slew through the nodes: leo_pyramid with the controller's and the estimator's
fault table on, a 10 deg slew about body x planned over the service, wheel 0 (the one that carries
most of that axis) seized through ``/simulator/inject_fault`` 30 % into it. The controller isolates
it (``/controller/faults``; the estimator's sensor detectors stay quiet), brakes on the three others,
asks the planner for the rest on their envelope (``PlanManeuver.healthy_wheels``) and the one execute
goal ends with the re-planned slew complete: the final error from the truth, no zone entered (the
simulator's truth margins), all recorded; then ``att-review`` of that MCAP marks the fault, its
detection and the response on the time histories."""
from __future__ import annotations

import math
import time
from datetime import timedelta

import numpy as np
import pytest
import rclpy

from att_msgs.msg import AttitudeEstimate, FaultEvent, FaultStatus
from att_msgs.srv import InjectFault
from att_msgs_py import convert, qos, topics
from att_msgs_py.log import read_log
from att_planner.nodes.client import maneuver_request
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SENSOR = [0.0, 1.0, 0.0]
SLEW = rot.from_axis_angle([1.0, 0.0, 0.0], math.radians(10.0))
SEIZED = 0                      # the wheel with the largest share of body x (0.612 of the pseudo-inverse)
ONSET = 0.3                     # of the plan's duration


def call(node, client, request, timeout: float = 30.0):
    future = client.call_async(request)
    rclpy.spin_until_future_complete(node, future, timeout_sec=timeout)
    assert future.done(), f"no answer from {client.srv_name} within {timeout} s"
    return future.result()


def test_a_wheel_seized_mid_slew_is_isolated_re_planned_on_three_wheels_and_reviewed(ros_suite, tmp_path):
    s = scen.load("leo_pyramid")
    params = {"controller": {"fault_table": "default", "settle_time_s": 5.0}, "estimator": {"fault_table": "default"},
              "simulator": {"real_time_factor": 0.0}, "planner": {"warm_up_scenarios": "''"}}   # (YAML ''): no warm-up
    with ros_suite("leo_pyramid", params=params, name="fault_recovery") as suite:
        node = suite.client
        estimates, reports, sensor_reports, events = [], [], [], []
        node.create_subscription(AttitudeEstimate, topics.ESTIMATE,
                                 lambda m: estimates.append(convert.estimate_from_msg(m)), qos.STREAM_QOS)
        node.create_subscription(FaultStatus, topics.CONTROLLER_FAULTS,
                                 lambda m: reports.append(convert.fault_status_from_msg(m)), qos.MISSION_QOS)
        node.create_subscription(FaultStatus, topics.ESTIMATOR_FAULTS,
                                 lambda m: sensor_reports.append(convert.fault_status_from_msg(m)), qos.MISSION_QOS)
        node.create_subscription(FaultEvent, topics.SIM_FAULTS,
                                 lambda m: events.append(convert.fault_event_from_msg(m)), qos.MISSION_QOS)
        inject = node.create_client(InjectFault, topics.INJECT_FAULT)
        assert inject.wait_for_service(timeout_sec=60)
        end = time.monotonic() + 30.0
        while not estimates and time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.05)
        assert estimates, f"no estimate on {topics.ESTIMATE} within 30 s"
        with node.simulator_held():
            now = estimates[-1]                  # at rest (idle): a later estimate differs by noise only
            goal = rot.multiply(now.q, SLEW)
            response = node.plan(maneuver_request(now.q, goal, SENSOR, [], method="eigenaxis_smooth",
                                                  frame_id=s.frame_id, epoch=s.epoch + timedelta(seconds=now.t),
                                                  zones=s.zones))
            assert response.success, response.message
            plan = convert.plan_from_msg(response.plan)
            onset = now.t + ONSET * plan.duration
            r = call(node, inject, InjectFault.Request(component="wheel", index=SEIZED, kind="seized", t_s=onset))
            assert r.success, r.message
        result = node.execute(plan.plan_id, timeout=600.0)
        assert result.success, result.message
        rclpy.spin_once(node, timeout_sec=0.1)
        [event] = events
        assert (event.component, event.index, event.kind) == ("wheel", SEIZED, "seized")
        wheel = [f for f in reports if f.component == "wheel"]
        assert wheel and (wheel[0].index, wheel[0].response, wheel[0].active) == (SEIZED, "exclude_wheel", True)
        assert event.t < wheel[0].detected_at <= event.t + 5.0, (event.t, wheel[0])
        assert sensor_reports == []                   # the estimator's sensor detectors: no false alarm
        log = suite.suite.log_text("controller")
        assert "re-planning from" in log and "flying re-plan" in log
        suite.stop()

    recorded = read_log(suite.mcap, topics=[topics.STATE, topics.ZONE_MARGINS, topics.PLANS, topics.CONTROLLER_FAULTS,
                                            topics.SIM_FAULTS])
    state = recorded[topics.STATE]
    assert math.degrees(rot.angle_between(np.asarray(state["attitude"])[-1], goal)) < 0.1     # the truth at the end
    margins = recorded[topics.ZONE_MARGINS]
    flown = np.asarray(margins["header.stamp"]) >= now.t
    assert flown.sum() > 100 and np.min(np.asarray(margins["min_margin"])[flown]) > 0.0
    plans = [convert.plan_from_msg(m) for m in recorded[topics.PLANS].messages]
    assert len(plans) == 2 and plans[1].spacecraft_digest == plans[0].spacecraft_digest
    assert len(recorded[topics.CONTROLLER_FAULTS]) >= 1 and len(recorded[topics.SIM_FAULTS]) == 1

    from att_planner.tools.review import review

    done = review(suite.mcap, tmp_path / "review")
    marks = done.summary["faults"]
    assert [(m["component"], m["index"], m["kind"]) for m in marks["injected"]] == [("wheel", SEIZED, "seized")]
    detected = marks["detected"][0]        # wheel_check, then wheel_torque: every detection names the seized wheel
    assert {(d["component"], d["index"]) for d in marks["detected"]} == {("wheel", SEIZED)}
    assert (detected["component"], detected["index"], detected["response"]) == ("wheel", SEIZED, "exclude_wheel")
    assert 0.0 < detected["latency_s"] <= 5.0
    assert marks["replans"] == [plans[1].plan_id]
    assert done.summary["final_attitude_error_deg"] < 0.1
    page = done.html.read_text()
    assert "fault injected" in page and "detected" in page and "exclude_wheel" in page
