"""Controller node: magnetorquer PD law, plan tracking with reaction wheels, safe mode.

Subscribes ``/spacecraft/state`` and the latched ``/planner/plans``; publishes
``/actuator/command`` and ``/controller/status`` at ``control_rate`` (Hz of sim time): a command is
computed when a state at or after the next control instant arrives, and stamped with that state's
time (the simulator's lockstep waits for it); serves
``/controller/set_mode`` and the ``/controller/execute`` action (ExecuteManeuver), which runs for
the maneuver's duration plus ``settle_time`` and reports progress as feedback.

Watchdog: when no state came for ``wall_timeout`` s of wall time the controller commands zero
and reports ``state_stale`` until states flow again.
"""
from __future__ import annotations

import time

import numpy as np
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.task import Future

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import ActuatorCommand, ControllerStatus, ManeuverPlan, SpacecraftState
from att_msgs.srv import SetControllerMode
from att_msgs_py import convert, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.node_runner import run_node
from att_planner import tracking
from att_planner.cones import min_margin
from att_planner.magnetorquer_law import dipole_command
from att_sim import rotations as rot
from att_sim import scenario as scen
from att_sim.simulation import MODE_IDLE, MODE_MAGNETORQUER_PD, MODE_PLAN_TRACKING, MODE_SAFE, MODES

MAX_CACHED_PLANS = 50


class ControllerNode(Node):
    def __init__(self):
        super().__init__("controller", parameter_overrides=[Parameter("use_sim_time", value=True)])
        self.scenario = scen.load(self.declare_parameter("scenario", "swift_demo").value)
        self.sc = self.scenario.spacecraft
        p = self.scenario.node_params.get("controller", {})

        def param(key, default):
            return self.declare_parameter(key, p.get(key, default)).value

        self.control_period = 1.0 / float(param("control_rate", 10.0))
        self.feedback_every = max(1, round(0.5 / self.control_period))   # feedback every 0.5 s of sim time
        self.next_control = -np.inf
        self.wall_timeout = float(param("wall_timeout", 2.0))
        self.kp_track, self.kd_track = float(param("tracking_kp", 0.4)), float(param("tracking_kd", 10.0))
        self.settle_time = float(param("settle_time", 20.0))
        self.kp_mag, self.kd_mag = float(param("kp", 2e5)), float(param("kd", 1e8))
        self.m_max = float(param("m_max", self.sc.dipole_max))
        self.safe_kd = float(param("safe_kd", self.kd_track))
        self.mode = int(param("initial_mode", MODE_IDLE))

        self.state = None            # latest state arrays
        self.state_wall = -np.inf    # wall time it arrived
        self.stale = False
        self.plans: dict[str, dict] = {}
        self.active = None           # {"plan":..., "t0":..., "done": Event}
        self.hold_q = None           # final attitude held after a maneuver

        self.cmd_pub = self.create_publisher(ActuatorCommand, topics.COMMAND, topics.STREAM_QOS)
        self.status_pub = self.create_publisher(ControllerStatus, topics.CONTROLLER_STATUS, topics.STREAM_QOS)
        self.create_subscription(SpacecraftState, topics.STATE, self.on_state, topics.STREAM_QOS)
        self.create_subscription(ManeuverPlan, topics.PLANS, self.on_plan, topics.LATCHED_QOS)
        self.create_service(SetControllerMode, topics.SET_CONTROLLER_MODE, self.on_set_mode)
        self.create_timer(0.5, self.on_wall_watchdog, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self.action = ActionServer(self, ExecuteManeuver, topics.EXECUTE_MANEUVER, execute_callback=self.execute,
                                   goal_callback=self.on_goal, cancel_callback=lambda _: CancelResponse.ACCEPT)
        self.get_logger().info(f"scenario '{self.scenario.name}', mode {self.mode}; magnetorquer gains "
                               f"kp={self.kp_mag:.6g} kd={self.kd_mag:.6g} m_max={self.m_max:g}")

    # -- inputs ---------------------------------------------------------------------------------
    def on_state(self, msg: SpacecraftState):
        s = convert.state_arrays(msg)
        if not (np.all(np.isfinite(s["q"])) and np.all(np.isfinite(s["omega"]))):
            self.get_logger().error("non-finite state received; ignored", throttle_duration_sec=1.0)
            return
        self.state, self.state_wall = s, time.monotonic()
        if self.stale:
            self.stale = False
            self.get_logger().info("state is fresh again")
        if s["t"] >= self.next_control - 1e-9:
            self.next_control = s["t"] + self.control_period
            cmd, status = self.control_step()
            self.cmd_pub.publish(cmd)
            self.status_pub.publish(status)

    def on_plan(self, msg: ManeuverPlan):
        self.plans[msg.plan_id] = convert.plan_arrays(msg)
        while len(self.plans) > MAX_CACHED_PLANS:
            self.plans.pop(next(iter(self.plans)))

    def on_set_mode(self, request, response):
        code, message = self.change_mode(int(request.mode))
        response.success, response.error_code, response.message = code == ErrorCode.OK, int(code), message
        return response

    def change_mode(self, mode: int) -> tuple[ErrorCode, str]:
        if mode not in MODES:
            return ErrorCode.INVALID_MODE, f"mode {mode} is not one of {MODES} (ActuatorCommand.MODE_*)"
        if mode == MODE_PLAN_TRACKING:
            return ErrorCode.INVALID_MODE, "plan tracking starts with the execute action, not with set_mode"
        if self.active is not None and mode != MODE_SAFE:
            return ErrorCode.BUSY, (f"maneuver '{self.active['plan']['plan_id']}' is executing: only MODE_SAFE "
                                    "(abort) is accepted until it ends or is cancelled")
        if self.active is not None:
            self.finish_active(False, ErrorCode.ABORTED, "aborted by a switch to safe mode")
        self.mode = mode
        return ErrorCode.OK, f"mode set to {mode}"

    # -- action -----------------------------------------------------------------------------------
    def on_goal(self, goal: ExecuteManeuver.Goal):
        return GoalResponse.REJECT if self.active is not None else GoalResponse.ACCEPT

    def resolve_plan(self, goal) -> tuple[dict | None, ErrorCode, str]:
        if goal.use_inline_plan:
            plan = convert.plan_arrays(goal.plan)
        else:
            plan = self.plans.get(goal.plan_id)
            if plan is None:
                return None, ErrorCode.UNKNOWN_PLAN, f"plan_id '{goal.plan_id}' is not a plan this controller received"
        t, torque = plan["t"], plan["torque"]
        if len(t) < 2 or len(plan["q"]) != len(t) or len(torque) != len(t) or np.any(np.diff(t) <= 0):
            return None, ErrorCode.INVALID_PLAN, "plan times must increase and match attitudes, rates and torques"
        if not all(np.all(np.isfinite(plan[k])) for k in ("t", "q", "omega", "torque")):
            return None, ErrorCode.INVALID_PLAN, "plan contains NaN or Inf"
        if plan["control_kind"] not in ("body_torque", "wheel_torque", ""):
            return None, ErrorCode.INVALID_PLAN, f"control_kind '{plan['control_kind']}' is not supported"
        if plan["status"] == "failed":
            return None, ErrorCode.INVALID_PLAN, "plan status is 'failed'"
        return plan, ErrorCode.OK, ""

    async def execute(self, goal_handle):
        """Start tracking and wait (without blocking the executor) until the control loop ends
        the maneuver; feedback and cancellation are handled by the control loop."""
        result = ExecuteManeuver.Result()
        plan, code, message = self.resolve_plan(goal_handle.request)
        if plan is not None and self.state is None:
            code, message = ErrorCode.NO_STATE, "no spacecraft state received yet"
        if code != ErrorCode.OK:
            goal_handle.abort()
            result.error_code, result.message = int(code), message
            return result
        done = Future(executor=self.executor)
        self.active = {"plan": plan, "t0": self.state["t"], "done": done, "goal": goal_handle, "ticks": 0}
        self.mode = MODE_PLAN_TRACKING
        self.get_logger().info(f"executing plan '{plan['plan_id']}' ({plan['method']}, {plan['duration']:.1f} s)")
        success, code, message, metrics = await done
        result.success, result.error_code, result.message = success, int(code), message
        result.duration, result.final_attitude_error, result.final_rate = metrics
        if goal_handle.is_cancel_requested:
            goal_handle.canceled()
        elif success:
            goal_handle.succeed()
        else:
            goal_handle.abort()
        return result

    def feedback(self, elapsed: float, ref_q: np.ndarray) -> ExecuteManeuver.Feedback:
        """Action feedback for the running maneuver at ``elapsed`` s, reference attitude ``ref_q``."""
        plan, s = self.active["plan"], self.state
        fb = ExecuteManeuver.Feedback()
        fb.elapsed = float(elapsed)
        fb.progress = float(min(1.0, elapsed / max(plan["duration"] + self.settle_time, 1e-9)))
        fb.attitude_error = float(rot.angle_between(s["q"], ref_q))
        fb.min_cone_margin = min_margin(s["q"], plan["sensor_axis"], plan["cones"]) if plan["cones"] else float("inf")
        return fb

    def finish_active(self, success: bool, code: ErrorCode, message: str):
        """Close the running maneuver and hand its result to the waiting action callback."""
        s, plan = self.state, self.active["plan"]
        elapsed = s["t"] - self.active["t0"] if s is not None else 0.0
        err = float(rot.angle_between(s["q"], plan["q"][-1])) if s is not None else float("nan")
        rate = float(np.linalg.norm(s["omega"])) if s is not None else float("nan")
        self.active["done"].set_result((success, code, message, (float(elapsed), err, rate)))
        self.hold_q = plan["q"][-1] if success else None
        self.active = None
        self.mode = MODE_SAFE if code == ErrorCode.ABORTED else self.mode

    # -- control loop -----------------------------------------------------------------------------
    def control_step(self):
        """Command (and status) for the latest state."""
        s = self.state
        cmd = ActuatorCommand(mode=self.mode, wheel_torques=[0.0] * self.sc.n_wheels)
        cmd.header.stamp = convert.time_msg(s["t"])
        cmd.header.frame_id = self.scenario.body_frame_id
        status = ControllerStatus(mode=self.mode, header=cmd.header)
        if self.mode == MODE_MAGNETORQUER_PD:
            m = dipole_command(s["q"], s["omega"], s["field_body"], self.kp_mag, self.kd_mag, self.m_max)
            cmd.dipole = convert.vector3(m)
        elif self.mode == MODE_SAFE:
            tau = -self.safe_kd * s["omega"]
            cmd.wheel_torques = tracking.wheel_torques(self.sc, tau, s["omega"], s["wheel_speeds"]).tolist()
        elif self.mode == MODE_PLAN_TRACKING and self.active is not None:
            plan = self.active["plan"]
            elapsed = s["t"] - self.active["t0"]
            ref = tracking.reference(plan["t"], plan["q"], plan["omega"], plan["torque"], plan["interpolation"], elapsed)
            if plan["control_kind"] == "wheel_torque":
                fb = tracking.tracking_torque(s["q"], s["omega"], tracking.Reference(ref.q, ref.omega, np.zeros(3)),
                                              self.kp_track, self.kd_track)
                u = ref.torque + tracking.wheel_torques(self.sc, fb, s["omega"], np.zeros(self.sc.n_wheels))
                u = np.clip(u, -self.sc.wheel_torque_max, self.sc.wheel_torque_max)
            else:
                tau = tracking.tracking_torque(s["q"], s["omega"], ref, self.kp_track, self.kd_track)
                u = tracking.wheel_torques(self.sc, tau, s["omega"], s["wheel_speeds"])
            cmd.wheel_torques = u.tolist()
            cmd.plan_id = status.plan_id = plan["plan_id"]
            self.active["ticks"] += 1
            if self.active["ticks"] % self.feedback_every == 0:
                self.active["goal"].publish_feedback(self.feedback(elapsed, ref.q))
            if self.active["goal"].is_cancel_requested:
                self.finish_active(False, ErrorCode.ABORTED, "cancelled")
                return cmd, status
            status.plan_progress = float(min(1.0, elapsed / max(plan["duration"], 1e-9)))
            if elapsed >= plan["duration"] + self.settle_time:
                self.finish_active(True, ErrorCode.OK, "maneuver complete")
                status.message = "maneuver complete; holding the final attitude"
        elif self.mode == MODE_PLAN_TRACKING and self.hold_q is not None:
            # after a maneuver: hold the last plan's final attitude
            hold = tracking.Reference(self.hold_q, np.zeros(3), np.zeros(3))
            tau = tracking.tracking_torque(s["q"], s["omega"], hold, self.kp_track, self.kd_track)
            cmd.wheel_torques = tracking.wheel_torques(self.sc, tau, s["omega"], s["wheel_speeds"]).tolist()
            status.message = "holding the final attitude of the last maneuver"
        return cmd, status

    def on_wall_watchdog(self):
        silent = time.monotonic() - self.state_wall > self.wall_timeout
        if silent and not self.stale:
            self.stale = True
            self.get_logger().warning("no state for %.1f s of wall time: commanding zero" % self.wall_timeout)
            cmd = ActuatorCommand(mode=MODE_SAFE, wheel_torques=[0.0] * self.sc.n_wheels)
            self.cmd_pub.publish(cmd)
            self.status_pub.publish(ControllerStatus(mode=self.mode, state_stale=True, message="no state (wall clock)"))


def main(args=None):
    run_node(ControllerNode, args)


if __name__ == "__main__":
    main()
