"""Spoofing over ROS: a forged plan (no or a wrong signature, a reused id, another spacecraft, a far
start) is never flown; hand-published states and goals never stall or steer the controller."""
from __future__ import annotations

import math
import re
import time

import numpy as np
import pytest
import rclpy
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import ManeuverPlan, SpacecraftState
from att_msgs_py import convert, qos, signing, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import State
from att_planner.nodes.client import maneuver_request
from att_sim.models import rotations as rot
from helpers.from_here import SENSOR, latest_state, plan_from_here
from helpers.node_logs import LogMark
from helpers.waiting import wait_until

pytestmark = pytest.mark.ros


@pytest.fixture(scope="module")
def suite(ros_suite):
    with ros_suite("swift_demo", nodes=("simulator", "controller", "planner"),
                   params={"simulator": {"real_time_factor": 0.0},
                           "controller": {"settle_time_s": 5.0, "state_source": "truth"}},
                   name="spoofing_test") as s:
        yield s


def publish_plans(client, msgs, settle=1.0):
    pub = client.create_publisher(ManeuverPlan, topics.PLANS, qos.LATCHED_QOS)
    for m in msgs:
        pub.publish(m)
    end = time.monotonic() + settle
    while time.monotonic() < end:
        rclpy.spin_once(client, timeout_sec=0.05)
    client.destroy_publisher(pub)


def forge(plan_msg: ManeuverPlan, goal, key=None) -> ManeuverPlan:
    """A plan with ``plan_msg``'s id that ends at ``goal``, unsigned or signed by ``key``."""
    forged = ManeuverPlan()
    for name in plan_msg.get_fields_and_field_types():
        setattr(forged, name, getattr(plan_msg, name))
    forged.attitudes = [convert.quaternion(rot.slerp(convert.from_quaternion(plan_msg.attitudes[0]), goal, s))
                        for s in np.linspace(0, 1, len(plan_msg.times))]
    forged.signature = b""
    if key is not None:
        signing.sign(forged, key)
    return forged


def test_forged_plans_with_a_real_id_are_never_flown_and_never_evict_it(suite):
    client = suite.client
    mark = LogMark(suite.suite, "controller")
    real, goal = plan_from_here(client, 0.6)
    q0 = convert.from_quaternion(real.attitudes[0])
    elsewhere = rot.from_axis_angle([1, 0, 0], 1.5)
    attacker = Ed25519PrivateKey.generate()
    forged = [forge(real, elsewhere), forge(real, elsewhere, attacker)]
    forged += [forge(real, elsewhere, attacker) for _ in range(60)]
    for i, m in enumerate(forged[2:]):
        m.plan_id = f"forged_{i}"
        signing.sign(m, attacker)
    publish_plans(client, forged)
    result = client.execute(real.plan_id)
    assert result.success, result.message
    final = latest_state(client).q
    assert rot.angle_between(final, goal) < math.radians(0.5), "the forged plan was flown"
    assert rot.angle_between(final, elsewhere) > math.radians(30) and rot.angle_between(q0, goal) > 0.5
    # refusals are logged once a second per kind (another test's refused plan may have taken the
    # second): the unsigned forgery is published again until one of this test's is logged
    pub = client.create_publisher(ManeuverPlan, topics.PLANS, qos.LATCHED_QOS)
    wait_until(lambda: re.search(r"published plan refused .*PLAN_NOT_AUTHENTIC", mark.text())
               or pub.publish(forged[0]), 20, "a published forgery refused as not authentic", node=client)
    client.destroy_publisher(pub)
    log = suite.suite.log_text("controller")          # the whole log: the suite's first second is checked
    stamps = {kind: [float(m) for m in re.findall(rf"\[(\d+\.\d+)\] \[controller\]: {kind}", log)]
              for kind in ("scenario", "no state for")}
    assert stamps["scenario"], log[:500]
    assert all(t - stamps["scenario"][0] >= 1.0 for t in stamps["no state for"]), "'no state' in the first second"


def send_goal(client, goal: ExecuteManeuver.Goal, timeout=60.0):
    send = client.execute_client.send_goal_async(goal)
    rclpy.spin_until_future_complete(client, send, timeout_sec=20)
    handle = send.result()
    assert handle is not None and handle.accepted
    done = handle.get_result_async()
    rclpy.spin_until_future_complete(client, done, timeout_sec=timeout)
    assert done.done(), "the goal was never answered"
    return done.result().result


def test_inline_plans_that_are_forged_or_malformed_are_refused_and_the_controller_keeps_serving(suite):
    client = suite.client
    real, _ = plan_from_here(client, 0.4)
    key = signing.load_private_key(signing.default_key_dir() / signing.PRIVATE_NAME)
    cases = []
    unsigned = forge(real, rot.from_axis_angle([0, 1, 0], 1.0))
    cases.append(("unsigned", unsigned, ErrorCode.PLAN_NOT_AUTHENTIC))
    short_rates = forge(real, convert.from_quaternion(real.attitudes[-1]))
    short_rates.rates = list(short_rates.rates)[:-5]
    signing.sign(short_rates, key)                  # even a correctly signed plan is checked field by field
    cases.append(("rates shorter than times", short_rates, ErrorCode.INVALID_PLAN))
    nan_duration = forge(real, convert.from_quaternion(real.attitudes[-1]))
    nan_duration.times = list(nan_duration.times)[:-1] + [float("nan")]
    signing.sign(nan_duration, key)
    cases.append(("NaN duration", nan_duration, ErrorCode.INVALID_PLAN))
    negative = forge(real, convert.from_quaternion(real.attitudes[-1]))
    negative.times = [-t for t in negative.times]
    signing.sign(negative, key)
    cases.append(("negative duration", negative, ErrorCode.INVALID_PLAN))
    cubic = forge(real, convert.from_quaternion(real.attitudes[-1]))
    cubic.interpolation = "cubic"
    signing.sign(cubic, key)
    cases.append(("unknown interpolation", cubic, ErrorCode.INVALID_PLAN))
    zero_q = forge(real, convert.from_quaternion(real.attitudes[-1]))
    zero_q.attitudes[3] = convert.quaternion([0, 0, 0, 0])
    signing.sign(zero_q, key)
    cases.append(("zero quaternion", zero_q, ErrorCode.INVALID_PLAN))
    for name, msg, code in cases:
        result = send_goal(client, ExecuteManeuver.Goal(use_inline_plan=True, plan=msg))
        assert not result.success and result.error_code == code, (name, result.message)
    assert all(suite.suite.alive().values())
    result = client.execute(real.plan_id)            # still serving
    assert result.success, result.message


def test_plans_for_another_spacecraft_or_a_far_start_are_refused(suite):
    client = suite.client
    q0 = latest_state(client).q
    other = client.plan(maneuver_request(q0, rot.multiply(q0, rot.from_axis_angle([0, 0, 1], 0.3)), SENSOR, [],
                                         method="eigenaxis_smooth", spacecraft="olivares_staffetti"))
    assert other.success, other.message
    result = client.execute(other.plan.plan_id)
    assert result.error_code == ErrorCode.WRONG_SPACECRAFT, result.message
    far_start = rot.multiply(q0, rot.from_axis_angle([0, 1, 0], math.radians(132)))
    far = client.plan(maneuver_request(far_start, rot.multiply(far_start, rot.from_axis_angle([0, 0, 1], 0.3)),
                                       SENSOR, [], method="eigenaxis_smooth"))
    assert far.success, far.message
    result = client.execute(far.plan.plan_id)
    assert result.error_code == ErrorCode.PLAN_CONTEXT and "132" in result.message, result.message


def test_a_hand_published_state_far_in_the_future_stalls_nothing(suite):
    client = suite.client
    mark = LogMark(suite.suite, "controller")
    pub = client.create_publisher(SpacecraftState, topics.STATE, qos.STREAM_QOS)
    fake = convert.state_msg(State(t=1e6, q=rot.IDENTITY, omega=np.zeros(3), wheel_speeds=np.zeros(3),
                                   frame_id="eci", body_frame_id="body"))
    end = time.monotonic() + 1.0
    while time.monotonic() < end:
        pub.publish(fake)
        rclpy.spin_once(client, timeout_sec=0.05)
    client.destroy_publisher(pub)
    real, _ = plan_from_here(client, 0.3)
    result = client.execute(real.plan_id, timeout=60)
    assert result.success, result.message
    assert "STATE_TIME_JUMP" in mark.text() or "second publisher" in mark.text()

