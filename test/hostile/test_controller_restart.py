"""Faults: the controller is killed mid-maneuver; the simulator keeps its real-time factor with
inputs zeroed and flagged; a restarted controller finds the spacecraft rotating and damps it by itself."""
from __future__ import annotations

import signal
import time

import numpy as np
import pytest
import rclpy

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import ControllerStatus, SpacecraftState
from att_msgs_py import convert, qos, signing, topics
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario

pytestmark = pytest.mark.ros

RTF = 4.0


def signed_plan_msg(goal):
    s = scenario.load("swift_demo")
    plan = plan_eigenaxis_smooth(ManeuverProblem(s.spacecraft, rot.IDENTITY, goal))
    plan.plan_id, plan.spacecraft, plan.frame_id = "restart_test", s.name, s.frame_id
    plan.spacecraft_digest = s.spacecraft.digest
    msg = convert.plan_msg(plan)
    signing.sign(msg, signing.load_private_key(signing.default_key_dir() / signing.PRIVATE_NAME))
    return msg


def collect(client, seconds, states):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        rclpy.spin_once(client, timeout_sec=0.05)
    return [convert.state_from_msg(m) for m in states]


def wait_for(client, seconds, condition):
    """Spin until ``condition()`` holds (True) or ``seconds`` of wall time pass (False)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if condition():
            return True
        rclpy.spin_once(client, timeout_sec=0.05)
    return condition()


def rate_of(msg) -> float:
    return float(np.linalg.norm(convert.state_from_msg(msg).omega))


@pytest.mark.slow                                   # 20-40 s on the 2-core machine
def test_killed_controller_then_restarted_controller_damps_the_coasting_spacecraft(ros_suite):
    with ros_suite("swift_demo", nodes=("simulator", "controller"), name="restart_test",
                   params={"simulator": {"real_time_factor": RTF}, "controller": {"state_source": "truth"}}) as s:
        client, suite = s.client, s.suite
        assert client.execute_client.wait_for_server(timeout_sec=30)
        received, statuses = [], []
        client.create_subscription(SpacecraftState, topics.STATE, received.append, qos.STREAM_QOS)
        client.create_subscription(ControllerStatus, topics.CONTROLLER_STATUS, statuses.append, qos.STREAM_QOS)
        # A goal sent before the controller has a state is answered NO_STATE: wait until it steps.
        assert wait_for(client, 30, lambda: any(not m.state_stale for m in statuses)), "controller never stepped"
        send = client.execute_client.send_goal_async(
            ExecuteManeuver.Goal(use_inline_plan=True, plan=signed_plan_msg(rot.from_axis_angle([0, 0, 1], 1.5))))
        rclpy.spin_until_future_complete(client, send, timeout_sec=20)
        assert send.result().accepted
        result = send.result().get_result_async()
        turning = wait_for(client, 30, lambda: bool(received) and rate_of(received[-1]) > 0.01)
        assert turning and not result.done(), "the maneuver did not start"       # mid-slew: the spacecraft turns
        suite.procs["controller"].send_signal(signal.SIGKILL)
        suite.procs["controller"].wait(10)
        received.clear()
        wall0 = time.monotonic()
        dead = collect(client, 6.0, received)
        wall = time.monotonic() - wall0
        assert dead, "the simulator stopped publishing without a controller"
        sim_rate = (dead[-1].t - dead[0].t) / wall
        assert sim_rate > 0.6 * RTF, f"without a controller the simulator ran at {sim_rate:.2f}x, not ~{RTF}x"
        assert dead[-1].command_timeout, "inputs zeroed but not flagged"
        coasting = np.linalg.norm(dead[-1].omega)
        assert coasting > 0.005, f"the spacecraft should coast mid-slew (rate {coasting:.4f} rad/s)"
        suite.start("controller", {"scenario": "swift_demo", "state_source": "truth"})
        assert suite.wait_for_output("controller", "safe mode", 60), suite.log_text("controller")[-2000:]
        received.clear()

        def damped():
            last = convert.state_from_msg(received[-1]) if received else None
            return last is not None and np.linalg.norm(last.omega) < 0.3 * coasting and not last.command_timeout

        assert wait_for(client, 60, damped), "the restarted controller did not damp the rate"
