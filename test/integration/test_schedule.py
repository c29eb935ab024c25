"""PlanSchedule over ROS: a 2-target tour planned by the planner node, verified, executed; the first
target observed (held for a dwell), the second flown through."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs.srv import PlanSchedule
from att_msgs_py import convert
from att_msgs_py.errors import ErrorCode
from att_msgs_py.log import read_log
from att_msgs_py.topics import COMMAND, STATE
from att_planner.reference.olivares_staffetti import olivares_targets
from att_sim.models import rotations as rot

pytestmark = pytest.mark.ros
DWELL = 20.0                  # s held on target a


def schedule_request(names, targets, budget=120.0):
    req = PlanSchedule.Request(target_names=list(names), spacecraft="olivares_staffetti", time_budget=budget)
    req.targets = [convert.quaternion(q) for q in targets]
    req.start_attitude = convert.quaternion(rot.IDENTITY)
    return req


def test_schedule_is_planned_verified_and_executed(ros_suite):
    with ros_suite("olivares_staffetti", schedule=True, name="schedule_test") as s:
        client = s.client
        bad = client.schedule(schedule_request(["a", "a"], [rot.IDENTITY, rot.IDENTITY]))
        assert not bad.success and bad.error_code == ErrorCode.INVALID_ATTITUDE and "distinct" in bad.message
        targets = olivares_targets("A")
        names = ["a", "b"]
        short = schedule_request(names, [targets[n] for n in names])
        short.dwell_times, short.window_opens, short.window_closes = [20.0, 0.0], [0.0, 0.0], [10.0, math.inf]
        bad = client.schedule(short)
        assert not bad.success and bad.error_code == ErrorCode.INVALID_OBSERVATION and "needs 20 s" in bad.message
        request = schedule_request(names, [targets[n] for n in names])
        request.dwell_times = [DWELL, 0.0]
        response = client.schedule(request)
        assert response.success, response.message
        assert sorted(response.order) == names and len(response.passage_times) == 2
        held = dict(zip(response.order, zip(response.passage_times, response.observation_ends)))
        assert held["a"][1] - held["a"][0] == pytest.approx(DWELL) and held["b"][1] == held["b"][0]
        plan = response.plan
        assert plan.control_kind == "wheel_torque" and plan.verification.final_attitude_error < math.radians(0.5)
        result = client.execute(plan.plan_id)
        assert result.success, result.message
        assert result.final_attitude_error < math.radians(0.5)
        codes = s.stop()
    assert all(c == 0 for c in codes.values()), codes
    log = read_log(s.mcap, topics=[STATE, COMMAND])
    t, q = log[STATE]["header.stamp"], log[STATE]["attitude"]
    tracking = np.flatnonzero(log[COMMAND]["plan_id"] == plan.plan_id)
    assert tracking.size, "no command tracked the plan"
    t0 = log[COMMAND]["header.stamp"][tracking[0]]      # the first command of the plan: its t = 0
    for name, tp in zip(response.order, response.passage_times):
        k = int(np.argmin(np.abs(t - (t0 + tp))))
        assert rot.angle_between(q[k], targets[name]) < math.radians(2.0), name
    start, end = held["a"]          # observed: on the target through the whole dwell
    during = (t >= t0 + start + 1.0) & (t <= t0 + end)
    assert during.sum() >= 10
    assert max(rot.angle_between(qk, targets["a"]) for qk in q[during]) < math.radians(2.0)
