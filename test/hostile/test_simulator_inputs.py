"""Hostile inputs to the simulator: actuator commands and resets, refused with a code and a sentence.

The ROS-free cases drive :class:`~att_sim.truth.simulation.Simulation` with the checks the simulator node
configures (stamps within one step ahead and ``command_timeout`` behind, the body frame, limits
``command_limit_factor`` x the actuator limits, reset rate ``max_reset_rate``). Each hostile input
must be refused with its code and a sentence naming the field, and must change nothing: the state
and the held command are identical before and after, and the next step matches a twin that never
saw it. The ROS cases publish hostile commands and call the reset service on a running simulator
(no controller): it stays up, states keep flowing at its real-time factor, no refused command is
applied, a command stamped far in the future never satisfies the lockstep, and refusals are
logged at most once a second with their running count.
"""
from __future__ import annotations

import copy
import re
import time
from dataclasses import replace

import numpy as np
import pytest
import rclpy
from std_srvs.srv import SetBool

from att_msgs.msg import ActuatorCommand, SpacecraftState
from att_msgs.srv import ResetSimulator
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Command, ControlMode
from att_sim.models import rotations as rot
from att_sim.models import scenario
from att_sim.truth.simulation import Checks, Simulation
from helpers.waiting import wait_until

SWIFT = scenario.load("swift_demo")
SC = SWIFT.spacecraft
STEP, TIMEOUT = 0.05, 1.0
MAX_HOLD = 3.0                                # s of wall time a hold of the ROS cases lasts at most
T_NOW = 5.0                                   # sim time of the fixture's simulation
W_MAX, M_MAX, TAU_MAX, SPEED_MAX = SC.wheel_torque_max, SC.dipole_max, SC.body_torque_max, SC.wheel_speed_max
INVALID, LIMIT, TEXT, SIZE = (ErrorCode.INVALID_COMMAND, ErrorCode.COMMAND_LIMIT, ErrorCode.INVALID_TEXT,
                              ErrorCode.SIZE_LIMIT)
NAN, INF = float("nan"), float("inf")


def make_sim() -> Simulation:
    """The swift_demo simulation as the node configures it, at t = 5 s, tumbling slowly, with a
    good command held."""
    sim = Simulation(SC, SWIFT.orbit, omega0=[0.01, -0.02, 0.005], wheel_speed0=[10.0, -20.0, 5.0],
                     checks=Checks(body_frame_id="body", stamp_ahead=STEP, stamp_age=TIMEOUT))
    while sim.t < T_NOW - 1e-9:
        assert sim.set_command(good_command(sim.t)) is None
        sim.advance(STEP)
    return sim


def good_command(t: float = T_NOW, **fields) -> Command:
    base = Command(mode=ControlMode.PLAN_TRACKING, wheel_torques=np.array([0.01, -0.02, 0.005]),
                   dipole=np.array([0.5, 0.0, -0.5]), body_torque=np.zeros(3), plan_id="p1", t=t, frame_id="body")
    return replace(base, **fields)


def snapshot(sim: Simulation) -> dict:
    return copy.deepcopy({k: sim.__dict__[k] for k in ("t", "arg0", "x", "wheel_cmd", "dipole_cmd", "body_cmd",
                                                       "halted", "command_timeout")})


def assert_unchanged(sim: Simulation, before: dict) -> None:
    """Same state and held command as ``before``, and the next step equals a twin's that never
    saw the hostile input."""
    after = snapshot(sim)
    for key, value in before.items():
        assert np.array_equal(np.asarray(after[key]), np.asarray(value)), key
    twin = make_sim()
    sim.advance(STEP)
    twin.advance(STEP)
    assert np.array_equal(sim.x, twin.x)


HOSTILE_COMMANDS = {
    # mode
    "mode 9": (dict(mode=9), INVALID, "mode"),
    "mode 255": (dict(mode=255), INVALID, "mode"),
    "mode -1": (dict(mode=-1), INVALID, "mode"),
    "mode float": (dict(mode=2.5), INVALID, "mode"),
    "mode bool": (dict(mode=True), INVALID, "mode"),
    # sizes and types
    "2 wheel torques": (dict(wheel_torques=np.zeros(2)), INVALID, "3 wheels"),
    "4 wheel torques": (dict(wheel_torques=np.zeros(4)), INVALID, "3 wheels"),
    "10000 wheel torques": (dict(wheel_torques=np.zeros(10000)), INVALID, "3 wheels"),
    "2-D wheel torques": (dict(wheel_torques=np.zeros((3, 3))), INVALID, "wheel_torques"),
    "text wheel torques": (dict(wheel_torques=["a", "b", "c"]), INVALID, "wheel_torques"),
    "2-vector dipole": (dict(dipole=np.zeros(2)), INVALID, "dipole"),
    "4-vector body torque": (dict(body_torque=np.zeros(4)), INVALID, "body_torque"),
    # non-finite
    "NaN wheel torque": (dict(wheel_torques=np.array([NAN, 0, 0])), INVALID, "wheel_torques"),
    "+Inf wheel torque": (dict(wheel_torques=np.array([0, INF, 0])), INVALID, "wheel_torques"),
    "-Inf wheel torque": (dict(wheel_torques=np.array([0, 0, -INF])), INVALID, "wheel_torques"),
    "NaN dipole": (dict(dipole=np.array([0, NAN, 0])), INVALID, "dipole"),
    "Inf dipole": (dict(dipole=np.array([INF, 0, 0])), INVALID, "dipole"),
    "NaN body torque": (dict(body_torque=np.array([NAN, 0, 0])), INVALID, "body_torque"),
    "-Inf body torque": (dict(body_torque=np.array([0, 0, -INF])), INVALID, "body_torque"),
    "NaN dipole in idle": (dict(mode=ControlMode.IDLE, dipole=np.array([NAN, 0, 0])), INVALID, "dipole"),
    # far beyond the limits (within command_limit_factor they saturate, see below)
    "wheel torque 1e30": (dict(wheel_torques=np.array([1e30, 0, 0])), LIMIT, "wheel_torque_max"),
    "wheel torque -1e30": (dict(wheel_torques=np.array([0, -1e30, 0])), LIMIT, "wheel_torque_max"),
    "wheel torque 1e308": (dict(wheel_torques=np.array([0, 0, 1e308])), LIMIT, "wheel_torque_max"),
    "wheel torque 2.01 x limit": (dict(wheel_torques=np.array([2.01 * W_MAX, 0, 0])), LIMIT, "wheel_torques"),
    "dipole 1e30": (dict(dipole=np.array([1e30, 0, 0])), LIMIT, "dipole_max"),
    "dipole 2.5 x limit": (dict(dipole=np.array([0, -2.5 * M_MAX, 0])), LIMIT, "dipole"),
    "body torque 1e30": (dict(body_torque=np.array([0, 0, 1e30])), LIMIT, "torque_max"),
    "body torque 3 x limit": (dict(body_torque=np.array([3 * TAU_MAX, 0, 0])), LIMIT, "body_torque"),
    "wheel torque 1e30 in idle": (dict(mode=ControlMode.IDLE, wheel_torques=np.array([1e30, 0, 0])), LIMIT,
                                  "wheel_torques"),
    "dipole 1e30 in safe mode": (dict(mode=ControlMode.SAFE, dipole=np.array([0, 0, -1e30])), LIMIT, "dipole"),
    # stamps
    "stamp 1e6 s": (dict(t=1e6), INVALID, "ahead"),
    "stamp two steps ahead": (dict(t=T_NOW + 2 * STEP), INVALID, "ahead"),
    "stamp 2**31 s": (dict(t=2.0 ** 31), INVALID, "ahead"),
    "stamp older than command_timeout": (dict(t=T_NOW - 1.5 * TIMEOUT), INVALID, "command_timeout"),
    "stamp 0": (dict(t=0.0), INVALID, "older"),
    "stamp -1e9 s": (dict(t=-1e9), INVALID, "older"),
    "stamp NaN": (dict(t=NAN), INVALID, "header.stamp"),
    # frames and text
    "frame map": (dict(frame_id="map"), INVALID, "header.frame_id"),
    "frame eci (inertial)": (dict(frame_id="eci"), INVALID, "body frame"),
    "frame 'body ' (trailing blank)": (dict(frame_id="body "), INVALID, "header.frame_id"),
    "frame with SOH": (dict(frame_id="body\x01"), TEXT, "header.frame_id"),
    "frame of 300 characters": (dict(frame_id="b" * 300), SIZE, "header.frame_id"),
    "frame not a string": (dict(frame_id=None), INVALID, "header.frame_id"),
    "plan_id with a newline": (dict(plan_id="p1\n[ERROR] forged log line"), TEXT, "plan_id"),
    "plan_id with ESC": (dict(plan_id="\x1b[31mred"), TEXT, "plan_id"),
    "plan_id with DEL": (dict(plan_id="p\x7f1"), TEXT, "plan_id"),
    "plan_id with a lone surrogate": (dict(plan_id="p\ud8001"), TEXT, "plan_id"),
    "plan_id of 129 characters": (dict(plan_id="p" * 129), SIZE, "plan_id"),
    "plan_id of a million characters": (dict(plan_id="p" * 1_000_000), SIZE, "plan_id"),
}


@pytest.mark.parametrize("fields, code, words", HOSTILE_COMMANDS.values(), ids=HOSTILE_COMMANDS.keys())
def test_hostile_command_is_refused_and_changes_nothing(fields, code, words):
    sim = make_sim()
    before = snapshot(sim)
    refusal = sim.set_command(good_command(**fields))
    assert refusal is not None, "accepted"
    assert refusal.code == code and words in refusal.message, refusal
    assert len(refusal.message) <= 400
    assert_unchanged(sim, before)


@pytest.mark.parametrize("fields", [
    dict(wheel_torques=np.array([2.0 * W_MAX, -2.0 * W_MAX, 0])), dict(dipole=np.array([1.99 * M_MAX, 0, 0])),
    dict(body_torque=np.array([0, 0, -2.0 * TAU_MAX])), dict(t=T_NOW + STEP), dict(t=T_NOW - TIMEOUT),
    dict(frame_id=""), dict(plan_id="p" * 128), dict(wheel_torques=np.zeros(0))],
    ids=["wheels at 2x", "dipole 1.99x", "body torque 2x", "one step ahead", "command_timeout old", "no frame",
         "128-char plan_id", "no wheel torques"])
def test_commands_at_the_edges_are_accepted_and_saturate(fields):
    """The limits of the checks are inclusive; within command_limit_factor a command is clamped."""
    sim = make_sim()
    assert sim.set_command(good_command(**fields)) is None
    sim.advance(STEP)
    assert np.all(np.abs(sim.applied.wheel_torque) <= W_MAX) and np.all(np.abs(sim.applied.dipole) <= M_MAX)


def test_command_limit_factor_is_a_parameter():
    sim = Simulation(SC, SWIFT.orbit, checks=Checks(command_limit_factor=10.0))
    assert sim.set_command(good_command(t=0.0, wheel_torques=np.array([9 * W_MAX, 0, 0]))) is None
    assert sim.set_command(good_command(t=0.0, wheel_torques=np.array([11 * W_MAX, 0, 0]))).code == LIMIT


Q_OK = rot.from_axis_angle([0, 0, 1], 0.3)
RESET_BAD = ErrorCode.INVALID_RESET
HOSTILE_RESETS = {
    "attitude NaN": ((NAN, 0, 0, 1), (0, 0, 0), [], 0.0, "attitude"),
    "attitude +Inf": ((0, INF, 0, 1), (0, 0, 0), [], 0.0, "attitude"),
    "attitude zero": ((0, 0, 0, 0), (0, 0, 0), [], 0.0, "zero quaternion"),
    "attitude norm 2": ((0, 0, 0, 2), (0, 0, 0), [], 0.0, "norm"),
    "attitude norm 1.01": ((0, 0, 0, 1.01), (0, 0, 0), [], 0.0, "norm"),
    "attitude 1e308": ((1e308, 1e308, 1e308, 1e308), (0, 0, 0), [], 0.0, "attitude"),
    "attitude 3 components": ((0, 0, 1), (0, 0, 0), [], 0.0, "attitude"),
    "attitude text": (("a", "b", "c", "d"), (0, 0, 0), [], 0.0, "attitude"),
    "body_rate NaN": (Q_OK, (NAN, 0, 0), [], 0.0, "body_rate"),
    "body_rate -Inf": (Q_OK, (0, -INF, 0), [], 0.0, "body_rate"),
    "body_rate 1e30": (Q_OK, (0, 0, 1e30), [], 0.0, "max_reset_rate"),
    "body_rate norm just above max_reset_rate": (Q_OK, (0.6, 0.6, 0.6), [], 0.0, "max_reset_rate"),
    "body_rate 2 components": (Q_OK, (0, 0), [], 0.0, "body_rate"),
    "wheel speeds 1e30": (Q_OK, (0, 0, 0), [1e30, 0, 0], 0.0, "wheel_speed_max"),
    "wheel speeds -1e30": (Q_OK, (0, 0, 0), [0, -1e30, 0], 0.0, "wheel_speed_max"),
    "wheel speed just above the limit": (Q_OK, (0, 0, 0), [0, 0, SPEED_MAX * 1.001], 0.0, "wheel_speeds[2]"),
    "wheel speeds NaN": (Q_OK, (0, 0, 0), [NAN, 0, 0], 0.0, "wheel_speeds"),
    "wheel speeds -Inf": (Q_OK, (0, 0, 0), [0, 0, -INF], 0.0, "wheel_speeds"),
    "2 wheel speeds": (Q_OK, (0, 0, 0), [1.0, 2.0], 0.0, "3 wheels"),
    "4 wheel speeds": (Q_OK, (0, 0, 0), [1.0, 2.0, 3.0, 4.0], 0.0, "3 wheels"),
    "orbit_phase NaN": (Q_OK, (0, 0, 0), [], NAN, "orbit_phase"),
    "orbit_phase Inf": (Q_OK, (0, 0, 0), [], INF, "orbit_phase"),
    "orbit_phase 1e300": (Q_OK, (0, 0, 0), [], 1e300, "orbit_phase"),
}


@pytest.mark.parametrize("q, w, speeds, phase, words", HOSTILE_RESETS.values(), ids=HOSTILE_RESETS.keys())
def test_hostile_reset_is_refused_and_changes_nothing(q, w, speeds, phase, words):
    sim = make_sim()
    before = snapshot(sim)
    refusal = sim.reset(q, w, speeds, phase)
    assert refusal is not None, "accepted"
    assert refusal.code == RESET_BAD and words in refusal.message, refusal
    assert_unchanged(sim, before)


def test_resets_at_the_limits_are_accepted():
    sim = make_sim()
    assert sim.reset([0, 0, 0, 1.0009], [0.0, 0.0, 1.0], [SPEED_MAX, -SPEED_MAX, 0.0], -1e6) is None
    assert np.allclose(sim.x[:4], [0, 0, 0, 1]) and np.allclose(sim.x[7:], [SPEED_MAX, -SPEED_MAX, 0])
    assert Simulation(SC, SWIFT.orbit, checks=Checks(max_reset_rate=3.0)).reset(Q_OK, [2.0, 0, 0], [], 0.0) is None


def test_there_are_enough_distinct_hostile_simulator_inputs():
    assert len(HOSTILE_COMMANDS) + len(HOSTILE_RESETS) >= 60


# -- over ROS: a running simulator without a controller -----------------------------------------

RTF = 4.0


@pytest.fixture
def lonely_sim(ros_suite):
    """A simulator of the test's own, alone (RTF 4, lockstep on): no controller answers its states
    (each test sees a simulator no other test has commanded, in any order). Yields the suite, the
    states received as (wall time, message) and a function giving the latest stamp."""
    with ros_suite("swift_demo", nodes=("simulator",),
                   params={"simulator": {"real_time_factor": RTF, "max_hold_s": MAX_HOLD}}, name="sim_inputs") as s:
        states, latest = [], [0.0]

        def on_state(msg):
            states.append((time.monotonic(), msg))
            latest[0] = convert.from_time(msg.header.stamp)

        s.client.create_subscription(SpacecraftState, topics.STATE, on_state, qos.STREAM_QOS)
        yield s, states, lambda: latest[0]


def spin_for(client, seconds: float, each=None, period: float = 0.0) -> None:
    """Spin ``client`` for ``seconds``, calling ``each()`` at most every ``period`` s."""
    end, due = time.monotonic() + seconds, 0.0
    while time.monotonic() < end:
        if each is not None and time.monotonic() >= due:
            each()
            due = time.monotonic() + period
        rclpy.spin_once(client, timeout_sec=0.002)


def free_running(s) -> None:
    """Wait (spinning the client) until the lone simulator has given up waiting for a controller."""
    wait_until(lambda: "free-running" in s.suite.log_text("simulator"), 60,
               "the simulator going free-running without a controller", node=s.client)


def commanding(s, states, *publishers) -> None:
    """Wait until every command publisher is matched to the simulator and the client has received a
    state: the hostile commands are stamped from the latest state's time, and before the first one
    that time reads 0, so that ``now() + 10`` (meant to be ahead) would be a valid command at t = 10."""
    wait_until(lambda: all(p.get_subscription_count() > 0 for p in publishers) and len(states) > 0, 30,
               "the command publishers matched and a state received", node=s.client)


def command_msg(t: float, **fields) -> ActuatorCommand:
    base = dict(t=t, dipole=np.zeros(3), wheel_torques=np.array([0.05, 0.0, 0.0]))
    return convert.command_msg(good_command(**{**base, **fields}))


@pytest.mark.ros
def test_without_controller_the_lockstep_gives_up_and_keeps_the_real_time_factor(lonely_sim):
    s, states, _ = lonely_sim
    spin_for(s.client, 6.0)
    late = [(w, m) for w, m in states if w > states[0][0] + 1.0]
    (w0, m0), (w1, m1) = late[0], late[-1]
    rate = (convert.from_time(m1.header.stamp) - convert.from_time(m0.header.stamp)) / (w1 - w0)
    assert rate >= 0.75 * RTF, f"sim time advanced at {rate:.2f} x wall time (RTF {RTF})"
    assert all(m.command_timeout for _, m in late), "inputs not flagged as zeroed"
    assert s.suite.log_text("simulator").count("free-running") == 1


@pytest.mark.ros
def test_hostile_commands_are_refused_states_flow_and_refusals_are_throttled(lonely_sim):
    """A flood of refused commands (a valid torque each time, one field hostile): none is applied,
    none satisfies the lockstep (the stamp 1e6 one included), the states keep flowing."""
    s, states, now = lonely_sim
    free_running(s)
    pub = s.client.create_publisher(ActuatorCommand, topics.COMMAND, qos.STREAM_QOS)
    commanding(s, states, pub)
    hostile = [lambda: command_msg(1e6), lambda: command_msg(now() + 10.0),
               lambda: command_msg(now(), frame_id="map"), lambda: command_msg(now(), wheel_torques=np.full(3, 1e30)),
               lambda: command_msg(now(), wheel_torques=np.zeros(7)), lambda: command_msg(now(), mode=42),
               lambda: command_msg(now(), plan_id="x" * 500), lambda: command_msg(now(), plan_id="a\x1bb"),
               lambda: command_msg(now() - 30.0), lambda: command_msg(now(), dipole=np.array([NAN, 0.0, 0.0]))]
    sent = [0]

    def publish_one():
        pub.publish(hostile[sent[0] % len(hostile)]())
        sent[0] += 1

    states.clear()
    start = time.monotonic()
    spin_for(s.client, 4.0, publish_one, period=0.01)
    elapsed = time.monotonic() - start
    assert all(s.suite.alive().values())
    # the simulator's flow, read from the stamps: the client may drop states of its shallow queue while
    # it publishes the flood, so their count says how fast the test process is, not the simulator
    gaps = np.diff([w for w, _ in states])
    advanced = convert.from_time(states[-1][1].header.stamp) - convert.from_time(states[0][1].header.stamp)
    assert len(states) > 10 and gaps.max() < 1.0, "states stopped flowing"
    assert advanced >= 0.5 * RTF * elapsed, f"sim time advanced {advanced:.2f} s in {elapsed:.2f} s (RTF {RTF})"
    assert all(m.command_timeout and not np.any(m.wheel_torques) for _, m in states), \
        "a refused command was applied or satisfied the lockstep"
    lines = [ln for ln in s.suite.log_text("simulator").splitlines() if "actuator command rejected" in ln]
    counts = [int(n) for n in re.findall(r"\((\d+) so far\)", "\n".join(lines))]
    assert sent[0] > 200 and 1 <= len(lines) <= elapsed + 3, f"{len(lines)} log lines for {sent[0]} refusals"
    assert counts == sorted(counts) and counts[-1] > 50
    assert all(len(ln) < 600 for ln in lines) and re.search(r"\[40[12] (INVALID_COMMAND|COMMAND_LIMIT)\]", lines[0])
    s.client.destroy_publisher(pub)


@pytest.mark.ros
def test_a_command_answering_a_state_resumes_the_lockstep(lonely_sim):
    s, states, now = lonely_sim
    free_running(s)
    pub = s.client.create_publisher(ActuatorCommand, topics.COMMAND, qos.STREAM_QOS)
    commanding(s, states, pub)
    answered = set()

    def answer_latest():
        if now() not in answered:
            answered.add(now())
            pub.publish(command_msg(now()))

    states.clear()
    spin_for(s.client, 3.0, answer_latest)
    resumed = [m for _, m in states if not m.command_timeout]
    # applied through swift_demo's imperfect drive (quantum 1e-4 N m, noise 2e-4 N m 1 sigma)
    assert resumed and resumed[-1].wheel_torques[0] == pytest.approx(0.05, abs=1.5e-3), \
        "the answering commands were not applied"
    assert "lockstep resumed" in s.suite.log_text("simulator")
    s.client.destroy_publisher(pub)


@pytest.mark.ros
def test_a_late_command_of_the_controller_makes_the_simulator_wait_for_it(lonely_sim):
    """A controller that lives but lags (its commands too old to apply) is waited for, not drowned:
    its late command puts the free-running simulator back to waiting; another publisher's is ignored."""
    s, states, now = lonely_sim
    free_running(s)
    log = lambda: s.suite.log_text("simulator")      # noqa: E731
    pub = s.client.create_publisher(ActuatorCommand, topics.COMMAND, qos.STREAM_QOS)
    stranger = s.client.create_publisher(ActuatorCommand, topics.COMMAND, qos.STREAM_QOS)
    commanding(s, states, pub, stranger)
    answered = set()

    def answer_latest():                             # the controller: commands accepted, so it is held
        if now() not in answered:
            answered.add(now())
            pub.publish(command_msg(now()))

    deadline = time.monotonic() + 60
    while "lockstep resumed" not in log():
        assert time.monotonic() < deadline, "no command of the controller was accepted within 60 s"
        spin_for(s.client, 0.1, answer_latest)
    # then silent: the simulator free-runs again (its log line is throttled in sim time, so the event is
    # the sim clock running on past the last answered state without an answer, as lockstep never does)
    last = max(answered)
    wait_until(lambda: now() > last + 2.0, 60, "the simulator free-running again once the controller fell silent",
               node=s.client)
    stranger.publish(command_msg(now() - 5.0))
    spin_for(s.client, 1.0)                          # wait-ok: an interval in which nothing may happen
    assert log().count("waiting for it to catch up") == 0, "a stranger's late command was waited for"
    pub.publish(command_msg(now() - 5.0))            # late, from the controller
    wait_until(lambda: "waiting for it to catch up" in log(), 30,
               "the simulator waiting for the controller's late command", node=s.client)
    s.client.destroy_publisher(pub)
    s.client.destroy_publisher(stranger)


@pytest.mark.ros
def test_hostile_resets_over_the_service_are_refused(lonely_sim):
    s, states, _ = lonely_sim
    client = s.client.create_client(ResetSimulator, topics.RESET_SIMULATOR)
    assert client.wait_for_service(timeout_sec=20)

    def reset(q=Q_OK, w=(0, 0, 0), speeds=(), phase=0.0):
        future = client.call_async(ResetSimulator.Request(attitude=convert.quaternion(q), body_rate=convert.vector3(w),
                                                          wheel_speeds=[float(v) for v in speeds],
                                                          orbit_phase=float(phase)))
        rclpy.spin_until_future_complete(s.client, future, timeout_sec=10)
        return future.result()

    for q, w, speeds, phase, words in [((0, 0, 0, 1), (0, 0, 0), (1e30, 0, 0), 0.0, "wheel_speeds"),
                                       ((NAN, 0, 0, 1), (0, 0, 0), (), 0.0, "attitude"),
                                       ((0, 0, 0, 1), (5.0, 0, 0), (), 0.0, "max_reset_rate"),
                                       ((0, 0, 0, 1), (0, 0, 0), (1.0,), 0.0, "wheels"),
                                       ((0, 0, 0, 1), (0, 0, 0), (), INF, "orbit_phase")]:
        r = reset(q, w, speeds, phase)
        assert not r.success and r.error_code == ErrorCode.INVALID_RESET and words in r.message, r.message
    assert reset(Q_OK, (0.0, 0.0, 0.01)).success
    states.clear()
    spin_for(s.client, 1.0)
    q = convert.from_quaternion(states[-1][1].attitude)
    assert rot.angle_between(q, Q_OK) < 0.5 and all(s.suite.alive().values())
    assert "reset rejected [400 INVALID_RESET]" in s.suite.log_text("simulator")


@pytest.mark.ros
def test_a_hold_stops_sim_time_until_released_or_max_hold(lonely_sim):
    """/simulator/hold: no state is stamped after the held time while held; released by a call, or
    by the simulator itself after ``max_hold_s`` of wall time; sim time then runs again."""
    s, states, now = lonely_sim
    client = s.client.create_client(SetBool, topics.HOLD_SIMULATOR)
    assert client.wait_for_service(timeout_sec=20)
    wait_until(lambda: len(states) > 0, 30, "a state from the simulator", node=s.client)

    def hold(data: bool) -> tuple[bool, str, float]:
        future = client.call_async(SetBool.Request(data=data))
        rclpy.spin_until_future_complete(s.client, future, timeout_sec=10)
        r = future.result()
        return r.success, r.message, float(re.search(r"t = ([0-9.]+) s", r.message).group(1))

    def stamps():
        return [convert.from_time(m.header.stamp) for _, m in states]

    for release in ("call", "max_hold_s"):
        ok, message, held_at = hold(True)
        assert ok and "held at t =" in message, message
        states.clear()
        spin_for(s.client, 1.0)                          # RTF 4: 4 s of sim time if it were running
        assert all(t <= held_at + STEP + 1e-9 for t in stamps()), f"states after the hold at {held_at}: {stamps()}"
        if release == "call":
            ok, message, _ = hold(False)
            assert ok and "released at t =" in message, message
        else:
            wait_until(lambda: "held for more than max_hold_s" in s.suite.log_text("simulator"), MAX_HOLD + 30,
                       "the simulator releasing its hold after max_hold_s", node=s.client)
        wait_until(lambda h=held_at: any(t > h + 1.0 for t in stamps()), 30, "sim time running after the release",
                   node=s.client)
    assert all(s.suite.alive().values())
    assert hold(False)[1].startswith("sim time was not held")
