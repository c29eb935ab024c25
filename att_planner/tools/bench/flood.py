"""Flood: every node's resident memory after a flood of large messages, valid and invalid.

Starts the simulator, estimator, controller and planner of ``--scenario`` as processes
(:func:`att_planner.tools.launch.start_suite`, on a random ``ROS_DOMAIN_ID`` with localhost
discovery; no recorder: it would write every oversized message to disk), reads each node's RSS
(``Rss`` of ``smaps_rollup``, :func:`att_msgs_py.memory.rss_bytes`; the planner's solver workers separately, as the sum
over its descendant processes) once all serve and their resident sets have settled (:func:`settled`),
then sends ``--messages`` messages cycling through
:data:`KINDS`: large valid planning requests (16 moving zones, time-optimal with 200 intervals),
requests of 100,000 zones and schedules of 100,000 targets (about 10 MB), inline and published
plans of 120,000 samples, states, estimates, sensor messages, commands, resets and mode requests
carrying a 10 MB array or string, and a plan within the caps whose fields are invalid. Each
message is sent when the previous one is answered (services, action goals) or acknowledged by
every reader (topics). Reported: each node's RSS after start-up and after the flood (and its
peak between messages), its growth against the criterion (:data:`GROWTH_LIMIT`, 50 MB), and
each request's answer time past its budget (the worst per kind, counted from when the request
is serialised and written; a request without a budget counts from zero; a topic message: until
every reader acknowledged it). The final reading is taken once the resident sets have settled again.
"""
from __future__ import annotations

import math
import os
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from att_msgs_py import memory

GROWTH_LIMIT = 50.0             # MB a node may hold after the flood beyond what it held after start-up
MB = 1024 * 1024
BIG = 1_300_000                 # float64 entries of a 10 MB array
BIG_TEXT = 10 * MB              # characters of a 10 MB string
PLAN_SAMPLES = 120_000          # samples of a 10 MB plan (88 bytes each)
# The flood client's writers repair a lost fragment of a 10 MB message after 50 ms, not Fast DDS's
# default 3 s heartbeat: the flood is paced by the nodes, not by the client's retransmissions.
CLIENT_PROFILES = """<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="http://www.eprosima.com"><profiles>
  <data_writer profile_name="flood_writer" is_default_profile="true">
    <qos><publishMode><kind>ASYNCHRONOUS</kind></publishMode><data_sharing><kind>OFF</kind></data_sharing></qos>
    <times><heartbeat_period><sec>0</sec><nanosec>50000000</nanosec></heartbeat_period></times>
    <historyMemoryPolicy>DYNAMIC</historyMemoryPolicy>
  </data_writer>
  <data_reader profile_name="flood_reader" is_default_profile="true">
    <qos><data_sharing><kind>OFF</kind></data_sharing></qos><historyMemoryPolicy>DYNAMIC</historyMemoryPolicy>
  </data_reader>
</profiles></dds>
"""
NODES = ("simulator", "estimator", "controller", "planner")
KINDS = ("valid plan request", "plan request of 100k zones", "schedule of 100k targets", "inline plan 10 MB",
         "invalid inline plan", "published plan 10 MB", "state 10 MB", "estimate 10 MB", "wheel speeds 10 MB",
         "sun sensors 10 MB", "star tracker 10 MB", "command 10 MB", "reset 10 MB", "mode request 10 MB",
         "plan request of 100k cones", "valid schedule")


def configure(parser):
    parser.add_argument("--scenario", default="swift_demo")
    parser.add_argument("--messages", type=int, default=1000, help="messages of the flood (default 1000)")
    parser.add_argument("--state-source", default="truth", choices=("truth", "estimate"),
                        help="the controller's (truth: it reads the flooded states; estimate: the estimates)")
    parser.add_argument("--out", default=None, help="directory for the nodes' logs (default: a temporary one)")


def descendants(pid: int) -> list[int]:
    """The processes below ``pid`` (children, their children, ...), from /proc."""
    parents = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    parents[int(entry)] = int(fh.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
    found, frontier = [], [pid]
    while frontier:
        children = [p for p, parent in parents.items() if parent in frontier]
        found += children
        frontier = children
    return found


def resident(suite) -> dict[str, float]:
    """MB resident per node process, and ``planner workers``: the planner's descendants together."""
    out = {name: (memory.rss_bytes(suite.procs[name].pid) or 0) / MB for name in NODES}
    out["planner workers"] = sum(memory.rss_bytes(p) or 0 for p in descendants(suite.procs["planner"].pid)) / MB
    return out


def settled(suite, timeout: float = 60.0, tolerance: float = 2.0) -> dict[str, float]:
    """:func:`resident` once two readings 1 s apart agree within ``tolerance`` MB for every process
    and the planner has as many descendants (a worker being replaced and warmed, or a message still
    being read after the middleware acknowledged it, is not what the node keeps); the last reading
    after ``timeout`` s otherwise."""
    deadline = time.monotonic() + timeout
    before = (resident(suite), len(descendants(suite.procs["planner"].pid)))
    while True:
        time.sleep(1.0)                     # wait-ok: the interval between two readings being compared
        now = (resident(suite), len(descendants(suite.procs["planner"].pid)))
        if now[1] == before[1] and all(abs(now[0][k] - before[0][k]) <= tolerance for k in now[0]):
            return now[0]
        if time.monotonic() > deadline:
            return now[0]
        before = now


class Flood:
    """The client side: one message of each kind, built once, and its sender."""

    def __init__(self, node, scenario):
        from rclpy.action import ActionClient
        from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import JointState

        from att_msgs.action import ExecuteManeuver
        from att_msgs.msg import (
            ActuatorCommand,
            AttitudeEstimate,
            CoarseSunSensors,
            ManeuverPlan,
            SpacecraftState,
            StarTracker,
        )
        from att_msgs.srv import PlanManeuver, PlanSchedule, ResetSimulator, SetControllerMode
        from att_msgs_py import qos, topics

        self.node = node
        shallow = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=2, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.VOLATILE)
        latched = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.pubs = {kind: node.create_publisher(t, topic, q) for kind, t, topic, q in (
            (ManeuverPlan, ManeuverPlan, topics.PLANS, latched),
            (SpacecraftState, SpacecraftState, topics.STATE, shallow),
            (AttitudeEstimate, AttitudeEstimate, topics.ESTIMATE, shallow),
            (JointState, JointState, topics.WHEEL_SPEEDS, shallow),
            (CoarseSunSensors, CoarseSunSensors, topics.SUN_SENSORS, shallow),
            (StarTracker, StarTracker, topics.STAR_TRACKER, shallow),
            (ActuatorCommand, ActuatorCommand, topics.COMMAND, shallow))}
        self.services = {PlanManeuver: node.create_client(PlanManeuver, topics.PLAN_MANEUVER,
                                                          qos_profile=qos.SERVICE_QOS),
                         PlanSchedule: node.create_client(PlanSchedule, topics.PLAN_SCHEDULE,
                                                          qos_profile=qos.SERVICE_QOS),
                         ResetSimulator: node.create_client(ResetSimulator, topics.RESET_SIMULATOR),
                         SetControllerMode: node.create_client(SetControllerMode, topics.SET_CONTROLLER_MODE)}
        self.action = ActionClient(node, ExecuteManeuver, topics.EXECUTE_MANEUVER)
        self.messages = messages(scenario)

    def wait_ready(self, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        for client in self.services.values():
            if not client.wait_for_service(timeout_sec=max(0.1, deadline - time.monotonic())):
                raise TimeoutError(f"service {client.srv_name} not available after {timeout:g} s")
        if not self.action.wait_for_server(timeout_sec=max(0.1, deadline - time.monotonic())):
            raise TimeoutError(f"the execute action is not available after {timeout:g} s")

    def _wait(self, future, timeout: float):
        import rclpy
        rclpy.spin_until_future_complete(self.node, future, timeout_sec=timeout)
        if not future.done():
            raise TimeoutError("no answer")
        return future.result()

    def send(self, kind: str, timeout: float = 120.0) -> tuple[float, float, int | None]:
        """Send one message of ``kind``: (answer seconds, its budget, the answer's error code or None)."""
        from rclpy.duration import Duration

        msg = self.messages[kind]
        code = None
        if type(msg).__name__.endswith("_Request"):
            future = self.services[_service_of(msg)].call_async(msg)
            start = time.monotonic()           # serialised and written: the server's time starts
            code = self._wait(future, timeout).error_code
        elif type(msg).__name__.endswith("_Goal"):
            future = self.action.send_goal_async(msg)
            start = time.monotonic()
            handle = self._wait(future, timeout)
            if handle.accepted:
                code = self._wait(handle.get_result_async(), timeout).result.error_code
        else:
            pub = self.pubs[type(msg)]
            pub.publish(msg)
            start = time.monotonic()
            pub.wait_for_all_acked(Duration(seconds=timeout))
        return time.monotonic() - start, float(getattr(msg, "time_budget", 0.0)), code


def _service_of(msg):
    from att_msgs.srv import PlanManeuver, PlanSchedule, ResetSimulator, SetControllerMode
    return next(s for s in (PlanManeuver, PlanSchedule, ResetSimulator, SetControllerMode)
                if isinstance(msg, s.Request))


def messages(scenario) -> dict:
    """One message of each of :data:`KINDS` (built once, sent many times)."""
    from sensor_msgs.msg import JointState

    from att_msgs.action import ExecuteManeuver
    from att_msgs.msg import (
        ActuatorCommand,
        AttitudeEstimate,
        CoarseSunSensors,
        KeepOutCone,
        ManeuverPlan,
        SpacecraftState,
        StarTracker,
    )
    from att_msgs.srv import PlanSchedule, ResetSimulator, SetControllerMode
    from att_msgs_py import convert
    from att_msgs_py.types import Zone
    from att_planner.nodes.client import maneuver_request
    from att_sim.models import rotations as rot

    q0, q1 = rot.IDENTITY, rot.from_axis_angle([0.0, 0.0, 1.0], math.radians(60.0))
    epoch = datetime(2026, 3, 20, 12, 0, tzinfo=UTC)
    z_B = np.array([0.0, 0.0, 1.0])
    zones = [Zone(f"sun{i}", "sun", z_B, math.radians(2.0 + 0.1 * i)) for i in range(8)]
    zones += [Zone(f"moon{i}", "moon", z_B, math.radians(2.0 + 0.1 * i)) for i in range(8)]
    valid = maneuver_request(q0, q1, z_B, [], method="time_optimal", time_budget=2.0, epoch=epoch, zones=zones,
                             options={"intervals": 200}, spacecraft=scenario)
    many_zones = maneuver_request(q0, q1, z_B, [], time_budget=0.5, spacecraft=scenario)
    many_zones.zones = [convert.zone_msg(zones[0])] * 100_000
    many_cones = maneuver_request(q0, q1, z_B, [], time_budget=0.5, spacecraft=scenario)
    many_cones.cones = [KeepOutCone(name="c", half_angle=0.1)] * 100_000
    targets = [convert.quaternion(rot.from_axis_angle([0.0, 0.0, 1.0], a)) for a in np.linspace(0.2, 1.0, 3)]
    schedule = PlanSchedule.Request(target_names=["a", "b", "c"], targets=targets, spacecraft=scenario,
                                    time_budget=2.0)
    schedule.start_attitude = convert.quaternion(q0)
    big_schedule = PlanSchedule.Request(target_names=["t"] * 100_000, targets=targets[:1] * 100_000,
                                        spacecraft=scenario, time_budget=0.5)
    big_schedule.start_attitude = convert.quaternion(q0)

    def plan(samples: int, bad: bool = False) -> ManeuverPlan:
        p = ManeuverPlan(plan_id="flood", method="eigenaxis", status="optimal", spacecraft=scenario,
                         control_kind="body_torque", interpolation="linear")
        p.header.frame_id = "eci"
        p.times = np.linspace(0.0, 100.0, samples).tolist()
        p.duration = 100.0
        p.attitudes = [convert.quaternion(q0)] * samples
        p.rates = [convert.vector3(np.zeros(3))] * samples
        p.torques = [convert.vector3([math.nan if bad else 0.0, 0.0, 0.0])] * samples
        p.sensor_axis = convert.vector3(z_B)
        return p

    big = np.zeros(BIG).tolist()
    state = SpacecraftState(wheel_speeds=big)
    state.attitude.w = 1.0
    estimate = AttitudeEstimate(message="m" * BIG_TEXT)
    estimate.attitude.w = 1.0
    mode = SetControllerMode.Request(mode=1, key_id="k", signature=bytes(BIG_TEXT))
    return {
        "valid plan request": valid, "plan request of 100k zones": many_zones,
        "schedule of 100k targets": big_schedule,
        "inline plan 10 MB": ExecuteManeuver.Goal(use_inline_plan=True, plan=plan(PLAN_SAMPLES)),
        "invalid inline plan": ExecuteManeuver.Goal(use_inline_plan=True, plan=plan(20_000, bad=True)),
        "published plan 10 MB": plan(PLAN_SAMPLES), "state 10 MB": state, "estimate 10 MB": estimate,
        "wheel speeds 10 MB": JointState(velocity=big), "sun sensors 10 MB": CoarseSunSensors(values=big),
        "star tracker 10 MB": StarTracker(sensor_frame_id="s" * BIG_TEXT),
        "command 10 MB": ActuatorCommand(wheel_torques=big), "reset 10 MB": ResetSimulator.Request(wheel_speeds=big),
        "mode request 10 MB": mode, "plan request of 100k cones": many_cones, "valid schedule": schedule}


def flood(scenario: str, n_messages: int, out: Path, state_source: str = "truth") -> dict:
    """Run the flood (module docstring) and return its figures."""
    from att_planner.nodes.client import client_session
    from att_planner.tools.launch import isolated_env, join_env, start_suite

    env = isolated_env()
    join_env(env)
    suite = start_suite(scenario, out / "unused.mcap", out, env=env, nodes=NODES,
                        params={"controller": {"state_source": state_source}})
    (out / "flood_client.xml").write_text(CLIENT_PROFILES)       # this process's writers only, not the nodes'
    os.environ.update({"RMW_FASTRTPS_USE_QOS_FROM_XML": "1",
                       "FASTDDS_DEFAULT_PROFILES_FILE": str(out / "flood_client.xml")})
    try:
        with client_session("flood_client") as client:
            sender = Flood(client, scenario)
            sender.wait_ready(timeout=180.0)
            for kind in ("valid plan request", "valid schedule"):     # the workers' first solves: start-up
                sender.send(kind)
            start = settled(suite)
            peak = dict(start)
            answers = {kind: [] for kind in KINDS}
            timeline = []                   # RSS after each cycle of KINDS
            t0 = time.monotonic()
            for i in range(n_messages):
                kind = KINDS[i % len(KINDS)]
                seconds, budget, code = sender.send(kind)
                answers[kind].append((seconds, budget, code))
                if i % len(KINDS) == len(KINDS) - 1:
                    timeline.append(resident(suite))
                    peak = {k: max(v, peak[k]) for k, v in timeline[-1].items()}
            flood_seconds = time.monotonic() - t0
            end = settled(suite)
            alive = suite.alive()
    finally:
        codes = suite.stop()
    growth = {k: end[k] - start[k] for k in start}
    return {"scenario": scenario, "messages": n_messages, "state_source": state_source,
            "flood_seconds": flood_seconds, "start_mib": start, "end_mib": end, "peak_mib": peak,
            "timeline_mib": timeline,             "growth_mib": growth, "alive": alive, "exit_codes": codes,
            "answers": {k: [{"seconds": s, "budget": b, "code": c} for s, b, c in v] for k, v in answers.items()},
            "worst_past_budget": {k: max((s - b for s, b, _ in v), default=None) for k, v in answers.items()},
            "growth_limit_mib": GROWTH_LIMIT, "passed": all(g <= GROWTH_LIMIT for g in growth.values())}


def run(args) -> dict:
    out = Path(args.out or tempfile.mkdtemp(prefix="att_flood_"))
    r = flood(args.scenario, args.messages, out, args.state_source)
    print(f"flood {r['scenario']}: {r['messages']} messages in {r['flood_seconds']:.1f} s "
          f"(controller on the {r['state_source']}); nodes alive: {r['alive']}")
    print(f"  {'process':16s} {'start MiB':>10s} {'end MiB':>10s} {'peak MiB':>10s} {'growth':>8s}")
    for name in r["start_mib"]:
        print(f"  {name:16s} {r['start_mib'][name]:10.1f} {r['end_mib'][name]:10.1f} {r['peak_mib'][name]:10.1f} "
              f"{r['growth_mib'][name]:+8.1f}")
    print(f"  {'kind':28s} {'sent':>5s} {'worst answer - budget (s)':>26s}  codes (topics: until acknowledged)")
    for kind, answers in r["answers"].items():
        codes = sorted({a["code"] for a in answers if a["code"] is not None})
        worst = r["worst_past_budget"][kind]
        print(f"  {kind:28s} {len(answers):5d} {'-' if worst is None else f'{worst:.3f}':>26s}  {codes or ''}")
    print(f"  criterion: growth <= {GROWTH_LIMIT:g} MB per process: {'PASS' if r['passed'] else 'FAIL'}")
    print(f"  logs: {out}")
    return r
