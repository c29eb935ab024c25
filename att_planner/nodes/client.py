"""A small rclpy client of the suite (planner service, controller action and mode service).

Used by ``att-demo``, the integration tests and user scripts::

    client = SuiteClient()                       # after rclpy.init()
    client.wait_for_servers(timeout=20)
    response = client.plan(maneuver_request(q0, qf, sensor, cones))
    result = client.execute(response.plan.plan_id)
"""
from __future__ import annotations

import time
from contextlib import contextmanager

import rclpy
from rclpy.action import ActionClient
from rclpy.node import Node

from att_msgs.action import ExecuteManeuver
from att_msgs.srv import PlanManeuver, PlanSchedule, SetControllerMode
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Cone


def maneuver_request(q_initial, q_final, sensor_axis, cones: list[Cone], *, method: str = "",
                     time_budget: float = 0.0, spacecraft: str = "", frame_id: str = "eci",
                     options: dict | None = None) -> PlanManeuver.Request:
    req = PlanManeuver.Request()
    req.header.frame_id = frame_id
    req.initial_attitude = convert.quaternion(q_initial)
    req.final_attitude = convert.quaternion(q_final)
    req.sensor_axis = convert.vector3(sensor_axis)
    req.cones = [convert.cone_msg(c) for c in cones]
    req.method, req.time_budget, req.spacecraft = method, float(time_budget), spacecraft
    req.option_names = list((options or {}).keys())
    req.option_values = [float(v) for v in (options or {}).values()]
    return req


class SuiteClient(Node):
    def __init__(self, name: str = "suite_client"):
        super().__init__(name)
        self.plan_client = self.create_client(PlanManeuver, topics.PLAN_MANEUVER, qos_profile=qos.SERVICE_QOS)
        self.schedule_client = self.create_client(PlanSchedule, topics.PLAN_SCHEDULE, qos_profile=qos.SERVICE_QOS)
        self.mode_client = self.create_client(SetControllerMode, topics.SET_CONTROLLER_MODE)
        self.execute_client = ActionClient(self, ExecuteManeuver, topics.EXECUTE_MANEUVER)

    def wait_for_servers(self, timeout: float = 30.0, schedule: bool = False) -> None:
        deadline = time.monotonic() + timeout
        clients = [self.plan_client, self.mode_client] + ([self.schedule_client] if schedule else [])
        for client in clients:
            if not client.wait_for_service(timeout_sec=max(0.1, deadline - time.monotonic())):
                raise TimeoutError(f"service {client.srv_name} not available after {timeout} s")
        if not self.execute_client.wait_for_server(timeout_sec=max(0.1, deadline - time.monotonic())):
            raise TimeoutError(f"action {topics.EXECUTE_MANEUVER} not available after {timeout} s")

    def _call(self, client, request, timeout: float):
        future = client.call_async(request)
        rclpy.spin_until_future_complete(self, future, timeout_sec=timeout)
        if not future.done():
            raise TimeoutError(f"no answer from {client.srv_name} within {timeout} s")
        return future.result()

    def plan(self, request: PlanManeuver.Request, timeout: float = 120.0) -> PlanManeuver.Response:
        return self._call(self.plan_client, request, timeout)

    def schedule(self, request: PlanSchedule.Request, timeout: float = 300.0) -> PlanSchedule.Response:
        return self._call(self.schedule_client, request, timeout)

    def set_mode(self, mode: int, timeout: float = 10.0) -> SetControllerMode.Response:
        return self._call(self.mode_client, SetControllerMode.Request(mode=mode), timeout)

    def execute(self, plan_id: str = "", plan=None, timeout: float = 600.0, on_feedback=None,
                retries: int = 10) -> ExecuteManeuver.Result:
        """Run a plan on the controller and wait for the result. A plan just published may not have
        reached the controller yet: UNKNOWN_PLAN is retried ``retries`` times, 0.5 s apart."""
        goal = ExecuteManeuver.Goal(plan_id=plan_id, use_inline_plan=plan is not None)
        if plan is not None:
            goal.plan = plan
        for _ in range(retries + 1):
            send = self.execute_client.send_goal_async(goal, feedback_callback=on_feedback)
            rclpy.spin_until_future_complete(self, send, timeout_sec=30.0)
            handle = send.result()
            if handle is None or not handle.accepted:
                raise RuntimeError("the controller rejected the goal (another maneuver is executing)")
            done = handle.get_result_async()
            rclpy.spin_until_future_complete(self, done, timeout_sec=timeout)
            if not done.done():
                raise TimeoutError(f"maneuver not finished within {timeout} s")
            result = done.result().result
            if result.error_code != ErrorCode.UNKNOWN_PLAN:
                return result
            time.sleep(0.5)
        return result



@contextmanager
def client_session(name: str = "suite_client"):
    """``rclpy.init()``, a :class:`SuiteClient`, and a clean shutdown whatever happens."""
    rclpy.init()
    client = SuiteClient(name)
    try:
        yield client
    finally:
        client.destroy_node()
        rclpy.try_shutdown()
