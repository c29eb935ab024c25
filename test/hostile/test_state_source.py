"""A spoofer cannot take the controller's state input by pausing the real source: with the simulator
(or the estimator) stopped (SIGSTOP) for 3 s while an intruder publishes plausible states (or
estimates) at a high rate (the current attitude, stamps running on from the real ones, a small body
rate) and its own frozen /clock, the controller never acts on an intruder's message, and once the
real source resumes and the intruder stops, the controller is back on it within seconds. A
restarted simulator (the held publisher gone, stamps from 0) is followed as a new timeline."""
from __future__ import annotations

import signal
import time
from dataclasses import replace

import numpy as np
import pytest
import rclpy
from rosgraph_msgs.msg import Clock

from att_msgs.msg import ActuatorCommand, AttitudeEstimate, SpacecraftState
from att_msgs_py import convert, qos, topics
from att_msgs_py.types import Health
from helpers.waiting import wait_until

pytestmark = pytest.mark.ros

PAUSE = 3.0            # s of wall time the simulator is stopped
STEP = 0.05            # s: the simulator's step; every real stamp is a multiple of it
OFFSET = 0.0137        # s: the intruder's stamps sit this far off the simulator's grid


def off_grid(t: float) -> bool:
    """Whether a stamp is not on the simulator's step grid (an intruder's)."""
    return abs(t / STEP - round(t / STEP)) > 1e-3


def spoof_while_paused(s, victim: str, topic: str, kind, heard: list, fake) -> None:
    """Stop ``victim`` (SIGSTOP) for ``PAUSE`` s while an intruder node floods ``topic`` with
    ``fake(last, k)`` (``last``: the victim's latest message, read from ``heard``) and a /clock frozen
    at its stamp; resume the victim; keep flooding until the controller has commanded on 6 of the
    victim's messages after it resumed; then the intruder leaves. Fails unless the controller
    commands on the victim's messages after that, and never on an intruder's (its stamps are off
    the simulator's step grid)."""
    client, commanded = s.client, []
    client.create_subscription(ActuatorCommand, topics.COMMAND,
                               lambda m: commanded.append(convert.from_time(m.header.stamp)), qos.STREAM_QOS)
    wait_until(lambda: len(commanded) > 5 and heard, 30, f"the controller commanding on the {victim}'s messages",
               node=client)
    intruder = rclpy.create_node("intruder", context=client.context)
    fake_pub = intruder.create_publisher(kind, topic, qos.STREAM_QOS)
    fake_clock = intruder.create_publisher(Clock, topics.CLOCK, qos.CLOCK_QOS)
    proc = s.suite.procs[victim]
    proc.send_signal(signal.SIGSTOP)
    try:
        rclpy.spin_once(client, timeout_sec=0.1)
        last = heard[-1]
        t_last = convert.from_time(last.header.stamp)
        frozen = Clock(clock=convert.time_msg(t_last))
        sent = [0]

        def spoof():
            """One plausible message (and the frozen clock) a millisecond after the last."""
            sent[0] += 1
            fake_pub.publish(fake(last, t_last + OFFSET + 0.001 * sent[0]))
            fake_clock.publish(frozen)
            return False

        paused_until = time.monotonic() + PAUSE
        wait_until(lambda: spoof() or time.monotonic() > paused_until, PAUSE + 5, "the intruder's flood",
                   node=client, period=0.001)
    finally:
        proc.send_signal(signal.SIGCONT)
    resumed = len(commanded)
    wait_until(lambda: spoof() or sum(not off_grid(t) and t > t_last for t in commanded[resumed:]) > 5, 20,
               f"the controller commanding on the resumed {victim}'s messages while the intruder floods",
               node=client, period=0.001)
    intruder.destroy_node()                              # the intruder stops
    stopped = len(commanded)
    wait_until(lambda: sum(t > t_last for t in commanded[stopped:]) > 10, 10,
               f"the controller commanding on the {victim}'s messages after the intruder stopped", node=client)
    assert sent[0] > 1000, f"the intruder published only {sent[0]} messages"
    acted = [t for t in commanded if off_grid(t)]
    assert not acted, f"the controller acted on {len(acted)} intruder messages (stamps {acted[:3]})"
    assert "second publisher" in s.suite.log_text("controller")


def test_a_spoofer_cannot_take_the_state_input_while_the_simulator_pauses_and_the_real_one_is_followed_after(
        ros_suite):
    with ros_suite("swift_demo", nodes=("simulator", "controller"), name="state_source",
                   params={"simulator": {"real_time_factor": 1.0},
                           "controller": {"state_source": "truth"}}) as s:
        states = []
        s.client.create_subscription(SpacecraftState, topics.STATE, states.append, qos.STREAM_QOS)

        def fake(last, t):
            state = convert.state_from_msg(last)
            return convert.state_msg(replace(state, t=t, omega=np.array([0.002, -0.001, 0.0])))

        spoof_while_paused(s, "simulator", topics.STATE, SpacecraftState, states, fake)


def test_a_spoofer_cannot_take_the_estimate_input_while_the_estimator_pauses(ros_suite):
    """The controller on the estimate: converged estimates of a rate that does not exist are never
    flown (no safe-mode damping of a phantom rate)."""
    with ros_suite("swift_demo", nodes=("simulator", "estimator", "controller"), name="estimate_source",
                   params={"simulator": {"real_time_factor": 1.0}}) as s:
        estimates = []
        s.client.create_subscription(AttitudeEstimate, topics.ESTIMATE, estimates.append, qos.STREAM_QOS)

        def fake(last, t):
            estimate = convert.estimate_from_msg(last)
            return convert.estimate_msg(replace(estimate, t=t, omega=np.array([0.05, 0.0, 0.0]),
                                                health=int(Health.CONVERGED)))

        spoof_while_paused(s, "estimator", topics.ESTIMATE, AttitudeEstimate, estimates, fake)


def test_a_restarted_simulator_is_followed_as_a_new_timeline(ros_suite):
    """The held publisher leaves the graph (the simulator stopped) and a new one appears whose stamps
    start again at 0: the controller takes it (a new timeline, logged) and commands on its states.
    The graph can show the stopped publisher for seconds after its process exits (on a loaded machine
    it was 2.3 s), and the new simulator's time runs meanwhile: the first one runs past t = 10 s and
    the second at real time, so the new timeline is taken while its stamps are still below the old."""
    with ros_suite("swift_demo", nodes=("simulator", "controller"), name="state_source_restart",
                   params={"simulator": {"real_time_factor": 2.0},
                           "controller": {"state_source": "truth"}}) as s:
        client, commanded = s.client, []
        client.create_subscription(ActuatorCommand, topics.COMMAND,
                                   lambda m: commanded.append(convert.from_time(m.header.stamp)), qos.STREAM_QOS)
        wait_until(lambda: commanded and commanded[-1] > 10.0, 30, "the controller commanding past t = 10 s",
                   node=client)
        simulator = s.suite.procs["simulator"]
        simulator.send_signal(signal.SIGINT)
        assert simulator.wait(10) == 0
        before = len(commanded)
        last = max(commanded)
        s.suite.start("simulator", {"scenario": "swift_demo", "real_time_factor": 1.0})
        wait_until(lambda: sum(t < last for t in commanded[before:]) > 10, 30,
                   "the controller commanding on the restarted simulator's states", node=client)
        assert "timeline restarted" in s.suite.log_text("controller")
