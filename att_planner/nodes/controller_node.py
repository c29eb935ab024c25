"""Controller node: a thin ROS adapter around :class:`att_planner.control.controller.Controller`.

Subscribes ``/spacecraft/state`` and the latched ``/planner/plans``; publishes
``/actuator/command`` and ``/controller/status`` at ``control_rate`` (Hz of sim time): a command is
computed when a state at or after the next control instant arrives, and stamped with that state's
time (the simulator's lockstep waits for it); serves ``/controller/set_mode`` and the
``/controller/execute`` action (ExecuteManeuver), which runs for the maneuver's duration plus
``settle_time`` and reports progress as feedback.

Watchdog: when no state came for ``wall_timeout`` s of wall time the controller commands zero
and reports ``state_stale`` until states flow again.
"""
from __future__ import annotations

import math
import time

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.task import Future

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import ActuatorCommand, ControllerStatus, ManeuverPlan, SpacecraftState
from att_msgs.srv import SetControllerMode
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.node_runner import parameter_reader, run_node
from att_msgs_py.types import ControlMode, ManeuverResult
from att_planner.control.controller import Controller, ControllerConfig
from att_sim import scenario as scen


class ControllerNode(Node):
    def __init__(self):
        super().__init__("controller", parameter_overrides=[Parameter("use_sim_time", value=True)])
        self._scenario = scen.load(self.declare_parameter("scenario", "swift_demo").value)
        sc = self._scenario.spacecraft
        param = parameter_reader(self, self._scenario.node_params.get("controller", {}))
        d = ControllerConfig()
        tracking_kd = float(param("tracking_kd", d.tracking_kd))
        config = ControllerConfig(
            control_period=1.0 / float(param("control_rate", 1.0 / d.control_period)),
            settle_time=float(param("settle_time", d.settle_time)),
            tracking_kp=float(param("tracking_kp", d.tracking_kp)), tracking_kd=tracking_kd,
            kp=float(param("kp", d.kp)), kd=float(param("kd", d.kd)), m_max=float(param("m_max", sc.dipole_max)),
            safe_kd=float(param("safe_kd", tracking_kd)))
        self._core = Controller(sc, config, int(param("initial_mode", ControlMode.IDLE)),
                                self._scenario.body_frame_id)
        self._wall_timeout = float(param("wall_timeout", 2.0))
        self._state_wall = -math.inf     # wall time the latest state arrived
        self._stale = False
        self._goal = None                # the goal handle of the running maneuver
        self._done: Future | None = None

        self._cmd_pub = self.create_publisher(ActuatorCommand, topics.COMMAND, qos.STREAM_QOS)
        self._status_pub = self.create_publisher(ControllerStatus, topics.CONTROLLER_STATUS, qos.STREAM_QOS)
        self.create_subscription(SpacecraftState, topics.STATE, self.on_state, qos.STREAM_QOS)
        self.create_subscription(ManeuverPlan, topics.PLANS, self.on_plan, qos.LATCHED_QOS)
        self.create_service(SetControllerMode, topics.SET_CONTROLLER_MODE, self.on_set_mode)
        self.create_timer(0.5, self.on_wall_watchdog, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._action = ActionServer(self, ExecuteManeuver, topics.EXECUTE_MANEUVER, execute_callback=self.execute,
                                    goal_callback=self.on_goal, cancel_callback=lambda _: CancelResponse.ACCEPT)
        self.get_logger().info(f"scenario '{self._scenario.name}', mode {self._core.mode}; magnetorquer gains "
                               f"kp={config.kp:.6g} kd={config.kd:.6g} m_max={self._core.m_max:g}")

    # -- inputs ---------------------------------------------------------------------------------
    def on_state(self, msg: SpacecraftState):
        error = self._core.accept_state(convert.state_from_msg(msg))
        if error:
            self.get_logger().error(error, throttle_duration_sec=1.0)
            return
        self._state_wall = time.monotonic()
        if self._stale:
            self._stale = False
            self.get_logger().info("state is fresh again")
        if self._core.due():
            out = self._core.step(cancel_requested=self._goal is not None and self._goal.is_cancel_requested)
            self._cmd_pub.publish(convert.command_msg(out.command))
            self._status_pub.publish(convert.controller_status_msg(out.status))
            if out.feedback is not None and self._goal is not None:
                self._goal.publish_feedback(convert.feedback_msg(out.feedback))
            if out.result is not None:
                self.finish(out.result)

    def on_plan(self, msg: ManeuverPlan):
        self._core.receive_plan(convert.plan_from_msg(msg))

    def on_set_mode(self, request, response):
        code, message, ended = self._core.set_mode(int(request.mode))
        if ended is not None:
            self.finish(ended)
        response.success, response.error_code, response.message = code == ErrorCode.OK, int(code), message
        return response

    # -- action -----------------------------------------------------------------------------------
    def on_goal(self, goal: ExecuteManeuver.Goal):
        return GoalResponse.REJECT if self._core.maneuver is not None else GoalResponse.ACCEPT

    async def execute(self, goal_handle):
        """Start tracking and wait (without blocking the executor) until the control loop ends
        the maneuver; feedback and cancellation are handled by the control loop."""
        goal = goal_handle.request
        inline = convert.plan_from_msg(goal.plan) if goal.use_inline_plan else None
        plan, code, message = self._core.resolve(goal.plan_id, inline)
        if plan is not None:
            code, message = self._core.start(plan)
        if code != ErrorCode.OK:
            goal_handle.abort()
            return convert.result_msg(ManeuverResult(False, int(code), message))
        self._goal, self._done = goal_handle, Future(executor=self.executor)
        self.get_logger().info(f"executing plan '{plan.plan_id}' ({plan.method}, {plan.duration:.1f} s)")
        result = await self._done
        if goal_handle.is_cancel_requested:
            goal_handle.canceled()
        elif result.success:
            goal_handle.succeed()
        else:
            goal_handle.abort()
        return convert.result_msg(result)

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
    run_node(ControllerNode, args)


if __name__ == "__main__":
    main()
