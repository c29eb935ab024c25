"""Faults recovered on the client side: a planner killed (SIGKILL) and restarted answers the very
first request sent after the restart, and a goal whose controller is killed mid-maneuver is
reported by SuiteClient.execute as ABORTED within its stall timeout, not after the 600 s timeout."""
from __future__ import annotations

import math
import signal
import time

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_planner.nodes.client import maneuver_request
from att_sim.models import rotations as rot

pytestmark = pytest.mark.ros

SENSOR = np.array([1.0, 0.0, 0.0])
STALL = 5.0             # s: the client's stall timeout in these tests


def kill(suite, name: str) -> None:
    proc = suite.procs[name]
    proc.send_signal(signal.SIGKILL)
    proc.wait(10)


def test_the_first_request_after_a_planner_restart_is_answered(ros_suite):
    request = maneuver_request(rot.IDENTITY, rot.from_axis_angle([0, 0, 1], 0.4), SENSOR, [],
                               method="eigenaxis_smooth")
    with ros_suite("swift_demo", nodes=("planner",), name="planner_restart") as s:
        client = s.client
        assert client.plan_client.wait_for_service(timeout_sec=60)
        assert client.plan(request, timeout=30).success
        for _ in range(2):          # the graph still lists the dead planner(s) when the request is sent
            kill(s.suite, "planner")
            s.suite.start("planner", {"scenario": "swift_demo"})
            response = client.plan(request, timeout=60)
            assert response.success, response.message
            assert s.suite.alive()["planner"]


def test_a_goal_whose_controller_dies_is_reported_aborted(ros_suite):
    with ros_suite("swift_demo", nodes=("simulator", "controller", "planner"), name="controller_killed",
                   params={"controller": {"state_source": "truth"}}) as s:
        client = s.client
        response = client.plan(maneuver_request(rot.IDENTITY, rot.from_axis_angle([0, 0, 1], math.radians(120)),
                                                SENSOR, [], method="eigenaxis_smooth"))
        assert response.success and response.plan.duration > 20.0, response.message
        killed = []

        def on_feedback(_msg):
            if not killed:
                kill(s.suite, "controller")
                killed.append(time.monotonic())

        result = client.execute(response.plan.plan_id, on_feedback=on_feedback, stall_timeout=STALL, timeout=300)
        assert killed, "the maneuver gave no feedback before it ended"
        waited = time.monotonic() - killed[0]
        assert (result.success, result.error_code) == (False, ErrorCode.ABORTED), result.message
        assert "fell silent" in result.message and STALL - 0.5 < waited < STALL + 5.0, (waited, result.message)
        assert all(alive for name, alive in s.suite.alive().items() if name != "controller")
