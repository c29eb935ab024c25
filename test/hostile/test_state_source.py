"""A spoofer cannot take the controller's state input by pausing the real source: with the simulator
stopped (SIGSTOP) for 3 s while an intruder publishes plausible states at a high rate (the current
attitude, stamps running on from the simulator's, a small body rate) and its own frozen /clock, the
controller never acts on an intruder's state, and once the simulator resumes and the intruder
stops, the controller is back on the simulator's states within seconds."""
from __future__ import annotations

import signal
import time
from dataclasses import replace

import numpy as np
import pytest
import rclpy
from rosgraph_msgs.msg import Clock

from att_msgs.msg import ActuatorCommand, SpacecraftState
from att_msgs_py import convert, qos, topics
from helpers.waiting import wait_until

pytestmark = pytest.mark.ros

PAUSE = 3.0            # s of wall time the simulator is stopped
STEP = 0.05            # s: the simulator's step; every real stamp is a multiple of it
OFFSET = 0.0137        # s: the intruder's stamps sit this far off the simulator's grid


def off_grid(t: float) -> bool:
    """Whether a stamp is not on the simulator's step grid (an intruder's)."""
    return abs(t / STEP - round(t / STEP)) > 1e-3


def test_a_spoofer_cannot_take_the_state_input_while_the_simulator_pauses_and_the_real_one_is_followed_after(
        ros_suite):
    with ros_suite("swift_demo", nodes=("simulator", "controller"), name="state_source",
                   params={"simulator": {"real_time_factor": 1.0},
                           "controller": {"state_source": "truth"}}) as s:
        client, states, commanded = s.client, [], []
        client.create_subscription(SpacecraftState, topics.STATE, states.append, qos.STREAM_QOS)
        client.create_subscription(ActuatorCommand, topics.COMMAND,
                                   lambda m: commanded.append(convert.from_time(m.header.stamp)), qos.STREAM_QOS)
        wait_until(lambda: len(commanded) > 5 and states, 30, "the controller commanding on the simulator's states",
                   node=client)
        intruder = rclpy.create_node("intruder", context=client.context)
        fake_states = intruder.create_publisher(SpacecraftState, topics.STATE, qos.STREAM_QOS)
        fake_clock = intruder.create_publisher(Clock, topics.CLOCK, qos.CLOCK_QOS)
        simulator = s.suite.procs["simulator"]
        simulator.send_signal(signal.SIGSTOP)
        try:
            rclpy.spin_once(client, timeout_sec=0.1)
            last = convert.state_from_msg(states[-1])
            frozen = Clock(clock=convert.time_msg(last.t))
            sent = [0]

            def spoof():
                """One plausible state (and the frozen clock) a millisecond after the last."""
                sent[0] += 1
                t = last.t + OFFSET + 0.001 * sent[0]
                fake_states.publish(convert.state_msg(replace(last, t=t, omega=np.array([0.002, -0.001, 0.0]))))
                fake_clock.publish(frozen)
                return False

            paused_until = time.monotonic() + PAUSE
            wait_until(lambda: spoof() or time.monotonic() > paused_until, PAUSE + 5, "the intruder's flood",
                       node=client, period=0.001)
        finally:
            simulator.send_signal(signal.SIGCONT)
        resumed = len(commanded)
        wait_until(lambda: spoof() or sum(not off_grid(t) and t > last.t for t in commanded[resumed:]) > 5, 15,
                   "the controller commanding on the resumed simulator's states while the intruder floods",
                   node=client, period=0.001)
        intruder.destroy_node()                              # the intruder stops
        stopped = len(commanded)
        wait_until(lambda: sum(t > last.t for t in commanded[stopped:]) > 10, 10,
                   "the controller commanding on the simulator's states after the intruder stopped", node=client)
        assert sent[0] > 1000, f"the intruder published only {sent[0]} states"
        acted = [t for t in commanded if off_grid(t)]
        assert not acted, f"the controller acted on {len(acted)} intruder states (stamps {acted[:3]})"
        assert "second publisher" in s.suite.log_text("controller")


def test_a_restarted_simulator_is_followed_as_a_new_timeline(ros_suite):
    """The held publisher leaves the graph (the simulator stopped) and a new one appears whose stamps
    start again at 0: the controller takes it (a new timeline, logged) and commands on its states."""
    with ros_suite("swift_demo", nodes=("simulator", "controller"), name="state_source_restart",
                   params={"simulator": {"real_time_factor": 2.0},
                           "controller": {"state_source": "truth"}}) as s:
        client, commanded = s.client, []
        client.create_subscription(ActuatorCommand, topics.COMMAND,
                                   lambda m: commanded.append(convert.from_time(m.header.stamp)), qos.STREAM_QOS)
        wait_until(lambda: commanded and commanded[-1] > 5.0, 30, "the controller commanding past t = 5 s",
                   node=client)
        simulator = s.suite.procs["simulator"]
        simulator.send_signal(signal.SIGINT)
        assert simulator.wait(10) == 0
        before = len(commanded)
        s.suite.start("simulator", {"scenario": "swift_demo", "real_time_factor": 2.0})
        wait_until(lambda: sum(t < 5.0 for t in commanded[before:]) > 10, 30,
                   "the controller commanding on the restarted simulator's states", node=client)
        assert "timeline restarted" in s.suite.log_text("controller")
