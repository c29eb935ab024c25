"""Actuator commands are held to their source: a valid-looking command from a second publisher is
not applied while the held publisher (the controller) is in the ROS graph, however long it is
silent, and the simulator follows a new publisher only once the held one has left the graph."""
from __future__ import annotations

import time

import numpy as np
import pytest
import rclpy

from att_msgs.msg import ActuatorCommand, SpacecraftState
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Command, ControlMode
from att_sim.models import scenario
from att_sim.truth.simulation import Simulation

CONTROLLER, INTRUDER = b"controller-gid", b"intruder-gid"
SWIFT = scenario.load("swift_demo")


def simulation(*publishers):
    """A simulation whose command topic lists ``publishers`` in the graph (a set to edit)."""
    sim = Simulation(SWIFT.spacecraft, SWIFT.orbit)
    live = set(publishers)
    sim.command_source.live = lambda: live
    return sim, live


def torque(sim, wheel_x: float) -> Command:
    return Command(t=sim.t, mode=ControlMode.PLAN_TRACKING, wheel_torques=np.array([wheel_x, 0.0, 0.0]),
                   dipole=np.zeros(3), body_torque=np.zeros(3))


def test_a_second_publisher_is_refused_while_the_first_is_in_the_graph_however_long_it_is_silent():
    sim, _ = simulation(CONTROLLER, INTRUDER)
    assert sim.set_command(torque(sim, 0.0), CONTROLLER) is None
    for _ in range(100):                                      # the controller paused 5 s of sim time
        sim.advance(0.05)
        refused = sim.set_command(torque(sim, 0.12), INTRUDER)
        assert refused.code == ErrorCode.INVALID_COMMAND and "second publisher" in refused.message
    assert np.all(sim.wheel_cmd == 0.0)
    assert sim.set_command(torque(sim, 0.01), CONTROLLER) is None and sim.wheel_cmd[0] == 0.01


def test_a_new_publisher_is_followed_once_the_held_one_has_left_the_graph():
    sim, live = simulation(CONTROLLER, INTRUDER)
    sim.set_command(torque(sim, 0.0), CONTROLLER)
    live.discard(CONTROLLER)                                  # the controller stopped (or restarted)
    assert sim.set_command(torque(sim, 0.02), INTRUDER) is None and sim.wheel_cmd[0] == 0.02
    assert sim.command_source.held == INTRUDER
    live.add(CONTROLLER)
    assert sim.set_command(torque(sim, 0.0), CONTROLLER).code == ErrorCode.INVALID_COMMAND   # now the new one is held


def test_a_refused_command_never_takes_the_hold():
    sim, _ = simulation(CONTROLLER, INTRUDER)
    bad = torque(sim, float("nan"))
    assert sim.set_command(bad, INTRUDER).code == ErrorCode.INVALID_COMMAND
    assert sim.command_source.held is None
    assert sim.set_command(torque(sim, 0.0), CONTROLLER) is None and sim.command_source.held == CONTROLLER


def test_sources_the_middleware_does_not_name_are_not_compared():
    sim, _ = simulation(INTRUDER)
    assert sim.set_command(torque(sim, 0.0), None) is None and sim.command_source.held is None
    assert sim.set_command(torque(sim, 0.0), INTRUDER) is None
    assert sim.set_command(torque(sim, 0.0), None) is None and sim.command_source.held == INTRUDER


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

        def intruder_only():
            intruder.publish(command(latest[0], 0.12))
            time.sleep(0.005)  # wait-ok: pacing of the intruder's publications, not a wait

        states.clear()                                         # the controller silent, still in the graph
        assert spin_until(client, lambda: len(states) > 60, 30.0, intruder_only)
        assert all(m.command_timeout and m.wheel_torques[0] == 0.0 for m in states[20:]), \
            "a silent controller's input was handed to the intruder"
        client.destroy_publisher(controller)                   # the controller stops: it leaves the graph
        states.clear()
        assert spin_until(client, lambda: any(abs(m.wheel_torques[0] - 0.12) < 2e-3 for m in states), 20.0,
                          intruder_only), "a new publisher was never followed once the held one had gone"
