"""Planner node: serves ``/planner/plan_maneuver`` (PlanManeuver) and publishes every returned
plan on the latched ``/planner/plans`` for the controller and the recorder.

Callbacks only translate: message -> :class:`ManeuverRequest` -> :func:`validate_maneuver` ->
:func:`plan_maneuver` -> message. Requests run concurrently (reentrant callback group on a
multi-threaded executor), so a long solve never blocks a quick request; each request builds its
own problem, nothing is shared between requests but the read-only method registry.
"""
from __future__ import annotations

import math
import time
import uuid

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from att_msgs.msg import ManeuverPlan
from att_msgs.srv import PlanManeuver, PlanSchedule
from att_msgs_py import convert, topics
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.node_runner import run_node
from att_planner import methods as method_registry
from att_planner.planner import (Tolerances, plan_maneuver, run_method, schedule_plan, schedule_verification,
                                 verify_reserve)
from att_planner.requests import ManeuverRequest, validate_maneuver, validate_schedule
from att_planner.schedule import plan_schedule
from att_planner.worker import call_isolated, run_isolated, set_max_parallel, warm_up
from att_sim import scenario as scen


class PlannerNode(Node):
    def __init__(self):
        super().__init__("planner")
        self.scenario_name = self.declare_parameter("scenario", "swift_demo").value
        scenario = scen.load(self.scenario_name)
        p = scenario.node_params.get("planner", {})

        def param(key, default):
            return self.declare_parameter(key, p.get(key, default)).value

        self.frame_id = scenario.frame_id
        self.methods = method_registry.available()
        self.default_method = param("default_method", "") or next(iter(self.methods))
        self.default_budget = float(param("time_budget", 20.0))
        self.tolerances = Tolerances(attitude=math.radians(float(param("accept_attitude_error_deg", 1.0))),
                                     rate=float(param("accept_final_rate", 1e-3)),
                                     cone_margin=math.radians(float(param("accept_cone_penetration_deg", 0.1))))
        self.cone_padding = math.radians(float(param("cone_padding_deg", 1.0)))
        set_max_parallel(int(param("max_parallel_solves", 2)))
        warm_up()
        group = ReentrantCallbackGroup()
        self.plan_pub = self.create_publisher(ManeuverPlan, topics.PLANS, topics.LATCHED_QOS)
        self.schedule_rate_max = float(param("schedule_rate_max", float("inf")))
        self.create_service(PlanManeuver, topics.PLAN_MANEUVER, self.on_plan_maneuver, qos_profile=topics.SERVICE_QOS,
                            callback_group=group)
        self.create_service(PlanSchedule, topics.PLAN_SCHEDULE, self.on_plan_schedule, qos_profile=topics.SERVICE_QOS,
                            callback_group=group)
        self.get_logger().info(f"methods: {', '.join(self.methods)} (default {self.default_method})")

    def on_plan_maneuver(self, request: PlanManeuver.Request, response: PlanManeuver.Response):
        try:
            valid = validate_maneuver(
                ManeuverRequest(
                    frame_id=request.header.frame_id,
                    q_initial=convert.from_quaternion(request.initial_attitude),
                    q_final=convert.from_quaternion(request.final_attitude),
                    sensor_axis=convert.from_vector3(request.sensor_axis),
                    cones=[convert.cone_parts(c) for c in request.cones],
                    method=request.method, time_budget=request.time_budget, spacecraft=request.spacecraft,
                    option_names=list(request.option_names), option_values=list(request.option_values),
                    semi_free=request.semi_free, sensor_target=convert.from_vector3(request.sensor_target)),
                frame_id=self.frame_id, default_spacecraft=self.scenario_name,
                default_method=self.default_method, default_budget=self.default_budget, methods=self.methods)
        except RequestError as err:
            self.get_logger().warning(f"request rejected [{int(err.code)} {err.code.name}]: {err.message}")
            response.success, response.error_code, response.message = False, int(err.code), err.message
            return response
        runner = run_method if valid.method.cheap else run_isolated
        outcome = plan_maneuver(valid, self.tolerances, self.cone_padding, runner)
        response.success = outcome.code == ErrorCode.OK
        response.error_code, response.message = int(outcome.code), outcome.message
        if outcome.plan is not None and len(outcome.plan.t) >= 2:
            response.plan = convert.plan_msg(
                outcome.plan, plan_id=uuid.uuid4().hex[:12], frame_id=self.frame_id, spacecraft=valid.spacecraft,
                sensor_axis=valid.problem.sensor_axis, cones=valid.problem.cones, verification=outcome.verification)
            response.plan.header.stamp = self.get_clock().now().to_msg()
        if response.success:
            self.get_logger().info(f"{valid.method.name}: {outcome.message}")
            self.plan_pub.publish(response.plan)
        else:
            self.get_logger().warning(f"{valid.method.name} failed (code {response.error_code}): {outcome.message}")
        return response

    def on_plan_schedule(self, request: PlanSchedule.Request, response: PlanSchedule.Response):
        try:
            valid = validate_schedule(
                list(request.target_names), [convert.from_quaternion(q) for q in request.targets],
                convert.from_quaternion(request.start_attitude),
                None if request.return_to_start else convert.from_quaternion(request.end_attitude),
                request.spacecraft, request.time_budget,
                frame_id=self.frame_id, request_frame=request.header.frame_id,
                default_spacecraft=self.scenario_name, default_budget=self.default_budget)
        except RequestError as err:
            self.get_logger().warning(f"schedule rejected [{int(err.code)} {err.code.name}]: {err.message}")
            response.success, response.error_code, response.message = False, int(err.code), err.message
            return response
        wait = max(0.0, valid.time_budget - verify_reserve(valid.time_budget))
        result = call_isolated(plan_schedule, (valid.targets, valid.spacecraft),
                               {"q_start": valid.q_start, "q_end": valid.q_end, "rate_max": self.schedule_rate_max,
                                "deadline": time.monotonic() + wait}, wait, on_death=lambda message: message)
        if result is None or isinstance(result, str):
            response.error_code = int(ErrorCode.SOLVER_FAILED)
            response.message = result or f"time budget of {valid.time_budget:g} s expired without a schedule"
        elif not (result.success or result.status == "budget_expired") or result.verification is None \
                or not result.verification.passed:
            response.error_code = int(ErrorCode.VERIFICATION_FAILED if result.verification else ErrorCode.SOLVER_FAILED)
            response.message = f"no verified schedule: {result.message}"
        else:
            response.success, response.message = True, result.message
            response.order = list(result.order)
            response.passage_times = [float(v) for v in result.passage_times]
            response.plan = convert.plan_msg(
                schedule_plan(result), plan_id=uuid.uuid4().hex[:12], frame_id=self.frame_id,
                spacecraft=valid.spacecraft_name, sensor_axis=(1.0, 0.0, 0.0), cones=[],
                verification=schedule_verification(result), control_kind="wheel_torque")
            response.plan.header.stamp = self.get_clock().now().to_msg()
            self.plan_pub.publish(response.plan)
        if response.success:
            self.get_logger().info(f"schedule of {len(valid.targets)} targets: {response.message}")
        else:
            self.get_logger().warning(f"schedule of {len(valid.targets)} targets failed: {response.message}")
        return response


def main(args=None):
    # waiting requests hold a thread, not a core: many threads so quick requests never queue
    run_node(PlannerNode, args, make_executor=lambda: MultiThreadedExecutor(num_threads=16))


if __name__ == "__main__":
    main()
