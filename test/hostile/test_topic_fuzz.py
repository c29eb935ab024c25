"""Random valid messages with extreme field values on every subscribed topic while a maneuver runs.

The whole suite runs (recorder, simulator, estimator, controller, planner: the controller flies on
the estimate); a maneuver is executing (each test starts one when none flies); for each message
type hypothesis publishes random, well-formed CDR messages (NaN, ±Inf, ±1e308, denormals, huge and
empty arrays, control characters, any stamp) on the topics the nodes subscribe to, the sensors' and
the estimate's included. Each fuzz test then asserts its own outcome (it runs alone and in any
order): no node died, no loop stalled for more than a second (the state, estimate and
controller-status streams kept flowing, and each delivered a message after the fuzzing); the last
fuzzes every topic until the maneuver in flight ends with an answer: completed, or aborted with a
code. Hypothesis's health checks are all on.
"""
from __future__ import annotations

import math
import threading
import time

import pytest
import rclpy
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion, Vector3
from hypothesis import given, settings
from hypothesis import strategies as st
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState, MagneticField

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import (
    ActuatorCommand,
    AttitudeEstimate,
    CoarseSunSensors,
    ControllerStatus,
    KeepOutCone,
    ManeuverPlan,
    SpacecraftState,
    StarTracker,
)
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.node_runner import publisher_of
from att_planner.nodes.client import maneuver_request
from att_sim.models import rotations as rot
from helpers.waiting import wait_until

pytestmark = pytest.mark.ros

EXTREME = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                    st.sampled_from([0.0, -0.0, 1e308, -1e308, 5e-324, 1e-300, 1e30, -1e30, 1.0, 0.1]))
TEXT = st.text(alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters="\x00"), max_size=40)
EXAMPLES = settings(max_examples=25, deadline=None)


def stamps():
    return st.builds(Time, sec=st.integers(-2**31, 2**31 - 1), nanosec=st.integers(0, 2**32 - 1))


def vectors():
    return st.builds(Vector3, x=EXTREME, y=EXTREME, z=EXTREME)


def quaternions():
    return st.builds(Quaternion, x=EXTREME, y=EXTREME, z=EXTREME, w=EXTREME)


@st.composite
def states(draw):
    msg = SpacecraftState(body_frame_id=draw(st.sampled_from(["body", "", "x\x01"])),
                          attitude=draw(quaternions()), body_rate=draw(vectors()),
                          wheel_speeds=draw(st.lists(EXTREME, max_size=6)),
                          wheel_torques=draw(st.lists(EXTREME, max_size=6)),
                          magnetic_field_body=draw(vectors()), dipole=draw(vectors()), applied_torque=draw(vectors()),
                          position=draw(vectors()), command_timeout=draw(st.booleans()))
    msg.header.stamp = draw(stamps())
    msg.header.frame_id = draw(st.sampled_from(["eci", "", "map"]) | TEXT)
    return msg


@st.composite
def plans(draw):
    k = draw(st.integers(0, 30))
    kinds = st.sampled_from(["body_torque", "wheel_torque"]) | TEXT
    msg = ManeuverPlan(plan_id=draw(TEXT), method=draw(TEXT),
                       status=draw(st.sampled_from(["optimal", "failed"]) | TEXT),
                       message=draw(TEXT), spacecraft=draw(st.sampled_from(["swift_demo", ""]) | TEXT),
                       duration=draw(EXTREME), control_kind=draw(kinds),
                       interpolation=draw(st.sampled_from(["zoh", "linear"]) | TEXT),
                       times=draw(st.lists(EXTREME, min_size=k, max_size=k + 2)),
                       attitudes=draw(st.lists(quaternions(), min_size=max(0, k - 2), max_size=k)),
                       rates=draw(st.lists(vectors(), min_size=k, max_size=k)),
                       torques=draw(st.lists(vectors(), min_size=k, max_size=k)), sensor_axis=draw(vectors()),
                       cones=draw(st.lists(st.builds(KeepOutCone, name=TEXT, direction=vectors(), half_angle=EXTREME),
                                           max_size=20)),
                       solve_seconds=draw(EXTREME), spacecraft_digest=draw(TEXT), key_id=draw(TEXT),
                       signature=draw(st.binary(max_size=80)))
    msg.header.stamp = draw(stamps())
    msg.header.frame_id = draw(st.sampled_from(["eci", ""]) | TEXT)
    return msg


@st.composite
def commands(draw):
    msg = ActuatorCommand(mode=draw(st.integers(0, 255)), wheel_torques=draw(st.lists(EXTREME, max_size=6)),
                          dipole=draw(vectors()), body_torque=draw(vectors()), plan_id=draw(TEXT))
    msg.header.stamp = draw(stamps())
    msg.header.frame_id = draw(st.sampled_from(["body", ""]) | TEXT)
    return msg


@st.composite
def statuses(draw):
    msg = ControllerStatus(mode=draw(st.integers(0, 255)), plan_id=draw(TEXT), plan_progress=draw(EXTREME),
                           state_stale=draw(st.booleans()), message=draw(TEXT))
    msg.header.stamp = draw(stamps())
    return msg


def headed(draw, msg, frames=("body", "eci", "")):
    msg.header.stamp = draw(stamps())
    msg.header.frame_id = draw(st.sampled_from(frames) | TEXT)
    return msg


def nine():
    return st.lists(EXTREME, min_size=9, max_size=9)


@st.composite
def imus(draw):
    return headed(draw, Imu(orientation=draw(quaternions()), angular_velocity=draw(vectors()),
                            linear_acceleration=draw(vectors()), angular_velocity_covariance=draw(nine())))


@st.composite
def star_trackers(draw):
    name = draw(st.sampled_from(["st1", ""]) | TEXT)
    return headed(draw, StarTracker(sensor_frame_id=name, valid=draw(st.booleans()), status=draw(st.integers(0, 255)),
                                    attitude=draw(quaternions()), covariance=draw(nine())))


@st.composite
def magnetometers(draw):
    return headed(draw, MagneticField(magnetic_field=draw(vectors()), magnetic_field_covariance=draw(nine())))


@st.composite
def sun_sensor_readings(draw):
    return headed(draw, CoarseSunSensors(values=draw(st.lists(EXTREME, max_size=12)), noise=draw(EXTREME)))


@st.composite
def wheel_speed_readings(draw):
    k = draw(st.integers(0, 6))
    return headed(draw, JointState(name=draw(st.lists(TEXT, max_size=k)), velocity=draw(st.lists(EXTREME, max_size=k)),
                                   position=draw(st.lists(EXTREME, max_size=k))))


@st.composite
def estimates(draw):
    return headed(draw, AttitudeEstimate(body_frame_id=draw(st.sampled_from(["body", ""]) | TEXT),
                                         health=draw(st.integers(0, 255)), attitude=draw(quaternions()),
                                         body_rate=draw(vectors()), gyro_bias=draw(vectors()),
                                         attitude_covariance=draw(nine()), bias_covariance=draw(nine()),
                                         time_since_update=draw(EXTREME), message=draw(TEXT)), ("eci", "", "body"))


SENSOR_FUZZ = {topics.IMU: (Imu, imus), topics.STAR_TRACKER: (StarTracker, star_trackers),
               topics.MAGNETOMETER: (MagneticField, magnetometers),
               topics.SUN_SENSORS: (CoarseSunSensors, sun_sensor_readings),
               topics.WHEEL_SPEEDS: (JointState, wheel_speed_readings), topics.ESTIMATE: (AttitudeEstimate, estimates)}


class Monitor(Node):
    """Wall-clock arrival times of the state, estimate and controller-status streams, and the latest
    state the simulator published (the fuzzer's states on the same topic set aside by publisher)."""

    def __init__(self):
        super().__init__("fuzz_monitor")
        self.arrivals = {topics.STATE: [], topics.CONTROLLER_STATUS: [], topics.ESTIMATE: []}
        self.simulator_state = None
        self.publishers_seen: dict[bytes, bool] = {}      # publisher GID: whether it is the simulator
        self.create_subscription(SpacecraftState, topics.STATE, self.on_state, qos.STREAM_QOS)
        self.create_subscription(AttitudeEstimate, topics.ESTIMATE, lambda _: self.arrived(topics.ESTIMATE),
                                 qos.STREAM_QOS)
        self.create_subscription(ControllerStatus, topics.CONTROLLER_STATUS,
                                 lambda _: self.arrived(topics.CONTROLLER_STATUS), qos.STREAM_QOS)

    def arrived(self, topic):
        self.arrivals[topic].append(time.monotonic())

    def on_state(self, msg, info):
        self.arrived(topics.STATE)
        gid = publisher_of(info)
        if gid not in self.publishers_seen:
            simulator = {bytes(i.endpoint_gid) for i in self.get_publishers_info_by_topic(topics.STATE)
                         if i.node_name == "simulator"}
            self.publishers_seen[gid] = gid in simulator
        if self.publishers_seen[gid]:
            self.simulator_state = msg

    def largest_gap(self, topic, start, end) -> float:
        return self.gap_at(topic, start, end)[0]

    def gap_at(self, topic, start, end) -> tuple[float, float]:
        """The largest gap between two arrivals (or ``start``/``end``) and when it began."""
        t = [start] + [a for a in self.arrivals[topic] if start <= a <= end] + [end]
        return max((b - a, a) for a, b in zip(t, t[1:]))


@pytest.fixture(scope="module")
def fuzzed(ros_suite):
    with ros_suite("swift_demo", params={"simulator": {"real_time_factor": 4.0}}, name="fuzz_test") as s:
        monitor = Monitor()
        executor = SingleThreadedExecutor()
        executor.add_node(monitor)
        spinner = threading.Thread(target=executor.spin, daemon=True)
        spinner.start()
        client = s.client
        kinds = [(topics.STATE, SpacecraftState), (topics.PLANS, ManeuverPlan), (topics.COMMAND, ActuatorCommand),
                 (topics.CLOCK, Clock), (topics.CONTROLLER_STATUS, ControllerStatus),
                 *((t, cls) for t, (cls, _) in SENSOR_FUZZ.items())]
        publishers = {t: client.create_publisher(cls, t, qos.LATCHED_QOS if t == topics.PLANS else qos.STREAM_QOS)
                      for t, cls in kinds}
        state = {"suite": s, "monitor": monitor, "goal": None, "pubs": publishers,
                 "start": time.monotonic(), "published": 0}
        yield state
        executor.shutdown()
        monitor.destroy_node()


def in_flight(fuzzed):
    """The goal of a maneuver the controller is flying and its answer's future: the one running, or
    (none yet, or the last one answered) a new 1.2 rad slew from the simulator's latest state, sent
    and fed back on."""
    client, monitor = fuzzed["suite"].client, fuzzed["monitor"]
    if fuzzed["goal"] is not None:
        goal, answer = fuzzed["goal"]
        rclpy.spin_until_future_complete(client, answer, timeout_sec=0.2)     # an answer already sent is taken
        if not answer.done():
            return goal, answer
    wait_until(lambda: monitor.simulator_state is not None, 10, "a state from the simulator")
    q0 = convert.state_from_msg(monitor.simulator_state).q
    response = client.plan(maneuver_request(q0, rot.multiply(q0, rot.from_axis_angle([0, 0, 1], 1.2)), [1, 0, 0],
                                            [], method="eigenaxis_smooth"))
    assert response.success, response.message
    fed_back = []
    # sent once: a goal that reaches the controller before the plan waits for it (plan_wait_s)
    send = client.execute_client.send_goal_async(ExecuteManeuver.Goal(plan_id=response.plan.plan_id),
                                                 feedback_callback=fed_back.append)
    rclpy.spin_until_future_complete(client, send, timeout_sec=20)
    goal = send.result()
    assert goal is not None and goal.accepted
    answer = goal.get_result_async()
    wait_until(lambda: fed_back or answer.done(), 30, "feedback on the maneuver", node=client)
    assert fed_back, f"the maneuver was answered before it flew: {answer.result().result.message}"
    fuzzed["goal"] = goal, answer
    return goal, answer


def publish(fuzzed, topic, msg):
    for _ in range(3):
        fuzzed["pubs"][topic].publish(msg)
    fuzzed["published"] += 3
    time.sleep(0.005)       # wait-ok: paces the fuzzer (3 messages per 5 ms) so the nodes are not just flooded


def assert_survived(fuzzed, start: float, published_before: int) -> None:
    """What one fuzz test asserts of its own run (started at ``start``): it published at least ten
    examples of three messages, every node is alive, and the state, estimate and controller-status
    streams kept flowing (no gap of a second) from its first message until each stream delivered a
    message after its last one."""
    s, monitor = fuzzed["suite"], fuzzed["monitor"]
    assert fuzzed["published"] - published_before >= 3 * 10
    assert all(s.suite.alive().values()), s.suite.alive()
    stopped = time.monotonic()
    streams = (topics.STATE, topics.CONTROLLER_STATUS, topics.ESTIMATE)
    wait_until(lambda: all(monitor.arrivals[t] and monitor.arrivals[t][-1] > stopped for t in streams), 5.0,
               "a state, an estimate and a controller status after the fuzzing")
    for topic in streams:
        gap = monitor.largest_gap(topic, start, monitor.arrivals[topic][-1])
        assert gap < 1.0, f"{topic} stalled for {gap:.2f} s while fuzzing"


def fuzz(fuzzed, publish_examples, *args) -> None:
    """Run one hypothesis fuzzer against the running suite while a maneuver flies, then assert what
    it must leave."""
    in_flight(fuzzed)
    start, before = time.monotonic(), fuzzed["published"]
    publish_examples(fuzzed, *args)
    assert_survived(fuzzed, start, before)


@EXAMPLES
@given(msg=states())
def publish_states(fuzzed, msg):
    publish(fuzzed, topics.STATE, msg)


@EXAMPLES
@given(msg=plans())
def publish_plans(fuzzed, msg):
    publish(fuzzed, topics.PLANS, msg)


@EXAMPLES
@given(msg=commands())
def publish_commands(fuzzed, msg):
    publish(fuzzed, topics.COMMAND, msg)


@EXAMPLES
@given(stamp=stamps())
def publish_clocks(fuzzed, stamp):
    publish(fuzzed, topics.CLOCK, Clock(clock=stamp))


@EXAMPLES
@given(msg=statuses())
def publish_controller_statuses(fuzzed, msg):
    publish(fuzzed, topics.CONTROLLER_STATUS, msg)


@EXAMPLES
@given(data=st.data())
def publish_sensor_readings(fuzzed, topic, data):
    publish(fuzzed, topic, data.draw(SENSOR_FUZZ[topic][1]()))


def test_random_states(fuzzed):
    fuzz(fuzzed, publish_states)


def test_random_plans(fuzzed):
    fuzz(fuzzed, publish_plans)


def test_random_commands(fuzzed):
    fuzz(fuzzed, publish_commands)


def test_random_clocks(fuzzed):
    fuzz(fuzzed, publish_clocks)


def test_random_controller_statuses(fuzzed):
    fuzz(fuzzed, publish_controller_statuses)


@pytest.mark.parametrize("topic", list(SENSOR_FUZZ))
def test_random_sensor_readings_and_estimates(fuzzed, topic):
    fuzz(fuzzed, publish_sensor_readings, topic)


@EXAMPLES
@given(data=st.data())
def publish_anything(fuzzed, data):
    topic = data.draw(st.sampled_from(sorted(FUZZERS)))
    publish(fuzzed, topic, data.draw(FUZZERS[topic]()))


FUZZERS = {topics.STATE: states, topics.PLANS: plans, topics.COMMAND: commands,
           topics.CLOCK: lambda: st.builds(Clock, clock=stamps()), topics.CONTROLLER_STATUS: statuses,
           **{t: strategy for t, (_, strategy) in SENSOR_FUZZ.items()}}


@pytest.mark.slow                                   # 23 s on the 2-core machine
def test_nothing_died_nothing_stalled_and_the_maneuver_got_an_answer(fuzzed):
    """The maneuver in flight (a new one when none flies) fuzzed on every topic until its answer,
    whatever ran before: no node died, no stream stalled since the suite started, and the maneuver
    ended completed or aborted with a code."""
    s, monitor, client = fuzzed["suite"], fuzzed["monitor"], fuzzed["suite"].client
    began = time.monotonic()
    _, done = in_flight(fuzzed)
    deadline = time.monotonic() + 120
    while not done.done() and time.monotonic() < deadline:
        publish_anything(fuzzed)
        rclpy.spin_once(client, timeout_sec=0.05)
    rclpy.spin_until_future_complete(client, done, timeout_sec=max(0.0, deadline - time.monotonic()))
    assert done.done(), "the maneuver was never answered"
    end = time.monotonic()
    assert all(s.suite.alive().values()), s.suite.alive()
    for topic in (topics.STATE, topics.CONTROLLER_STATUS, topics.ESTIMATE):
        gap, at = monitor.gap_at(topic, fuzzed["start"] + 0.5, end)
        assert gap < 1.0, (f"{topic} stalled for {gap:.2f} s while fuzzing, from {at - fuzzed['start']:.1f} s "
                           f"after the suite started (this test ran from {began - fuzzed['start']:.1f} s)")
    result = done.result().result
    assert result.success or result.error_code in (ErrorCode.ABORTED, ErrorCode.STATE_TIME_JUMP), result.message
    assert "estimator" in s.suite.procs
    if result.success:
        assert result.final_attitude_error < math.radians(1.0)
