"""``att-mission MISSION``: a day in orbit flown by the suite's nodes.

Starts recorder, simulator, estimator, controller and planner (the mission file's rate for the
simulator's step, its state, the control and the estimate; the controller's momentum dumping as the
file says) and flies the target list of the mission file
(:mod:`att_planner.mission.config`) from the scenario's epoch to its horizon. What happens next is
decided by :class:`~att_planner.mission.executive.MissionExecutive` (no ROS): :class:`MissionDriver`
turns what the client's node hears (states, the estimate's health, the planner's and controller's
answers) into its events and carries out its actions as service and action calls, with the wall-time
watchdogs (a wait for sim time gives up below :data:`MIN_WALL_RTF` times real time).

Every decision, slew, dwell, park and miss is published on ``/mission/events``
(``att_msgs/MissionEvent``) and recorded with everything else in one MCAP; a mission of ground sites
also publishes, for a map, the sub-satellite point, the boresight's ground point and the site of each
slew and dwell as ``sensor_msgs/NavSatFix`` (:class:`GroundFixes`). At the end the day's
figures are measured from that log (:func:`att_planner.mission.day.day_report`): the targets' dwells
and pointing errors from the truth state, the zones' margins at their true positions, the wheels.
The last line printed is ``MCAP: <path>``.

Pace: by default the planner plans while the spacecraft flies, as it would on board: the simulator
runs at most at ``start_lead_s / time_budget_s`` × real time, so a plan that takes its whole
wall-time budget still comes back before its slew starts. With ``--rtf max`` the simulator never
waits on wall time (only on the lockstep of its controller) and sim time is held
(``/simulator/hold``) while the planner plans: the day flown no longer depends on how fast the
machine is, and a long mission takes what its compute takes. ``--rtf X`` does the same at most at
X × real time.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np
from sensor_msgs.msg import NavSatFix, NavSatStatus

from att_msgs.msg import AttitudeEstimate, MissionEvent
from att_msgs_py import convert, qos
from att_msgs_py.topics import BORESIGHT_FIX, ESTIMATE, MISSION_EVENTS, SUBSATELLITE_FIX, TARGET_FIX
from att_msgs_py.types import ControlMode, Health, PointingMode
from att_msgs_py.types import MissionEventKind as Kind
from att_planner.control.controller import ControllerConfig
from att_planner.mission import config as mission_config
from att_planner.mission import executive_io as io
from att_planner.mission.day import day_report
from att_planner.mission.executive import MissionExecutive
from att_planner.mission.ground import ground_fixes
from att_planner.nodes.client import client_session, maneuver_request, strip_request
from att_planner.tools.demo import SimClock, domain_line
from att_planner.tools.launch import default_nodes, isolated_env, join_env, start_suite
from att_sim.models import world

MIN_WALL_RTF = 0.5             # waits for sim time give up below this real-time factor
FIX_PERIOD = 1.0               # s of sim time between the ground points published for a map
CONVERGENCE = {int(h) for h in Health}


class Telemetry(SimClock):
    """The spacecraft's latest state message (sim time, attitude, wheels) and the estimate's health,
    heard on the client's node."""

    def __init__(self, node, estimator: bool, on_state=None):
        super().__init__(node)
        self.msg, self.health = None, None if estimator else Health.CONVERGED
        self.on_state = on_state
        if estimator:
            node.create_subscription(AttitudeEstimate, ESTIMATE, self._on_estimate, qos.STREAM_QOS)

    def _on_state(self, msg):
        super()._on_state(msg)
        self.msg = msg
        if self.on_state is not None:
            self.on_state(msg)

    def _on_estimate(self, msg):
        self.health = Health(msg.health) if msg.health in CONVERGENCE else Health.DIVERGED

    @property
    def converged(self) -> bool:
        return self.health == Health.CONVERGED

    @property
    def q_BN(self):
        """The latest state's attitude of the body relative to inertial, [x, y, z, w]."""
        return convert.from_quaternion(self.msg.attitude)

    def wait(self, until: float = -math.inf, timeout: float | None = None) -> float:
        """:meth:`SimClock.wait`, by default as long as the wait takes at :data:`MIN_WALL_RTF`, plus a minute."""
        if timeout is None:
            timeout = 60.0 + (max(0.0, until - self.t) / MIN_WALL_RTF if self.t is not None and until > 0 else 60.0)
        return super().wait(until, timeout)


def fix_msg(stamp, frame_id: str, lat_deg: float, lon_deg: float, alt_m: float) -> NavSatFix:
    """A ``sensor_msgs/NavSatFix`` of a point (deg, deg, m above the ellipsoid); NO_FIX when it is NaN."""
    msg = NavSatFix()
    msg.header.stamp, msg.header.frame_id = stamp, frame_id
    ok = bool(np.isfinite(lat_deg) and np.isfinite(lon_deg))
    msg.status.status = NavSatStatus.STATUS_FIX if ok else NavSatStatus.STATUS_NO_FIX
    msg.latitude, msg.longitude = (float(lat_deg), float(lon_deg)) if ok else (0.0, 0.0)
    msg.altitude = float(alt_m) if ok else 0.0
    msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_UNKNOWN
    return msg


class GroundFixes:
    """The ground points of a mission of ground sites, for a map (Foxglove's Map panel reads
    ``NavSatFix``): the sub-satellite point and the boresight's ground point of the truth state heard,
    every :data:`FIX_PERIOD` s of sim time, and the site of each slew and dwell reported."""

    def __init__(self, node, mission: mission_config.MissionConfig):
        self.field = world.Environment.from_scenario(mission.scenario).field
        self.sensor_axis, self.last = mission.sensor_axis, -math.inf
        self.sites = {t.name: t for t in mission.target_list.targets}
        self.boresight = node.create_publisher(NavSatFix, BORESIGHT_FIX, qos.STREAM_QOS)
        self.subsatellite = node.create_publisher(NavSatFix, SUBSATELLITE_FIX, qos.STREAM_QOS)
        self.target = node.create_publisher(NavSatFix, TARGET_FIX, qos.MISSION_QOS)

    def on_state(self, msg) -> None:
        t = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
        if t < self.last + FIX_PERIOD:
            return
        self.last = t
        r_N = np.array([msg.position.x, msg.position.y, msg.position.z])
        g = ground_fixes(self.field.itrs_rotation(np.array([t])), r_N, convert.from_quaternion(msg.attitude),
                         self.sensor_axis)
        self.subsatellite.publish(fix_msg(msg.header.stamp, "subsatellite", g["sub_lat"][0], g["sub_lon"][0],
                                          g["sub_alt"][0]))
        self.boresight.publish(fix_msg(msg.header.stamp, "boresight", g["bore_lat"][0], g["bore_lon"][0], 0.0))

    def on_event(self, event) -> None:
        site = self.sites.get(event.target)
        if site is not None and event.event in (Kind.SLEW, Kind.DWELL):
            self.target.publish(fix_msg(convert.time_msg(event.t), event.target, math.degrees(site.latitude),
                                        math.degrees(site.longitude), site.altitude))


class MissionDriver:
    """One mission flown through ``client`` (a :class:`~att_planner.nodes.client.SuiteClient`): the
    executive's events from the client's node, its actions as calls."""

    def __init__(self, client, mission: mission_config.MissionConfig, log=print, hold_while_planning: bool = False):
        self.client, self.mission, self.log = client, mission, log
        self.hold_while_planning = hold_while_planning
        controller = mission.scenario.node_params.get("controller", {})
        settle = float(controller.get("settle_time_s", ControllerConfig().settle_time))     # as the node reads it
        estimator = mission.scenario.sensors.gyro is not None
        self.fixes = GroundFixes(client, mission) if mission.target_list.kind == "ground" else None
        self.telemetry = Telemetry(client, estimator, self.fixes.on_state if self.fixes is not None else None)
        self.executive = MissionExecutive.of_mission(mission, settle, converged=not estimator)
        self.events = client.create_publisher(MissionEvent, MISSION_EVENTS, qos.MISSION_QOS)

    def heard(self, kind=io.Tick, **fields):
        """An event of type ``kind`` at the latest state heard."""
        return kind(t=self.telemetry.wait(), q_BN=self.telemetry.q_BN, **fields)

    def deliver(self, event) -> list:
        """The executive's actions after ``event`` (after the estimate's health, when it changed)."""
        actions = []
        if self.telemetry.converged != self.executive.converged:
            actions += self.executive.on(self.heard(io.EstimateHealth, converged=self.telemetry.converged))
        return actions + self.executive.on(event)

    def run(self) -> None:
        """Fly the mission to its horizon or its last target."""
        actions = self.deliver(self.heard())
        while True:
            for action in actions:
                if isinstance(action, (io.Report, io.Log)):
                    self.perform(action)
            if self.executive.done:
                self.end_day()
                if not self.client.delivered(self.events):
                    self.log("[mission] the last mission events were not acknowledged by every subscriber in 10 s")
                return
            actions = self.deliver(self.perform(self.executive.awaiting))

    def end_day(self) -> None:
        """Hold sim time where the day ended: what the nodes fly after it (while the last events are
        acknowledged and the suite stops, which at ``--rtf max`` is minutes of sim time) was never
        decided by the mission and is not its day. The nodes stop held."""
        try:
            answer = self.client.hold_simulator(True)
        except TimeoutError as error:
            self.log(f"[mission] sim time could not be held at the end of the day: {error}")
            return
        if not answer.success:
            self.log(f"[mission] sim time could not be held at the end of the day: {answer.message}")

    def perform(self, action):
        """Carry out one action; the event that answers it, or None."""
        if isinstance(action, io.Report):
            event = action.event
            self.events.publish(convert.mission_event_msg(dataclasses.replace(event, message=event.message[:400])))
            if self.fixes is not None:
                self.fixes.on_event(event)
            self.log(f"[mission] t = {event.t:8.1f} s  {event.event.value:9s} {event.target:14s} {event.message}")
            return None
        if isinstance(action, io.Log):
            self.log(f"[mission] t = {action.t:8.1f} s  {action.text}")
            return None
        if isinstance(action, io.WaitUntil):
            self.telemetry.wait(action.t)
            return self.heard()
        if isinstance(action, io.RequestPlan):
            return self.plan(action)
        if isinstance(action, io.StartManeuver):
            result = self.client.execute(action.plan_id, timeout=60.0 + action.duration / MIN_WALL_RTF,
                                         pointing_after=action.pointing_after)
            return self.heard(io.ManeuverEnded, request=action.request, success=bool(result.success),
                              code=int(result.error_code), message=result.message)
        if isinstance(action, io.SetPointing):
            hold = PointingMode("inertial") if action.q_BN is None else PointingMode("inertial", attitude=action.q_BN)
            answer = self.client.set_mode(ControlMode.POINTING, pointing=hold)
            return self.heard(io.PointingSet, request=action.request, success=bool(answer.success),
                              code=int(answer.error_code), message=answer.message)
        raise TypeError(f"unknown mission action {action!r}")

    def plan(self, action: io.RequestPlan):
        """The planner's answer to ``action`` among the mission's zones where they are at its start
        (sim time held meanwhile when the driver holds it): ``PlanManeuver``, or for a slew onto a
        strip ``ImageStrip``, whose answer says the scan the controller hands over to."""
        m = self.mission
        epoch = m.scenario.epoch + timedelta(seconds=action.t_start)
        common = dict(method=m.method, time_budget=action.time_budget, frame_id=m.scenario.frame_id, epoch=epoch,
                      zones=list(m.zones), wheel_speeds=list(self.telemetry.msg.wheel_speeds))
        if action.end_pointing is not None and action.end_pointing.kind == "strip":
            request, ask = strip_request(action.q_from_BN, action.end_pointing, **common), self.client.image_strip
        else:
            options = {"rate_max": m.rate_max} if math.isfinite(m.rate_max) else {}
            request = maneuver_request(action.q_from_BN, action.q_to_BN, m.sensor_axis, [], options=options,
                                       end_pointing=action.end_pointing, **common)
            ask = self.client.plan
        if self.hold_while_planning:
            with self.client.simulator_held():
                response = ask(request)
        else:
            response = ask(request)
        if not response.success:
            return self.heard(io.PlanRefused, request=action.request, code=int(response.error_code),
                              message=response.message)
        plan = response.plan
        after = convert.pointing_from_msg(response.pointing_after) if ask == self.client.image_strip else None
        return self.heard(io.PlanReturned, request=action.request, plan_id=plan.plan_id, duration=plan.duration,
                          method=plan.method, solve_seconds=plan.solve_seconds,
                          min_cone_margin=plan.verification.min_cone_margin, pointing_after=after)


def mission_and_env(name: str) -> tuple[mission_config.MissionConfig, dict]:
    """The mission file ``name`` (:func:`att_planner.mission.config.load`) and the nodes' environment
    (:func:`isolated_env` of this process's, a domain and discovery range set kept), both checked
    before any node starts. ValueError, one sentence naming what is refused: a mission not shipped,
    a file that is not a valid mission (its line and what is expected), or a malformed
    ``ROS_DOMAIN_ID`` / ``ROS_AUTOMATIC_DISCOVERY_RANGE``."""
    try:
        mission = mission_config.load(name)
    except KeyError as err:
        raise ValueError(err.args[0]) from None
    return mission, isolated_env(inherit=True)


def fly_mission(mission: mission_config.MissionConfig, out: Path, log=print,
                rtf: float | None = None, env: dict | None = None) -> tuple[Path, dict]:
    """Start the nodes, fly ``mission``, stop them; the MCAP's path and the day's report. ``rtf``:
    None, the planner races the flight (module docstring); 0, as fast as possible and sim time held
    while the planner plans; X > 0, the same at most at X × real time. ``env``: the nodes' environment
    (default: :func:`isolated_env` of this process's, a domain and discovery range set kept)."""
    run_dir = out / f"{mission.path.stem}_{datetime.now(UTC).strftime('%Y%m%d_%H%M%S')}"
    mcap_path = run_dir / "run.mcap"
    env = isolated_env(inherit=True) if env is None else env
    log(f"[mission] {domain_line(env)}")
    join_env(env)
    rate = mission.rate
    # the simulator does not wait for the planner: at most start_lead / time_budget × real time, a plan
    # that takes its whole wall-time budget still comes back before its slew's start
    pace = mission.start_lead / mission.time_budget if rtf is None else rtf
    params = {"simulator": {"step_s": 1.0 / rate, "publish_rate_Hz": rate, "clock_rate_Hz": rate,
                            "real_time_factor": pace},
              "controller": {"control_rate_Hz": rate, "momentum_dumping": mission.momentum_dumping,
                             "handover_blend_s": mission.handover_blend},
              "estimator": {"publish_rate_Hz": rate}}
    start = mission.start_attitude()
    if start is not None:
        params["simulator"]["initial_attitude"] = [float(x) for x in start]
    name = mission.scenario.name
    # the driver's telemetry listens to the state: one more subscriber for the simulator to wait for
    suite = start_suite(name, mcap_path, run_dir, env=env, nodes=default_nodes(name), params=params, state_listeners=1)
    wall = time.monotonic()
    try:
        with client_session("mission") as client:
            client.wait_for_servers(timeout=120)
            MissionDriver(client, mission, log, hold_while_planning=rtf is not None).run()
    finally:
        codes = suite.stop()
        log(f"[mission] nodes stopped: {codes}")
    report = day_report(mcap_path, mission.scenario)
    report["wall_seconds"] = time.monotonic() - wall
    report["rtf"] = report["sim_seconds"] / report["wall_seconds"]
    return mcap_path, report


def real_time_factor(text: str) -> float:
    """``--rtf``: 'max' (0.0: as fast as possible) or a finite number > 0."""
    if text.strip().lower() == "max":
        return 0.0
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"--rtf must be 'max' or a finite real-time factor > 0, not {text[:40]!r}")
    return value


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-mission", description=__doc__.splitlines()[0])
    parser.add_argument("mission", help="a mission file (config/missions/NAME.yaml, or a path)")
    parser.add_argument("--out", default="runs", help="directory for the MCAP and the node logs")
    parser.add_argument("--json", help="write the day's report here")
    parser.add_argument("--rtf", type=real_time_factor, default=None,
                        help="'max' (sim time never waits on wall time; held while the planner plans) or a "
                             "real-time factor > 0 (the same, at most that fast); default: the planner plans "
                             "while the spacecraft flies, at start_lead_s / time_budget_s x real time")
    args = parser.parse_args(argv)
    try:
        mission, env = mission_and_env(args.mission)
    except ValueError as err:
        print(f"att-mission: {err}", file=sys.stderr)
        return 2
    mcap_path, report = fly_mission(mission, Path(args.out), rtf=args.rtf, env=env)
    for target in report["targets"]:
        print(f"[mission]   {target['name']:14s} {'observed' if target['observed'] else 'missed  '} "
              f"{target.get('why', '')}")
    print(f"[mission] observed {report['observed']}, missed {report['missed']}, minimum zone margin "
          f"{report['min_margin_deg']:.2f} deg, peak wheel speed {report['peak_wheel_ratio']:.2f} of the limit, "
          f"{report['sim_seconds']:.0f} s of sim time in {report['wall_seconds']:.0f} s (RTF {report['rtf']:.1f})")
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=1))
    print(f"MCAP: {mcap_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
