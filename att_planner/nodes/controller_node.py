"""Controller node: a thin ROS adapter around :class:`att_planner.control.controller.Controller`.

Subscribes ``/spacecraft/state`` and the latched ``/planner/plans``; publishes
``/actuator/command`` and ``/controller/status`` at ``control_rate_Hz`` (sim time): a command is
computed when a state at or after the next control instant arrives, and stamped with that state's
time (the simulator waits for it before it advances); serves ``/controller/set_mode`` and the
``/controller/execute`` action (ExecuteManeuver), which runs for the maneuver's duration plus
``settle_time_s`` and reports progress as feedback (the zone margins of the feedback are taken
on the scenario's sky: its epoch and orbit). The planner publishes a plan before it answers, but DDS
does not order a topic before an action: a goal naming a plan not heard yet waits up to
``plan_wait_s`` of wall time for it (then UNKNOWN_PLAN), so a client sends each goal once.

Nothing received is trusted (the size caps of :mod:`att_msgs_py.limits`, checked before a message is
read, SIZE_LIMIT; the core's checks, :mod:`att_planner.control.plan_checks` and
:mod:`att_planner.control.state_gate`): a refused state or plan is logged (at most once a second
per kind, clipped, with a running count) and changes nothing. Plans must verify against the
Ed25519 public key ``plan_public_key`` (:mod:`att_msgs_py.signing`); with ``require_signed_modes``
mode requests must verify against ``mode_public_key`` and carry an increasing sequence number
(the signer's wall clock in ns, at most ``mode_sequence_ahead_s`` s ahead of the controller's), the
last accepted one kept in ``mode_sequence_file`` (:mod:`att_planner.control.mode_authentication`).

Sim time comes from the states' stamps. ``/clock`` is read by the node itself, not through
rclpy's ``use_sim_time`` (whose time source raises on a negative stamp, so one hostile message
would kill the node): the latest clock of each participant is kept, and a state is compared with
the clock of its own participant only (the state gate's skew check).

The states (or estimates) are held to one publisher: another one is ignored while the held one is
in the ROS graph (:class:`att_msgs_py.source_hold.SourceHold`), so neither pausing nor starving the
real source hands the loop to an intruder; a silent source is stale input (the watchdog below).

Faults: with ``fault_table`` (a name of ``config/faults`` or a file's path; empty, the default: off;
it needs ``state_source`` estimate) the node runs the table's monitor on what it has
(:class:`att_planner.fdir.onboard.Onboard`: the wheel speeds against its commands, the estimates, its
attitude error), hears the estimator's reports on ``/estimator/faults`` (held to one publisher;
refused, 322, unless the table declares them as reported), publishes its own on the latched
``/controller/faults`` (att_msgs/FaultStatus), names the active faults in the status message and acts
on the responses of both (:func:`att_planner.fdir.recovery.act`: the allocation on the healthy wheels,
safe mode). A wheel isolated during a maneuver: it brakes (:class:`att_planner.fdir.replan.Brake`),
asks ``/planner/plan_maneuver`` for the rest on the healthy wheels (``healthy_wheels``) and flies it;
the execute goal ends with the re-planned maneuver, or unsuccessfully with why (then safe mode).

Watchdog: when no state came for ``wall_timeout_s`` of wall time the controller commands zero
and reports ``state_stale`` until states flow again.

``state_source``: ``truth`` flies on ``/spacecraft/state``; ``estimate`` (the default of a
scenario with a gyro) flies on ``/estimator/attitude`` with the wheel speeds of
``/sensors/wheel_speeds`` and the field of ``/sensors/magnetometer``
(:class:`att_planner.control.measured_state.MeasuredState`), compensating the wheel drives' expected
friction (``friction_compensation``, default on when the scenario's ``actuators.wheels`` has some).
In that mode the state gate's clock check is left out (the estimates come from the estimator, the
clock from the simulator).
"""
from __future__ import annotations

import time
from datetime import timedelta

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.clock import Clock, ClockType
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.task import Future
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import JointState, MagneticField

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import (
    ActuatorCommand,
    AttitudeEstimate,
    ControllerStatus,
    FaultStatus,
    ManeuverPlan,
    SpacecraftState,
)
from att_msgs.srv import PlanManeuver, SetControllerMode
from att_msgs_py import convert, limits, memory, qos, signing, topics
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.node_runner import (
    ParameterReader,
    RefusalLog,
    live_publishers,
    participant_of,
    publisher_of,
    read_scenario,
    run_node,
    subscribe_when_heard,
)
from att_msgs_py.suite_node import SuiteNode
from att_msgs_py.types import ControlKind, ControlMode, ManeuverResult
from att_planner import methods
from att_planner.control.controller_from_scenario import controller_from_scenario, public_key
from att_planner.control.controller_parameters import CONTROLLER
from att_planner.control.mode_authentication import ModeAuthentication, default_sequence_path
from att_planner.control.plan_checks import check_message
from att_planner.estimation.inputs import Sources
from att_planner.fdir.onboard import Onboard, load_table
from att_planner.fdir.replan import REPLAN, SAFE, Brake
from att_planner.nodes.client import maneuver_request
from att_sim.models import scenario as scen

MAX_WAITING_GOALS = 8     # execute goals waiting for their plans at once; a goal beyond them is refused at once


class ControllerNode(SuiteNode):
    def __init__(self):
        super().__init__("controller")
        self._scenario = scen.load_checked(read_scenario(self))
        param = ParameterReader(self, CONTROLLER, self._scenario.node_params.get("controller", {}),
                                str(self._scenario.node_params_path))
        self._core = controller_from_scenario(param, self._scenario)
        self._core.gate.hold.live = live_publishers(self, topics.STATE if self._core.measured is None
                                                    else topics.ESTIMATE)
        self._wall_timeout = param("wall_timeout_s")
        self._plan_wait = param("plan_wait_s")
        wait_for_subscribers = param("wait_for_subscribers")
        start_timeout = param("start_timeout_s")
        signed = param("require_signed_modes")
        mode_key = public_key(param, "mode_public_key", load=signed)
        sequences = param("mode_sequence_file", str(default_sequence_path()))
        ahead = param("mode_sequence_ahead_s")
        if signed:
            self._core.authentication = ModeAuthentication(mode_key, sequences, ahead)
        fault_table = load_table(param("fault_table"))
        param.refuse_unknown()
        if fault_table is not None and self._core.measured is None:
            raise ConfigError(ErrorCode.INVALID_PARAMETER, "parameter 'fault_table': expected state_source estimate "
                                                           "(the monitor watches the measured wheel speeds and the "
                                                           "estimate); found state_source truth")
        if self._core.authentication.warning:
            self.get_logger().warning(self._core.authentication.warning)
        self._state_wall = time.monotonic()   # no "no state" warning before wall_timeout_s has passed
        self._stale = False
        self._refusals = RefusalLog(self.get_logger())   # refused inputs, logged once a second per kind
        self._goal = None                     # the goal handle of the running maneuver
        self._awaiting: list[tuple[str, object, Future]] = []   # (plan id, goal handle, heard): goals waiting
        self._waiting = None                  # (estimate, source) that came before any wheel speed
        self._sources = Sources({"wheel speed measurement": live_publishers(self, topics.WHEEL_SPEEDS),
                                 "magnetometer measurement": live_publishers(self, topics.MAGNETOMETER)})
        self._done: Future | None = None
        self._fdir = None if fault_table is None else Onboard(fault_table, self._scenario, self._core)
        self._brake = Brake()                 # the brake before a re-plan after a wheel loss
        self._replan_of = None                # the plan of the maneuver being re-planned (None: none)
        self._replanning: Future | None = None   # the planner's answer awaited

        self._cmd_pub = self.create_publisher(ActuatorCommand, topics.COMMAND, qos.STREAM_QOS)
        self._status_pub = self.create_publisher(ControllerStatus, topics.CONTROLLER_STATUS, qos.STREAM_QOS)
        subscribe_when_heard(self, self._cmd_pub, wait_for_subscribers, start_timeout, self._subscribe_state)
        self.create_subscription(ManeuverPlan, topics.PLANS, self.on_plan, qos.LATCHED_QOS)
        self.create_subscription(ClockMsg, topics.CLOCK, self.on_clock, qos.CLOCK_QOS)
        self.create_service(SetControllerMode, topics.SET_CONTROLLER_MODE, self.on_set_mode)
        if self._fdir is not None:
            self._fault_pub = self.create_publisher(FaultStatus, topics.CONTROLLER_FAULTS, qos.MISSION_QOS)
            self._planner = self.create_client(PlanManeuver, topics.PLAN_MANEUVER, qos_profile=qos.SERVICE_QOS)
            self._fault_sources = Sources({"estimator fault report": live_publishers(self, topics.ESTIMATOR_FAULTS)})
            self.create_subscription(FaultStatus, topics.ESTIMATOR_FAULTS, self.on_estimator_fault, qos.MISSION_QOS)
        self.create_timer(0.5, self.on_wall_watchdog, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._action = ActionServer(self, ExecuteManeuver, topics.EXECUTE_MANEUVER, execute_callback=self.execute,
                                    goal_callback=self.on_goal, cancel_callback=self.on_cancel)
        c = self._core.config
        source = "truth" if self._core.measured is None else "estimate"
        self.get_logger().info(f"scenario '{self._scenario.name}', state from the {source}, mode {self._core.mode}, "
                               f"friction compensation {'on' if self._core.friction else 'off'}, fault table "
                               f"{'off' if self._fdir is None else 'on'}, plan key "
                               f"{signing.key_id(self._core.context.public_key)}; magnetorquer gains "
                               f"kp={c.kp:.6g} kd={c.kd:.6g} m_max={self._core.m_max:g}")

    # -- inputs ---------------------------------------------------------------------------------
    def _subscribe_state(self) -> None:
        """The state (truth), or the estimate with the wheel speeds and the magnetometer."""
        if self._core.measured is None:
            self.create_subscription(SpacecraftState, topics.STATE, self.on_state, qos.STREAM_QOS)
        else:
            self.create_subscription(AttitudeEstimate, topics.ESTIMATE, self.on_estimate, qos.STREAM_QOS)
            self.create_subscription(JointState, topics.WHEEL_SPEEDS, self.on_wheel_speeds, qos.STREAM_QOS)
            self.create_subscription(MagneticField, topics.MAGNETOMETER, self.on_magnetometer, qos.STREAM_QOS)

    # (``info`` has no default: rclpy passes the message info only to two-argument callbacks)
    def on_clock(self, msg: ClockMsg, info: dict):
        if msg.clock.sec >= 0 and msg.clock.nanosec < 1_000_000_000:
            self._core.gate.clocks.hear(participant_of(publisher_of(info)), convert.from_time(msg.clock))

    def on_state(self, msg: SpacecraftState, info: dict):
        if (oversized := limits.issue(msg, limits.SPACECRAFT_STATE, "state")) is not None:
            return self._refusals("state", oversized)
        source = publisher_of(info)
        clock = self._core.gate.clocks.of(participant_of(source))
        self._step(self._core.accept_state(convert.state_from_msg(msg), time.monotonic(), clock, source), "state")

    def on_estimate(self, msg: AttitudeEstimate, info: dict):
        if (oversized := limits.issue(msg, limits.ATTITUDE_ESTIMATE, "estimate")) is not None:
            return self._refusals("attitude estimate", oversized)
        estimate, source = convert.estimate_from_msg(msg), publisher_of(info)
        outcome = self._core.accept_estimate(estimate, time.monotonic(), source)
        if outcome.refused is not None and outcome.refused.code == ErrorCode.NO_STATE:
            self._waiting = (estimate, source)   # the first wheel speeds are on their way: answer then
            return
        self._step(outcome, "attitude estimate", estimate)

    def on_wheel_speeds(self, msg: JointState, info: dict):
        try:
            limits.check(msg, limits.JOINT_STATE, "wheel_speeds")
            speeds = convert.wheel_speeds_from_msg(msg)
            self._sources.guarded("wheel speed measurement", publisher_of(info), self._core.measured.on_wheel_speeds,
                                  speeds)
        except RequestError as err:
            self._refusals("wheel speed measurement", err)
            return
        self._watch(topics.WHEEL_SPEEDS, speeds.t, speeds)
        if self._waiting is not None:
            (estimate, source), self._waiting = self._waiting, None
            self._step(self._core.accept_estimate(estimate, time.monotonic(), source), "attitude estimate", estimate)

    def on_magnetometer(self, msg: MagneticField, info: dict):
        try:
            limits.check(msg, limits.HEADER_ONLY, "magnetometer")
            self._sources.guarded("magnetometer measurement", publisher_of(info), self._core.measured.on_magnetometer,
                                  convert.magnetometer_from_msg(msg))
        except RequestError as err:
            self._refusals("magnetometer measurement", err)

    def _step(self, outcome, what: str, estimate=None) -> None:
        """After a state or estimate: report, act on the fault monitor, and command when a control instant
        is due."""
        if outcome.refused is not None:
            self._refusals(what, outcome.refused)
            return
        if estimate is not None:
            self._watch(topics.ESTIMATE, estimate.t, estimate)
        if outcome.note:
            self.get_logger().warning(outcome.note)
        if outcome.ended is not None:
            self.finish(outcome.ended)
        self._state_wall = time.monotonic()
        if self._stale:
            self._stale = False
            self.get_logger().info("state is fresh again")
        if self._fdir is not None:
            self._respond()
        if self._core.due():
            out = self._core.step(cancel_requested=self._goal is not None and self._goal.is_cancel_requested)
            if self._fdir is not None:
                self._watch(topics.COMMAND, out.command.t, out.command)
                self._watch(topics.CONTROLLER_STATUS, out.status.t, out.status)
                out.status.message = self._with_faults(out.status.message)
            self._cmd_pub.publish(convert.command_msg(out.command))
            self._status_pub.publish(convert.controller_status_msg(out.status))
            if out.feedback is not None and self._goal is not None:
                self._to_client("feedback", self._goal.publish_feedback, convert.feedback_msg(out.feedback))
            if out.result is not None:
                self.finish(out.result)

    # -- faults ---------------------------------------------------------------------------------------
    def _watch(self, topic: str, t: float, message) -> None:
        """Feed the fault monitor (when configured) and publish what it reported."""
        if self._fdir is None:
            return
        for report in self._fdir.feed(topic, t, message):
            self._fault_pub.publish(convert.fault_status_msg(report))
            log = self.get_logger().warning if report.active else self.get_logger().info
            log(clip(f"fault {report.fault_id} on {report.component} {report.index} "
                     f"{'declared' if report.active else 'cleared'} at t = {report.t:.2f} s ({report.detector}: "
                     f"{report.evidence}); response {report.response}"))

    def on_estimator_fault(self, msg: FaultStatus, info: dict):
        """A report of the estimator's monitor: its responses are acted on with this monitor's (held to one
        publisher; a fault the table does not declare as reported is refused, 322)."""
        try:
            limits.check(msg, limits.FAULT_STATUS, "fault")
            report = convert.fault_status_from_msg(msg)
            refused = self._fault_sources.guarded("estimator fault report", publisher_of(info), self._fdir.hear,
                                                  report)
        except RequestError as err:
            refused = err
        if refused is not None:
            self._refusals("estimator fault report", refused)
            return
        self.get_logger().info(clip(f"estimator fault {report.fault_id} on {report.component} {report.index} "
                                    f"{'declared' if report.active else 'cleared'} ({report.response})"))

    def _with_faults(self, message: str) -> str:
        """The status message with the active faults named (the fault topic has their reports)."""
        active = sorted(f"{f.fault_id}[{f.index}]" for f in [*self._fdir.monitor.active.values(),
                                                             *self._fdir.heard.values()])
        return clip(f"{message}; faults: {', '.join(active)}" if active and message else
                    f"faults: {', '.join(active)}" if active else message)

    def _respond(self) -> None:
        """Act on the monitor's responses (:meth:`Onboard.respond`); after a wheel isolated mid-maneuver,
        brake, then ask the planner for the rest on the healthy wheels (:mod:`att_planner.fdir.replan`):
        the execute goal in flight ends with the re-planned maneuver."""
        ended, changed = self._fdir.respond()
        if ended is not None:                      # safe mode aborted the maneuver
            self._replan_of, self._brake.since = None, None
            self.finish(ended)
        core, t = self._core, self._core.state.t
        if changed and (core.maneuver is not None or self._replan_of is not None):
            self._replan_of = core.maneuver.plan if core.maneuver is not None else self._replan_of
            self._brake.begin(core, t)
            self.get_logger().warning(f"healthy wheels {list(core.healthy or ())}: braking at t = {t:.2f} s to "
                                      f"re-plan maneuver '{self._replan_of.plan_id}'")
        if self._replan_of is not None and (core.mode == ControlMode.SAFE or self._goal is not None
                                            and self._goal.is_cancel_requested):
            why = "safe mode" if core.mode == ControlMode.SAFE else "cancelled"
            self._replan_of = self._brake.since = None
            self.finish(ManeuverResult(False, int(ErrorCode.ABORTED), f"{why} while re-planning"))
            return
        said = self._brake.poll(core, t)
        if said == SAFE:
            self._give_up(self._brake.why)
        elif said == REPLAN and self._replanning is None:
            self._request_replan()

    def _request_replan(self) -> None:
        """Ask the planner for the rest of the interrupted maneuver, from the estimate at rest to its
        goal among its cones and zones, for the healthy wheels' envelope (``healthy_wheels``)."""
        plan, state = self._replan_of, self._core.state
        epoch = None if self._scenario.epoch is None else self._scenario.epoch + timedelta(seconds=state.t)
        try:
            request = maneuver_request(state.q, plan.q[-1], plan.sensor_axis, plan.cones,
                                       method=plan.method if plan.method in methods.METHODS else "",
                                       frame_id=self._scenario.frame_id, epoch=epoch, zones=plan.zones)
        except ValueError as err:
            return self._give_up(f"no re-plan request: {err}")
        request.healthy_wheels = [bool(h) for h in (self._core.healthy or ())]
        if not self._planner.service_is_ready():
            return self._give_up(f"no re-plan: the planner service {topics.PLAN_MANEUVER} is not available")
        self.get_logger().info(f"re-planning from t = {state.t:.2f} s on wheels {list(request.healthy_wheels)}")
        self._replanning = self._planner.call_async(request)
        self._replanning.add_done_callback(self._on_replan)

    def _on_replan(self, future) -> None:
        self._replanning = None
        if self._replan_of is None:               # cancelled or safe mode meanwhile
            return
        try:
            response = future.result()
        except Exception as exc:  # a call the middleware failed: no re-plan, never a dead callback
            response, exc_text = None, f"{type(exc).__name__}: {exc}"
        else:
            exc_text = "no answer"
        if response is None or not response.success:
            why = exc_text if response is None else f"code {response.error_code}: {response.message}"
            return self._give_up(f"no verified re-plan ({why})")
        msg = response.plan
        refused = limits.issue(msg, limits.MANEUVER_PLAN, "plan") or check_message(msg)
        plan = None
        if refused is None:
            plan, refused = self._core.resolve(msg.plan_id, convert.plan_from_msg(msg), signing.payload(msg))
        if refused is None and plan.control_kind == ControlKind.WHEEL_TORQUE:
            refused = RequestError(ErrorCode.INVALID_PLAN, "a re-plan of wheel torques (flown as body torques only)")
        refused = refused or self._core.start(plan)
        if refused is not None:
            return self._give_up(f"the re-plan did not start: code {int(refused.code)}: {refused.message}")
        self._replan_of = None
        self.get_logger().info(f"flying re-plan '{plan.plan_id}' ({plan.method}, {plan.duration:.1f} s)")

    def _give_up(self, why: str) -> None:
        """No re-plan: safe mode; the execute goal in flight ends with why."""
        self._replan_of, self._brake.since = None, None
        self.get_logger().error(clip(f"re-planning after a wheel loss failed: {why}; safe mode"))
        self._core.set_mode(ControlMode.SAFE)
        self.finish(ManeuverResult(False, int(ErrorCode.ABORTED), clip(f"re-planning failed: {why}")))

    def on_plan(self, msg: ManeuverPlan):
        refused = (limits.issue(msg, limits.MANEUVER_PLAN, "plan") or check_message(msg)
                   or self._core.receive_plan(convert.plan_from_msg(msg), signing.payload(msg)))
        if refused is not None:
            self._refusals("published plan", refused)
        else:
            self._wake(lambda plan_id, _: plan_id == msg.plan_id)

    def on_set_mode(self, request, response):
        refused = limits.issue(request, limits.SET_CONTROLLER_MODE) or self._core.authorize_mode(
            signing.payload(request), bytes(request.signature), request.key_id, int(request.sequence))
        if refused is not None:
            self._refusals("mode request", refused)
            response.success, response.error_code, response.message = False, int(refused.code), refused.message
            return response
        dumping = {request.DUMPING_KEEP: None, request.DUMPING_ON: True, request.DUMPING_OFF: False}
        if int(request.dumping) not in dumping:
            code, message, ended = ErrorCode.INVALID_MODE, f"dumping {request.dumping} is not DUMPING_KEEP/ON/OFF", None
        else:
            code, message, ended = self._core.set_mode(int(request.mode), convert.pointing_from_msg(request.pointing),
                                                       dumping[int(request.dumping)])
        if code != ErrorCode.OK:
            self._refusals("mode request", RequestError(code, message))
        else:
            self.get_logger().info(f"mode request accepted: {message}")
        if ended is not None:
            self.finish(ended)
        response.success, response.error_code, response.message = code == ErrorCode.OK, int(code), message
        return response

    # -- action -----------------------------------------------------------------------------------
    def on_goal(self, goal: ExecuteManeuver.Goal):
        busy = self._core.maneuver is not None or self._replan_of is not None
        return GoalResponse.REJECT if busy else GoalResponse.ACCEPT

    def on_cancel(self, goal_handle):
        self._wake(lambda _, handle: handle is goal_handle)   # a goal waiting for its plan ends now, cancelled
        return CancelResponse.ACCEPT

    async def _wait_for_plan(self, plan_id: str, goal_handle) -> None:
        """Return once plan ``plan_id`` was received, the goal was cancelled or ``plan_wait_s`` of
        wall time passed, whichever is first; the executor serves every other callback meanwhile
        (other goals too: a waiting goal does not hold the controller)."""
        heard = Future(executor=self.executor)
        entry = (plan_id, goal_handle, heard)
        self._awaiting.append(entry)
        self.get_logger().info(f"execute goal for plan '{clip(plan_id, 80)}' waits up to {self._plan_wait:g} s "
                               "for the plan")
        timer = self.create_timer(self._plan_wait, lambda: heard.done() or heard.set_result(None),
                                  clock=Clock(clock_type=ClockType.STEADY_TIME))
        try:
            await heard
        finally:
            self.destroy_timer(timer)
            self._awaiting.remove(entry)

    def _wake(self, which) -> None:
        """End the wait of every waiting goal for which ``which(plan_id, goal_handle)`` holds."""
        for plan_id, handle, heard in self._awaiting:
            if which(plan_id, handle) and not heard.done():
                heard.set_result(None)

    async def execute(self, goal_handle):
        """Start tracking and wait (without blocking the executor) until the control loop ends
        the maneuver; feedback and cancellation are handled by the control loop."""
        goal = goal_handle.request
        caps = limits.inline_plan() if goal.use_inline_plan else limits.EXECUTE_MANEUVER
        refused = limits.issue(goal, caps) or (check_message(goal.plan) if goal.use_inline_plan else None)
        plan = None
        if refused is None:
            inline = convert.plan_from_msg(goal.plan) if goal.use_inline_plan else None
            plan, refused = self._core.resolve(goal.plan_id, inline, signing.payload(goal.plan) if inline else b"")
            if (refused is not None and refused.code == ErrorCode.UNKNOWN_PLAN and self._plan_wait > 0
                    and len(self._awaiting) < MAX_WAITING_GOALS):
                await self._wait_for_plan(goal.plan_id, goal_handle)
                if goal_handle.is_cancel_requested:
                    self._to_client("goal status", goal_handle.canceled)
                    return convert.result_msg(ManeuverResult(False, int(ErrorCode.ABORTED),
                                                             "cancelled while waiting for its plan"))
                plan, refused = self._core.resolve(goal.plan_id)
                if refused is not None and refused.code == ErrorCode.UNKNOWN_PLAN:
                    refused = RequestError(refused.code, f"{refused.message} (waited {self._plan_wait:g} s for it)")
                elif self._core.maneuver is not None or self._replan_of is not None:
                    plan, refused = None, RequestError(ErrorCode.BUSY, "another maneuver started while this goal "
                                                                       "waited for its plan")
        goal.plan = ManeuverPlan()       # read or refused: the goal handle, kept until its result expires, drops it
        if plan is not None:
            refused = self._core.start(plan, convert.pointing_from_msg(goal.pointing_after) if goal.point_after
                                       else None)
        if refused is not None:
            self._refusals("execute goal", refused)
            self._to_client("goal status", goal_handle.abort)
            return convert.result_msg(ManeuverResult(False, int(refused.code), refused.message))
        self._goal, self._done = goal_handle, Future(executor=self.executor)
        self.get_logger().info(f"executing plan '{plan.plan_id}' ({plan.method}, {plan.duration:.1f} s)")
        result = await self._done
        end = (goal_handle.canceled if goal_handle.is_cancel_requested else
               goal_handle.succeed if result.success else goal_handle.abort)
        self._to_client("goal status", end)
        return convert.result_msg(result)

    def _to_client(self, what: str, send, *args) -> None:
        """Send the action client ``what`` (a goal's feedback or its terminal status). The goal's
        state changes before the status is published, so a publication the middleware refuses
        loses only that message, never the goal's result: logged, and the node goes on."""
        try:
            send(*args)
        except _rclpy.RCLError as err:
            self.get_logger().warning(f"{what} not published: {err}")

    def finish(self, result: ManeuverResult):
        """Hand the result of the maneuver that ended to the waiting action callback."""
        if self._done is not None:
            self._done.set_result(result)
        self._goal, self._done = None, None

    def on_wall_watchdog(self):
        silent = time.monotonic() - self._state_wall > self._wall_timeout
        if silent and not self._stale:
            self._stale = True
            self.get_logger().warning(f"no state for {self._wall_timeout:.1f} s of wall time: commanding zero")
            command, status = self._core.stale_command()
            self._cmd_pub.publish(convert.command_msg(command))
            self._status_pub.publish(convert.controller_status_msg(status))


def main(args=None):
    memory.reexec_with_c_allocator()
    run_node(ControllerNode, args)


if __name__ == "__main__":
    main()
