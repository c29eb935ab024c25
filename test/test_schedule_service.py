"""PlanSchedule over ROS: a 2-target tour planned by the planner node, verified, executed."""
from __future__ import annotations

import math

import numpy as np

from att_msgs.srv import PlanSchedule
from att_msgs_py import convert
from att_msgs_py.errors import ErrorCode
from att_msgs_py.mcap_log import read_log
from att_planner.client_node import client_session
from att_planner.launch import isolated_env, join_env, start_suite
from att_planner.schedule import olivares_targets
from att_sim import rotations as rot


def schedule_request(names, targets, budget=120.0):
    req = PlanSchedule.Request(target_names=list(names), spacecraft="olivares_staffetti", time_budget=budget)
    req.targets = [convert.quaternion(q) for q in targets]
    req.start_attitude = convert.quaternion(rot.IDENTITY)
    return req


def test_schedule_is_planned_verified_and_executed(tmp_path):
    env = isolated_env()
    join_env(env)
    suite = start_suite("olivares_staffetti", tmp_path / "run.mcap", tmp_path, env=env)
    try:
        with client_session("schedule_test") as client:
            client.wait_for_servers(timeout=60, schedule=True)
            bad = client.schedule(schedule_request(["a", "a"], [rot.IDENTITY, rot.IDENTITY]))
            assert not bad.success and bad.error_code == ErrorCode.INVALID_ATTITUDE and "distinct" in bad.message
            targets = olivares_targets("A")
            names = ["a", "b"]
            response = client.schedule(schedule_request(names, [targets[n] for n in names]))
            assert response.success, response.message
            assert sorted(response.order) == names and len(response.passage_times) == 2
            plan = response.plan
            assert plan.control_kind == "wheel_torque" and plan.verification.final_attitude_error < math.radians(0.5)
            result = client.execute(plan.plan_id)
            assert result.success, result.message
            assert result.final_attitude_error < math.radians(0.5)
    finally:
        codes = suite.stop()
    assert all(c == 0 for c in codes.values()), codes
    state = read_log(tmp_path / "run.mcap", topics=["/spacecraft/state"])["/spacecraft/state"]
    t, q = state["header.stamp"], state["attitude"]
    t0 = t[-1] - (plan.duration + 10.0)          # the execution started settle_time + duration before the end
    for name, tp in zip(response.order, response.passage_times):
        k = int(np.argmin(np.abs(t - (t0 + tp))))
        assert rot.angle_between(q[k], targets[name]) < math.radians(2.0), name
