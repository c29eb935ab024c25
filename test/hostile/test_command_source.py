"""Actuator commands are held to their source: a valid-looking command from a second publisher is
not applied while the controller lives, and the simulator follows a new publisher only once the
held one is gone (no accepted command for ``command_timeout`` s of sim time)."""
from __future__ import annotations

import time

import numpy as np
import pytest
import rclpy

from att_msgs.msg import ActuatorCommand, SpacecraftState
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Command, ControlMode
from att_sim.truth.simulation import CommandSource

CONTROLLER, INTRUDER = b"controller-gid", b"intruder-gid"


def test_a_second_publisher_is_refused_while_the_first_lives():
    held = CommandSource(timeout=1.0)
    assert held.check(CONTROLLER, 0.0) is None
    held.accept(CONTROLLER, 0.0)
    for t in (0.0, 0.5, 1.0):
        refused = held.check(INTRUDER, t)
        assert refused.code == ErrorCode.INVALID_COMMAND and "second publisher" in refused.message
    assert held.check(CONTROLLER, 0.9) is None
    held.accept(CONTROLLER, 0.9)
    assert held.check(INTRUDER, 1.5) is not None              # 0.6 s after the controller's last command


def test_a_new_publisher_is_followed_once_the_held_one_is_gone():
    held = CommandSource(timeout=1.0)
    held.accept(CONTROLLER, 2.0)
    assert held.check(INTRUDER, 3.01) is None                  # silent for more than the timeout: gone
    held.accept(INTRUDER, 3.01)
    assert held.source == INTRUDER
    assert held.check(CONTROLLER, 3.5).code == ErrorCode.INVALID_COMMAND   # and now the new one is held


def test_sources_the_middleware_does_not_name_are_not_compared():
    held = CommandSource(timeout=1.0)
    held.accept(None, 0.0)
    assert held.source is None and held.check(INTRUDER, 0.1) is None
    held.accept(INTRUDER, 0.1)
    assert held.check(None, 0.2) is None
    held.accept(None, 0.2)
    assert held.source == INTRUDER and held.last_t == 0.2


def command(t: float, wheel_x: float) -> ActuatorCommand:
    return convert.command_msg(Command(t=t, mode=ControlMode.PLAN_TRACKING, wheel_torques=np.array([wheel_x, 0.0, 0.0]),
                                       dipole=np.zeros(3), body_torque=np.zeros(3)))


def spin_until(client, done, seconds: float, each=None) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if each is not None:
            each()
        if done():
            return True
        rclpy.spin_once(client, timeout_sec=0.002)
    return done()


@pytest.mark.ros
def test_a_second_publishers_command_is_not_applied_while_the_controller_answers(ros_suite):
    with ros_suite("swift_demo", nodes=("simulator",), params={"simulator": {"real_time_factor": 4.0}},
                   name="command_source") as s:
        client, states, latest = s.client, [], [0.0]

        def on_state(msg):
            states.append(msg)
            latest[0] = convert.from_time(msg.header.stamp)

        client.create_subscription(SpacecraftState, topics.STATE, on_state, qos.STREAM_QOS)
        controller = client.create_publisher(ActuatorCommand, topics.COMMAND, qos.STREAM_QOS)
        intruder = client.create_publisher(ActuatorCommand, topics.COMMAND, qos.STREAM_QOS)
        answered = set()

        def both():
            if latest[0] not in answered:                      # the controller answers every state
                answered.add(latest[0])
                controller.publish(command(latest[0], 0.0))
            intruder.publish(command(latest[0], 0.12))         # a valid command, current stamp

        assert spin_until(client, lambda: len(states) > 20, 30.0)
        assert spin_until(client, lambda: sum(not m.command_timeout for m in states) > 40, 20.0, both), \
            "the controller's commands were never applied"
        applied = [m for m in states if not m.command_timeout]
        assert max(abs(m.wheel_torques[0]) for m in applied) < 0.01, "the intruder's torque was applied"
        assert "second publisher" in s.suite.log_text("simulator")
        states.clear()                                         # the controller stops: gone after command_timeout

        def intruder_only():
            intruder.publish(command(latest[0], 0.12))
            time.sleep(0.005)  # wait-ok: pacing of the intruder's publications, not a wait

        assert spin_until(client, lambda: any(abs(m.wheel_torques[0] - 0.12) < 2e-3 for m in states), 20.0,
                          intruder_only), "a new publisher was never followed once the held one had gone"
