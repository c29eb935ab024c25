"""``att-mission MISSION``: a day in orbit (issue 17) flown by the suite's nodes.

Starts recorder, simulator, estimator, controller and planner (the mission file's rate for the
simulator's step, its state, the control and the estimate; the simulator as fast as the loop goes;
the controller's momentum dumping as the file says) and flies the target list of the mission file
(:mod:`att_planner.mission.config`) from the scenario's epoch to its horizon:

1. :class:`~att_planner.mission.scheduler.MissionScheduler` decides the order from where the
   spacecraft holds now (targets no zone leaves visible for their dwell before the horizon are missed,
   with the zone that covers them);
2. the first target's slew is requested from the planner (the scenario's zones where they are when it
   is flown: its start is ``start_lead`` s of sim time after the request, later when the target becomes
   visible later), re-planned later once when it would arrive before the target is visible;
3. while waiting for that start the spacecraft holds, or parks at another source when the zones reach
   the held attitude first;
4. the controller flies the plan and holds the target for its dwell; then back to 1. A slew the
   planner or the controller refuses is tried again at the next decision, twice at most (the target is
   then missed, with the refusal);
5. with no target left, the spacecraft holds (leaving a zone's path) until the horizon.

Every decision, slew, dwell, park and miss is published on ``/mission/events``
(``att_msgs/MissionEvent``) and recorded with everything else in one MCAP. At the end the day's
figures are measured from that log (:func:`att_planner.mission.day.day_report`): the targets' dwells
and pointing errors from the truth state, the zones' margins at their true positions, the wheels.
The last line printed is ``MCAP: <path>``.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections import Counter
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np

from att_msgs.msg import AttitudeEstimate, MissionEvent
from att_msgs_py import convert, qos
from att_msgs_py.errors import ConfigError
from att_msgs_py.topics import ESTIMATE, MISSION_EVENTS
from att_msgs_py.types import ControlMode, Health, PointingMode
from att_msgs_py.types import MissionEvent as Event
from att_msgs_py.types import MissionEventKind as Kind
from att_planner.control.controller import ControllerConfig
from att_planner.mission import config as mission_config
from att_planner.mission.day import day_report
from att_planner.mission.scheduler import MissionScheduler
from att_planner.nodes.client import client_session, maneuver_request
from att_planner.tools.demo import SimClock, domain_line
from att_planner.tools.launch import default_nodes, isolated_env, join_env, start_suite

SITE_DURATION_MATCH = 2.0      # s: a site's plan starts within this of the start its sky was planned for
SITE_ARRIVAL_SLACK = 1.0       # s: a slew to a site must arrive within this of the site's visibility
SLEW_FACTOR = 1.25             # planned slew / bang-coast-bang estimate (1.18 measured on the rate-bounded day)
MAX_ATTEMPTS = 2               # slews refused per target before it is missed
MIN_WALL_RTF = 0.5             # waits for sim time give up below this real-time factor
RECOVERY_STEP = 10.0           # s of sim time between the checks of a held attitude that cannot start a slew
RECOVERY_LIMIT = 1800.0        # s of sim time a mission waits for it at most
ESCAPE_LEAD = 60.0             # s of sim time from the request to the start of a slew away from a zone's path
ESCAPE_BUDGET = 2.0            # s of wall time the planner gets for it
CONVERGENCE = {int(h) for h in Health}


class Telemetry(SimClock):
    """The spacecraft's latest state message (sim time, attitude, wheels) and the estimate's health,
    heard on the client's node."""

    def __init__(self, node, estimator: bool):
        super().__init__(node)
        self.msg, self.health = None, None if estimator else Health.CONVERGED
        if estimator:
            node.create_subscription(AttitudeEstimate, ESTIMATE, self._on_estimate, qos.STREAM_QOS)

    def _on_state(self, msg):
        super()._on_state(msg)
        self.msg = msg

    def _on_estimate(self, msg):
        self.health = Health(msg.health) if msg.health in CONVERGENCE else Health.DIVERGED

    @property
    def converged(self) -> bool:
        return self.health == Health.CONVERGED

    def wait(self, until: float = -math.inf, timeout: float | None = None) -> float:
        """:meth:`SimClock.wait`, by default as long as the wait takes at :data:`MIN_WALL_RTF`, plus a minute."""
        if timeout is None:
            timeout = 60.0 + (max(0.0, until - self.t) / MIN_WALL_RTF if self.t is not None and until > 0 else 60.0)
        return super().wait(until, timeout)


class MissionRun:
    """One mission flown through ``client`` (a :class:`~att_planner.nodes.client.SuiteClient`)."""

    def __init__(self, client, mission: mission_config.MissionConfig, log=print):
        self.client, self.mission, self.log = client, mission, log
        self.scenario = mission.scenario
        controller = self.scenario.node_params.get("controller", {})
        self.settle = float(controller.get("settle_time", ControllerConfig().settle_time))   # as the node reads it
        self.blend = mission.handover_blend                                                  # set by fly_mission
        self.targets = mission.targets()
        self.scheduler = MissionScheduler(self.scenario, self.targets, mission.horizon, zones=mission.zones,
                                          margin=mission.margin, lead=mission.start_lead, rate_max=mission.rate_max,
                                          slew_factor=SLEW_FACTOR, settle=self.settle, blend=self.blend)
        self.telemetry = Telemetry(client, mission.scenario.sensors.gyro is not None)
        self.events = client.create_publisher(MissionEvent, MISSION_EVENTS, qos.MISSION_QOS)
        self.attempts: Counter = Counter()

    def publish(self, kind: Kind, target: str = "", start: float = 0.0, end: float = 0.0, plan_id: str = "",
                message: str = "") -> None:
        q, d = np.array([0.0, 0.0, 0.0, 1.0]), np.zeros(3)
        if target:
            at = start or self.telemetry.t
            q, d = self.targets[target].attitudes(at)[0], self.targets[target].direction_at(at)
        m = self.mission
        site = self.targets[target].track if target else None
        self.events.publish(convert.mission_event_msg(Event(
            self.telemetry.t, kind, target, start, end, q, d, m.sensor_axis if target else np.zeros(3),
            m.pointing_tolerance if target else 0.0, plan_id, message[:400], self.scenario.frame_id,
            site.mode if site is not None else None, tuple(z.name for z in m.zones))))
        self.log(f"[mission] t = {self.telemetry.t:8.1f} s  {kind.value:9s} {target:14s} {message}")

    def fly(self, name: str, q_from, t_start: float, wait_for_visibility: bool, budget: float | None = None):
        """Plan the slew from ``q_from`` to target ``name`` starting at sim time ``t_start`` and fly it;
        its end time, or None after a refusal (published; none while the estimate is not converged).
        ``wait_for_visibility``: a plan that would arrive before the target is visible for its dwell is
        planned again to arrive then (twice at most). ``budget``: the planner's wall time (default the mission's)."""
        q_to = self.targets[name].attitude
        if not self.telemetry.converged:
            return None
        for attempt in range(3):
            plan = self.plan(name, q_from, q_to, t_start, budget)
            if plan is None:
                return None
            arrival = t_start + plan.duration + self.settle           # the controller reports it done then
            visible = self.scheduler.observable_from(name, arrival) if wait_for_visibility else arrival
            if visible is None:
                self.publish(Kind.REFUSED, name, message=f"the slew would arrive at {arrival:.0f} s, after the "
                                                         "target's last visibility before the horizon")
                return None
            if visible <= arrival + 1.0:
                break
            if attempt == 2:
                self.publish(Kind.REFUSED, name, message=f"three slews arrived before the target is visible "
                                                         f"at {visible:.0f} s")
                return None
            t_start = visible - plan.duration - self.settle
        return self.execute(name, plan, t_start)

    def fly_to_site(self, name: str, q_from, t_start: float):
        """Plan a slew from ``q_from``, starting at sim time ``t_start`` or later, that arrives at rest
        on ground site ``name``'s tracking attitude when the site is visible for its blend and dwell,
        and fly it, handing over to the site's pointing mode; the arrival time, or None after a
        refusal (published). The arrival ``T`` is fixed first (the site's law at ``T`` is the plan's
        goal), then the start ``T − duration`` (planned again, twice at most, while the plan's
        duration moves its start's sky by more than :data:`SITE_DURATION_MATCH` s)."""
        target = self.targets[name]
        if not self.telemetry.converged:
            return None
        arrival = self.scheduler.observable_from(name, t_start + self.scheduler.slew_to(name, q_from, t_start))
        duration = None
        for _ in range(4):
            if arrival is None:
                self.publish(Kind.REFUSED, name, message="the slew cannot arrive before the site's last "
                                                         "visibility before the horizon")
                return None
            guess = duration or self.scheduler.slew_to(name, q_from, t_start)
            plan = self.plan(name, q_from, target.attitudes(arrival)[0], max(t_start, arrival - guess))
            if plan is None:
                return None
            duration = plan.duration
            if arrival - duration < t_start:               # longer than estimated: a later visibility
                arrival = self.scheduler.observable_from(name, t_start + duration)
                continue
            if abs(duration - guess) <= SITE_DURATION_MATCH:
                break
        else:
            self.publish(Kind.REFUSED, name, message="four plans did not fit the site's visibility")
            return None
        return self.execute(name, plan, arrival - duration, pointing_after=target.track.mode)

    def plan(self, name: str, q_from, q_to, t_start: float, budget: float | None = None):
        """The planner's plan from ``q_from`` to ``q_to`` starting at sim time ``t_start`` among the
        mission's zones where they are then (``budget`` s of wall time, default the mission's), or None
        after a refusal (published)."""
        epoch = self.scenario.epoch + timedelta(seconds=t_start)
        options = {"rate_max": self.mission.rate_max} if math.isfinite(self.mission.rate_max) else {}
        request = maneuver_request(q_from, q_to, self.mission.sensor_axis, [], method=self.mission.method,
                                   options=options, time_budget=budget or self.mission.time_budget,
                                   frame_id=self.scenario.frame_id, epoch=epoch, zones=list(self.mission.zones),
                                   wheel_speeds=list(self.telemetry.msg.wheel_speeds))
        response = self.client.plan(request)
        if not response.success:
            self.publish(Kind.REFUSED, name, message=f"planner: code {response.error_code}: {response.message}")
            return None
        return response.plan

    def execute(self, name: str, plan, t_start: float, pointing_after=None):
        """Fly ``plan`` from sim time ``t_start`` (``pointing_after``: the mode the controller hands over
        to at its end); the time the controller reports it done, or None after a refusal (published)."""
        late = self.telemetry.wait() - t_start
        if late > 0:            # never flown: no slew event (a slew event is a slew started)
            self.publish(Kind.REFUSED, name, plan_id=plan.plan_id,
                         message=f"planning ended {late:.1f} s of sim time after the slew's start ({plan.method}, "
                                 f"planned in {plan.solve_seconds:.2f} s): start_lead is too short")
            return None
        self.publish(Kind.SLEW, name, t_start, t_start + plan.duration, plan.plan_id,
                     f"{plan.method} {plan.duration:.1f} s, {math.degrees(plan.verification.min_cone_margin):.2f} deg "
                     f"from the zones, planned in {plan.solve_seconds:.2f} s")
        self.telemetry.wait(t_start)
        result = self.client.execute(plan.plan_id, timeout=60.0 + plan.duration / MIN_WALL_RTF,
                                     pointing_after=pointing_after)
        if not result.success:
            self.publish(Kind.REFUSED, name, plan_id=plan.plan_id,
                         message=f"controller: code {result.error_code}: {result.message}")
            return None
        return self.telemetry.t

    def park(self, q_hold, t: float, until: float, lead: float | None = None, budget: float | None = None):
        """Slew to a source that stays visible until ``until`` (:meth:`MissionScheduler.parks`, the
        nearest three tried), starting ``lead`` s from now (default the mission's ``start_lead``) and
        planned in ``budget``, and hold it; (its attitude, the time after) or None when none was flown."""
        for name in self.scheduler.parks(q_hold, t, until)[:3]:
            end = self.fly(name, q_hold, t + (lead or self.mission.start_lead), wait_for_visibility=False,
                           budget=budget)
            if end is not None:
                self.publish(Kind.PARK, name, end, max(end, until),
                             message=f"waiting at {name} until t = {until:.0f} s" if end < until else
                             f"parked at {name} after the t = {until:.0f} s it was to wait until: deciding again")
                return self.hold(self.targets[name]), end
            t = self.telemetry.t
        return None

    def hold(self, target=None) -> np.ndarray:
        """Hold still after reaching or leaving ``target`` (None: where the mission starts, the
        attitude of that moment) in the controller's inertial pointing mode
        (the mode that dumps momentum with the magnetorquers; the hold that ends a plan does not): a
        source's attitude, or after a site the attitude of that moment (the controller stops tracking
        it; braking takes the planning lead). A mode starts on a converged estimate: after a site,
        whose pass can blind both trackers, it is asked again every :data:`RECOVERY_STEP` s (at most
        :data:`RECOVERY_LIMIT` s) while the site is still tracked; a source stays held by the plan's
        end. The attitude held."""
        fixed = target is not None and not target.moving
        hold = PointingMode("inertial", attitude=target.attitude) if fixed else PointingMode("inertial")
        t, end = self.telemetry.t, self.telemetry.t + (RECOVERY_LIMIT if target is not None and target.moving else 0.0)
        answer = self.client.set_mode(ControlMode.POINTING, pointing=hold)
        if not answer.success:
            self.log(f"[mission] t = {t:8.1f} s  the controller refused the hold {target.name if target else 'here'} "
                     f"(code {answer.error_code}: {answer.message})" + (f": still tracking it, asking every "
                                                                       f"{RECOVERY_STEP:g} s" if end > t else ""))
        while not answer.success and t < end:
            t = self.telemetry.wait(t + RECOVERY_STEP)
            answer = self.client.set_mode(ControlMode.POINTING, pointing=hold)
        return target.attitude if fixed else convert.from_quaternion(self.telemetry.msg.attitude)

    def startable(self, q_hold, t: float) -> bool:
        """Whether a slew can start from ``q_hold`` soon after ``t``: the attitude clear of every zone
        until ``start_lead`` from now and the estimate converged."""
        return self.telemetry.converged and self.scheduler.clear(q_hold, t, t + self.mission.start_lead)

    def recover(self, q_hold, t: float, until: float = math.inf) -> tuple:
        """Get back to where a slew can start (:meth:`startable`): with a converged estimate a zone is
        about to cover the held attitude, so leave it while it is clear for :data:`ESCAPE_LEAD` s (a
        park planned in :data:`ESCAPE_BUDGET` s); else (or when no park was flown) hold until a slew
        can start, at most :data:`RECOVERY_LIMIT` s and not past ``until``. The attitude held and the
        time then."""
        if self.telemetry.converged and self.scheduler.clear(q_hold, t, t + ESCAPE_LEAD):
            self.log(f"[mission] t = {t:8.1f} s  a zone is about to cover the held attitude: leaving it")
            parked = self.park(q_hold, t, t + ESCAPE_LEAD + 2.0 * self.mission.start_lead, ESCAPE_LEAD, ESCAPE_BUDGET)
            if parked is not None:
                return parked
        why = ("the estimate is not converged" if not self.telemetry.converged else
               "a zone reaches the held attitude, or no tracker sees the sky, within the lead")
        self.log(f"[mission] t = {t:8.1f} s  holding: {why}")
        end = min(t + RECOVERY_LIMIT, until)
        while t < end and not self.startable(q_hold, t):
            t = self.telemetry.wait(t + RECOVERY_STEP)
        return q_hold, t

    def hold_until(self, q_hold, t: float, until: float) -> None:
        """With nothing left to observe, hold (dumping) until ``until`` (the horizon: the day is flown
        whole); a zone due at the held attitude within two leads is left for a park at a source clear
        for :data:`RECOVERY_LIMIT` s (or until ``until``), within one lead as :meth:`recover` does
        (no slew follows: the trackers' view of the sky does not matter here)."""
        lead = self.mission.start_lead
        while t < until:
            if not self.scheduler.keeps_zones(q_hold, t, min(until, t + 2.0 * lead)):
                parked = self.park(q_hold, t, min(until, t + RECOVERY_LIMIT))
                if parked is not None:
                    q_hold, t = parked
                    continue
                if not self.scheduler.keeps_zones(q_hold, t, min(until, t + lead)):
                    q_hold, t = self.recover(q_hold, t, until)
            t = self.telemetry.wait(min(until, t + RECOVERY_STEP))

    def next_slew(self, decision, q_hold, t: float):
        """The first of the decided order's first three targets whose slew can wait for its start at
        ``q_hold`` clear of the zones: (name, start) or (None, the first target's start)."""
        first = None
        for name, arrival in list(zip(decision.order, decision.arrivals))[:3]:
            start = max(t + self.mission.start_lead, arrival - self.scheduler.slew_to(name, q_hold, arrival))
            first = start if first is None else first
            if self.scheduler.clear(q_hold, t, start):
                return name, start
        return None, first

    def count_attempt(self, name: str, remaining: list) -> None:
        """One more failed attempt at target ``name``: missed after :data:`MAX_ATTEMPTS`."""
        self.attempts[name] += 1
        if self.attempts[name] >= MAX_ATTEMPTS:
            remaining.remove(name)
            self.publish(Kind.MISSED, name, message=f"{MAX_ATTEMPTS} attempts at it failed (above)")

    def run(self) -> None:
        """Fly the mission to its horizon or its last target."""
        t = self.telemetry.wait()
        q_hold = convert.from_quaternion(self.telemetry.msg.attitude)
        remaining, observed, holding = list(self.targets), 0, False
        while remaining and t < self.mission.horizon:
            if not self.startable(q_hold, t):
                q_hold, t = self.recover(q_hold, t)
            if not holding:                 # the attitude the scenario starts at, held (not left to drift)
                q_hold, holding = self.hold(), True
            decision = self.scheduler.decide(t, q_hold, remaining)
            for name, why in decision.missed.items():
                self.publish(Kind.MISSED, name, message=why)
                remaining.remove(name)
            if not decision.order:
                break
            self.publish(Kind.SCHEDULED, message="order " + ", ".join(
                f"{k} at {a:.0f} s" for k, a in zip(decision.order, decision.arrivals)))
            name, t_start = self.next_slew(decision, q_hold, t)
            if name is None:                         # the held attitude cannot wait: park, then decide again
                parked = self.park(q_hold, t, t_start)
                if parked is None:
                    self.log(f"[mission] t = {t:8.1f} s  no source to park at until t = {t_start:.0f} s: holding")
                    t = self.telemetry.wait(t + RECOVERY_STEP)
                else:
                    q_hold, t = parked
                continue
            t = self.telemetry.wait(t_start - self.mission.start_lead)
            target, t_start = self.targets[name], max(t_start, t + self.mission.start_lead)
            end = self.fly_to_site(name, q_hold, t_start) if target.moving else \
                self.fly(name, q_hold, t_start, wait_for_visibility=True)
            if end is None:
                q_hold, t = convert.from_quaternion(self.telemetry.msg.attitude), self.telemetry.t
                if self.startable(q_hold, t):               # the slew itself was refused: the target's count
                    self.count_attempt(name, remaining)
                continue
            start = self.scheduler.observable_from(name, end)
            if start is None or (start > end + SITE_ARRIVAL_SLACK if target.moving
                                 else not self.scheduler.clear(target.attitude, end, start)):
                self.publish(Kind.REFUSED, name, message="arrived too late for this visibility window: "
                                                         "deciding again")
                self.count_attempt(name, remaining)
                q_hold, t = self.hold(target), self.telemetry.t
                continue
            if target.moving:                               # the controller blends into the site's law first
                start = end + self.blend
            else:
                self.hold(target)
            self.publish(Kind.DWELL, name, start, start + target.dwell, message=f"observing for {target.dwell:g} s")
            t = self.telemetry.wait(start + target.dwell)
            q_hold = self.hold(target) if target.moving else target.attitude
            remaining.remove(name)
            observed += 1
        for name in remaining:
            self.publish(Kind.MISSED, name, message=f"not reached before the mission ended (horizon "
                                                     f"{self.mission.horizon:g} s)")
        self.hold_until(q_hold, t, self.mission.horizon)
        self.publish(Kind.ENDED, message=f"{observed} targets held for their dwell, {len(self.targets) - observed} "
                                         f"missed or not reached at t = {self.telemetry.t:.0f} s")


def fly_mission(mission: mission_config.MissionConfig, out: Path, log=print) -> tuple[Path, dict]:
    """Start the nodes, fly ``mission``, stop them; the MCAP's path and the day's report."""
    run_dir = out / f"{mission.path.stem}_{datetime.now(UTC).strftime('%Y%m%d_%H%M%S')}"
    mcap_path = run_dir / "run.mcap"
    env = isolated_env(inherit=True)
    log(f"[mission] {domain_line(env)}")
    join_env(env)
    rate = mission.rate
    # the simulator does not wait for the planner: at most start_lead / time_budget × real time, a plan
    # that takes its whole wall-time budget still comes back before its slew's start
    pace = mission.start_lead / mission.time_budget
    params = {"simulator": {"step": 1.0 / rate, "publish_rate": rate, "clock_rate": rate, "real_time_factor": pace},
              "controller": {"control_rate": rate, "momentum_dumping": mission.momentum_dumping,
                             "handover_blend": mission.handover_blend},
              "estimator": {"publish_rate": rate}}
    name = mission.scenario.name
    suite = start_suite(name, mcap_path, run_dir, env=env, nodes=default_nodes(name), params=params)
    wall = time.monotonic()
    try:
        with client_session("mission") as client:
            client.wait_for_servers(timeout=120)
            MissionRun(client, mission, log).run()
    finally:
        codes = suite.stop()
        log(f"[mission] nodes stopped: {codes}")
    report = day_report(mcap_path, mission.scenario)
    report["wall_seconds"] = time.monotonic() - wall
    report["rtf"] = report["sim_seconds"] / report["wall_seconds"]
    return mcap_path, report


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-mission", description=__doc__.splitlines()[0])
    parser.add_argument("mission", help="a mission file (config/missions/NAME.yaml, or a path)")
    parser.add_argument("--out", default="runs", help="directory for the MCAP and the node logs")
    parser.add_argument("--json", help="write the day's report here")
    args = parser.parse_args(argv)
    try:
        mission = mission_config.load(args.mission)
    except (KeyError, ConfigError) as err:
        print(f"att-mission: {err.args[0] if isinstance(err, KeyError) else err}", file=sys.stderr)
        return 2
    mcap_path, report = fly_mission(mission, Path(args.out))
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
