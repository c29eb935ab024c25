"""Plans whose fields contradict each other are refused before anything is flown (no ROS).

A plan message carries its ``duration`` besides its ``times``; a correctly signed message whose
duration says -5 s, NaN or 1e308 s while its times end at 10 s contradicts itself and is refused
(:func:`att_planner.control.plan_checks.check_message`, called by the controller node on every
published and inline plan before conversion) with a sentence naming the field.
"""
from __future__ import annotations

import math

import pytest
import rclpy
from action_msgs.msg import GoalStatus

from att_msgs.action import ExecuteManeuver
from att_msgs_py import convert, signing
from att_msgs_py.errors import ErrorCode
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.control.plan_checks import check_message
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario
from helpers.signed_plans import KEY, context, issue

SWIFT = scenario.load("swift_demo")


def signed_message(key=KEY, **fields):
    """A good plan's message ending at 10 s, ``fields`` changed, then signed with the planner's key."""
    plan = plan_eigenaxis_smooth(ManeuverProblem(SWIFT.spacecraft, rot.IDENTITY, rot.from_axis_angle([0, 0, 1], 0.3)),
                                 samples=51)
    plan.t = plan.t * (10.0 / plan.t[-1])
    ctx = context()
    plan.plan_id, plan.spacecraft, plan.frame_id = "p", ctx.spacecraft_name, ctx.frame_id
    plan.spacecraft_digest = ctx.spacecraft.digest
    msg = convert.plan_msg(plan)
    for name, value in fields.items():
        setattr(msg, name, value)
    signing.sign(msg, key)
    return msg


def test_a_consistent_plan_message_passes():
    msg = signed_message()
    assert msg.times[-1] == 10.0 and msg.duration == 10.0 and check_message(msg) is None


@pytest.mark.parametrize("duration", [-5.0, math.nan, 1e308, math.inf, -math.inf, 0.0, 9.99, 10.001])
def test_a_duration_that_contradicts_the_times_is_refused(duration):
    refused = check_message(signed_message(duration=duration))
    assert refused.code == ErrorCode.INVALID_PLAN and "plan.duration" in refused.message, refused.message
    assert "10.0" in refused.message                  # the span of the times it contradicts


@pytest.mark.parametrize("solve_seconds, words", [(math.nan, "nan"), (-1.0, "-1.0"), (math.inf, "inf")])
def test_a_non_finite_or_negative_solve_time_is_refused(solve_seconds, words):
    core = Controller(context(), ControllerConfig(control_period=0.1), body_frame_id="body")
    msg = signed_message(solve_seconds=solve_seconds)
    plan, payload = convert.plan_from_msg(msg), signing.payload(msg)
    for refused in (core.resolve("", plan, payload)[1], core.receive_plan(plan, payload)):
        assert refused.code == ErrorCode.INVALID_PLAN and "plan.solve_seconds" in refused.message
        assert words in refused.message
    assert core.maneuver is None and not core.plans


def test_a_plan_without_samples_is_left_to_the_field_checks():
    """No times: check_message has no span to compare; check_plan refuses the sample count."""
    msg = signed_message(times=[], duration=-5.0)
    assert check_message(msg) is None
    core = Controller(context(), ControllerConfig(control_period=0.1), body_frame_id="body")
    refused = core.resolve("", *issue(convert.plan_from_msg(msg), context(), "p"))[1]
    assert refused.code == ErrorCode.INVALID_PLAN and "samples" in refused.message


@pytest.mark.ros
def test_the_controller_node_refuses_an_inline_plan_whose_duration_contradicts_its_times(ros_suite):
    ground = signing.load_private_key(signing.default_key_dir() / signing.PRIVATE_NAME)
    with ros_suite("swift_demo", nodes=("controller",), name="plan_fields_test",
                   params={"controller": {"state_source": "truth"}}) as s:
        client = s.client
        assert client.execute_client.wait_for_server(timeout_sec=30)
        for duration in (-5.0, math.nan, 1e308):
            goal = ExecuteManeuver.Goal(use_inline_plan=True, plan=signed_message(ground, duration=duration))
            send = client.execute_client.send_goal_async(goal)
            rclpy.spin_until_future_complete(client, send, timeout_sec=20)
            handle = send.result()
            assert handle is not None and handle.accepted
            done = handle.get_result_async()
            rclpy.spin_until_future_complete(client, done, timeout_sec=20)
            assert done.done(), "the goal was never answered"
            result = done.result().result
            assert done.result().status == GoalStatus.STATUS_ABORTED, (done.result().status, result.message)
            assert not result.success and result.error_code == ErrorCode.INVALID_PLAN, result.message
            assert "plan.duration" in result.message
