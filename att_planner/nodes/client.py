"""A small rclpy client of the suite (planner service, controller action and mode service).

Used by ``att-demo``, the integration tests and user scripts::

    client = SuiteClient()                       # after rclpy.init()
    client.wait_for_servers(timeout=20)
    response = client.plan(maneuver_request(q0, qf, sensor, cones))   # epoch=, zones=, tle= for the real sky
    result = client.execute(response.plan.plan_id)

Robust to hostile input and to the other side failing: :func:`maneuver_request` refuses a string
with a NUL or another control character, and every call refuses a NUL before sending (ValueError
naming the field; rclpy would silently cut the string at the NUL); a service call survives a
restart of its server (the request is sent again once a new server has appeared, see
:meth:`SuiteClient._call`); an executing goal whose controller falls silent (no feedback for
``stall_timeout`` s of wall time) is cancelled and reported as ABORTED instead of waiting for the
overall timeout.
"""
from __future__ import annotations

import math
import sys
import time
from contextlib import contextmanager
from datetime import datetime

import rclpy
from rclpy.action import ActionClient
from rclpy.duration import Duration
from rclpy.node import Node
from std_srvs.srv import SetBool

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import AttitudeEstimate
from att_msgs.srv import ImageStrip, ImageTarget, PlanManeuver, PlanSchedule, SetControllerMode
from att_msgs_py import convert, qos, signing, topics
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Cone, PointingMode, Zone
from att_msgs_py.validation import text

POLL = 0.05                 # s between checks of a pending call or goal
RESEND_SETTLE = 0.5         # s a new server is given to discover this client before a request is sent again
STALL_TIMEOUT = 15.0        # s of wall time without feedback after which an executing goal is given up
GOAL_ANSWER_TIMEOUT = 30.0  # s for the controller to accept or reject a goal
_NO_STRINGS = ("geometry_msgs/", "builtin_interfaces/", "float", "double", "int", "uint", "bool", "octet", "byte")


def check_strings(msg, name: str = "", nul_only: bool = False) -> None:
    """Every string of ``msg`` (nested messages and sequences too) is free of NUL and other control
    characters (only of NUL with ``nul_only``), or ValueError naming the field (``header.frame_id``,
    ``cones[2].name``)."""
    def check(value: str, label: str) -> None:
        if not nul_only:
            text(value, label, max_length=sys.maxsize)
        elif "\0" in value:
            raise RequestError(ErrorCode.INVALID_TEXT, f"{label} contains a NUL character at position "
                                                       f"{value.index(chr(0))} (it would be cut there unseen)")

    for field, kind in msg.get_fields_and_field_types().items():
        label = f"{name}.{field}" if name else field
        value = getattr(msg, field)
        if isinstance(value, str):
            check(value, label)
        elif hasattr(value, "get_fields_and_field_types"):
            check_strings(value, label, nul_only)
        elif kind.startswith("sequence<") and not kind[len("sequence<"):].startswith(_NO_STRINGS):
            for i, item in enumerate(value):
                if isinstance(item, str):
                    check(item, f"{label}[{i}]")
                else:
                    check_strings(item, f"{label}[{i}]", nul_only)


def strip_request(q_initial, strip: PointingMode, *, method: str = "", time_budget: float = 0.0,
                  frame_id: str = "eci", epoch: datetime | None = None, zones: list[Zone] = (),
                  wheel_speeds=()) -> ImageStrip.Request:
    """The ImageStrip request of the strip of pointing mode ``strip`` (kind ``strip``: its start,
    end, altitude and scan speed, its boresight and along-track axes; its ``scan_start`` is the
    planner's to set, the arrival) from ``q_initial`` at ``epoch``, keeping ``zones``; ValueError as
    :func:`maneuver_request`."""
    req = ImageStrip.Request()
    req.header.frame_id = frame_id
    req.initial_attitude = convert.quaternion(q_initial)
    req.start_latitude_deg, req.start_longitude_deg = math.degrees(strip.latitude), math.degrees(strip.longitude)
    req.end_latitude_deg, req.end_longitude_deg = math.degrees(strip.end_latitude), math.degrees(strip.end_longitude)
    req.altitude_m, req.scan_speed_m_s = float(strip.altitude), float(strip.scan_speed)
    req.sensor_axis, req.along_track_axis = convert.vector3(strip.primary_axis), convert.vector3(strip.secondary_axis)
    req.method, req.time_budget = method, float(time_budget)
    req.epoch = convert.epoch_msg(epoch)
    req.zones = [convert.zone_msg(z) for z in zones]
    req.wheel_speeds = [float(v) for v in wheel_speeds]
    check_strings(req)
    return req


def maneuver_request(q_initial, q_final, sensor_axis, cones: list[Cone], *, method: str = "",
                     time_budget: float = 0.0, spacecraft: str = "", frame_id: str = "eci",
                     options: dict | None = None, epoch: datetime | None = None, zones: list[Zone] = (),
                     tle: tuple[str, str] = ("", ""), wheel_speeds=(),
                     end_pointing: PointingMode | None = None) -> PlanManeuver.Request:
    """A PlanManeuver request; ValueError when a string holds a NUL or another control character.
    The real sky: ``epoch`` (UTC start; None: the scenario's), ``zones`` (besides the cones) and the
    orbit's ``tle`` lines (empty: the scenario's orbit); ``wheel_speeds``: the wheels' speeds at the
    start (rad/s relative to the body; empty: stopped), kept within their limit along the plan;
    ``end_pointing``: a pointing mode the plan ends on, at its attitude and rate (method time_optimal)."""
    req = PlanManeuver.Request()
    req.header.frame_id = frame_id
    req.initial_attitude = convert.quaternion(q_initial)
    req.final_attitude = convert.quaternion(q_final)
    req.sensor_axis = convert.vector3(sensor_axis)
    req.cones = [convert.cone_msg(c) for c in cones]
    req.method, req.time_budget, req.spacecraft = method, float(time_budget), spacecraft
    req.option_names = list((options or {}).keys())
    req.option_values = [float(v) for v in (options or {}).values()]
    req.epoch = convert.epoch_msg(epoch)
    req.zones = [convert.zone_msg(z) for z in zones]
    req.tle_line1, req.tle_line2 = tle
    req.wheel_speeds = [float(v) for v in wheel_speeds]
    if end_pointing is not None:
        req.end_pointing = convert.pointing_msg(end_pointing)
    check_strings(req)
    return req


DEFAULT_KEY = object()      # set_mode: sign with the default key file when it exists


class SuiteClient(Node):
    def __init__(self, name: str = "suite_client"):
        super().__init__(name)
        self.plan_client = self.create_client(PlanManeuver, topics.PLAN_MANEUVER, qos_profile=qos.SERVICE_QOS)
        self.schedule_client = self.create_client(PlanSchedule, topics.PLAN_SCHEDULE, qos_profile=qos.SERVICE_QOS)
        self.image_target_client = self.create_client(ImageTarget, topics.IMAGE_TARGET, qos_profile=qos.SERVICE_QOS)
        self.image_strip_client = self.create_client(ImageStrip, topics.IMAGE_STRIP, qos_profile=qos.SERVICE_QOS)
        self.mode_client = self.create_client(SetControllerMode, topics.SET_CONTROLLER_MODE)
        self.execute_client = ActionClient(self, ExecuteManeuver, topics.EXECUTE_MANEUVER)
        self.hold_client = self.create_client(SetBool, topics.HOLD_SIMULATOR)

    def wait_for_servers(self, timeout: float = 30.0, schedule: bool = False, estimate: bool = False) -> None:
        """Wait for the planner's and the controller's services and action (``schedule``: the schedule
        service too; ``estimate``: then for a CONVERGED attitude estimate, without which a controller
        flying on the estimate refuses a maneuver with 313 ESTIMATE_UNHEALTHY); TimeoutError after
        ``timeout`` s in all."""
        deadline = time.monotonic() + timeout
        clients = [self.plan_client, self.mode_client] + ([self.schedule_client] if schedule else [])
        for client in clients:
            if not client.wait_for_service(timeout_sec=max(0.1, deadline - time.monotonic())):
                raise TimeoutError(f"service {client.srv_name} not available after {timeout} s")
        if not self.execute_client.wait_for_server(timeout_sec=max(0.1, deadline - time.monotonic())):
            raise TimeoutError(f"action {topics.EXECUTE_MANEUVER} not available after {timeout} s")
        if estimate:
            self.wait_for_estimate(max(0.0, deadline - time.monotonic()))

    def wait_for_estimate(self, timeout: float = 30.0) -> None:
        """Spin until the estimator publishes a CONVERGED attitude estimate; TimeoutError after ``timeout`` s."""
        converged = []
        sub = self.create_subscription(AttitudeEstimate, topics.ESTIMATE,
                                       lambda m: converged.append(m.health == m.HEALTH_CONVERGED), qos.STREAM_QOS)
        try:
            deadline = time.monotonic() + timeout
            while not any(converged):
                if time.monotonic() > deadline:
                    raise TimeoutError(f"no converged estimate on {topics.ESTIMATE} within {timeout:.3g} s")
                rclpy.spin_once(self, timeout_sec=0.05)
        finally:
            self.destroy_subscription(sub)

    def _servers(self, client) -> frozenset:
        """The servers of ``client``'s service as this node's graph lists them: the GIDs of their
        reply writers (empty for a middleware without DDS topic names, or while the graph lags)."""
        try:
            return frozenset(bytes(i.endpoint_gid)
                             for i in self.get_publishers_info_by_topic(f"rr{client.srv_name}Reply", no_mangle=True))
        except Exception:  # a middleware that does not list them: only readiness changes are seen
            return frozenset()

    def _call(self, client, request, timeout: float):
        """Send ``request`` once the service is ready and wait for the first answer.

        The graph still lists a killed server until its lease expires, so a request can go to a
        dead server. Whenever a server appears that was not listed when the request was sent (a
        restart), or the service comes back after being gone, the request is sent again
        :data:`RESEND_SETTLE` s later (time for the new server to discover this client, so that
        its reply is not lost); a server that has only just appeared gets that time before the
        first send too. The first answer wins. A string with a NUL is refused (ValueError): rclpy
        would send it cut at the NUL; other control characters are for the server to refuse."""
        check_strings(request, nul_only=True)
        deadline = time.monotonic() + timeout
        if not client.service_is_ready():
            if not client.wait_for_service(timeout_sec=max(0.0, timeout)):
                raise TimeoutError(f"no answer from {client.srv_name} within {timeout} s (no server)")
            self._spin_for(RESEND_SETTLE)
        futures, known, was_ready, appeared = [client.call_async(request)], self._servers(client), True, None
        try:
            while True:
                rclpy.spin_until_future_complete(self, futures[-1], timeout_sec=POLL)
                answered = next((f for f in futures if f.done()), None)
                if answered is not None:
                    return answered.result()
                now = time.monotonic()
                if now > deadline:
                    raise TimeoutError(f"no answer from {client.srv_name} within {timeout} s")
                servers, ready = self._servers(client), client.service_is_ready()
                if ready and ((known and servers - known) or not was_ready):
                    appeared = appeared or now
                known, was_ready = known | servers, ready
                if appeared is not None and ready and now - appeared >= RESEND_SETTLE:
                    self.get_logger().info(f"{client.srv_name}: a new server appeared; sending the request again")
                    futures.append(client.call_async(request))
                    appeared = None
        finally:
            for future in futures:
                if not future.done():
                    client.remove_pending_request(future)

    def _spin_for(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            rclpy.spin_once(self, timeout_sec=min(POLL, max(0.0, end - time.monotonic())))

    def plan(self, request: PlanManeuver.Request, timeout: float = 120.0) -> PlanManeuver.Response:
        return self._call(self.plan_client, request, timeout)

    def schedule(self, request: PlanSchedule.Request, timeout: float = 300.0) -> PlanSchedule.Response:
        return self._call(self.schedule_client, request, timeout)

    def image_target(self, request: ImageTarget.Request, timeout: float = 120.0) -> ImageTarget.Response:
        return self._call(self.image_target_client, request, timeout)

    def image_strip(self, request: ImageStrip.Request, timeout: float = 120.0) -> ImageStrip.Response:
        return self._call(self.image_strip_client, request, timeout)

    def hold_simulator(self, held: bool, timeout: float = 10.0) -> SetBool.Response:
        """Hold sim time (``held``) or let it run again (the simulator's ``/simulator/hold``)."""
        return self._call(self.hold_client, SetBool.Request(data=held), timeout)

    def delivered(self, publisher, timeout: float = 10.0) -> bool:
        """Whether every message ``publisher`` (reliable) sent was acknowledged by its subscribers within
        ``timeout`` s of wall time: before the suite stops, its last messages reach the recorder."""
        return publisher.wait_for_all_acked(Duration(seconds=timeout))

    @contextmanager
    def simulator_held(self, timeout: float = 10.0):
        """Sim time held for the block, released after it whatever happened in it."""
        self.hold_simulator(True, timeout)
        try:
            yield
        finally:
            self.hold_simulator(False, timeout)

    def set_mode(self, mode: int, timeout: float = 10.0, key=DEFAULT_KEY, pointing=None,
                 dumping: bool | None = None) -> SetControllerMode.Response:
        """Change the controller's mode (MODE_POINTING: to ``pointing``, an
        :class:`att_msgs_py.types.PointingMode`) and, when ``dumping`` is given, switch the momentum
        dumping; the request is signed with ``key`` (an Ed25519 private key; by default the key file
        of :func:`att_msgs_py.signing.default_key_dir` when there is one, ``None``: unsigned), which
        a controller with ``require_signed_modes`` needs."""
        if key is DEFAULT_KEY:
            path = signing.default_key_dir() / signing.PRIVATE_NAME
            key = signing.load_private_key(path) if path.is_file() else None
        request = SetControllerMode.Request(mode=mode, sequence=time.time_ns())
        if pointing is not None:
            request.pointing = convert.pointing_msg(pointing)
        if dumping is not None:
            request.dumping = request.DUMPING_ON if dumping else request.DUMPING_OFF
        if key is not None:
            signing.sign(request, key)
        return self._call(self.mode_client, request, timeout)

    def execute(self, plan_id: str = "", plan=None, timeout: float = 600.0, on_feedback=None,
                stall_timeout: float = STALL_TIMEOUT, pointing_after=None) -> ExecuteManeuver.Result:
        """Run a plan on the controller and wait for the result (``pointing_after``: a
        :class:`att_msgs_py.types.PointingMode` the controller hands over to at the plan's end). A
        plan just published that has not reached the controller yet is waited for by the controller
        (its ``plan_wait_s``). A controller that falls silent (no feedback for ``stall_timeout`` s of
        wall time) gives an ABORTED result (:meth:`_await_result`)."""
        goal = ExecuteManeuver.Goal(plan_id=plan_id, use_inline_plan=plan is not None,
                                    point_after=pointing_after is not None)
        if plan is not None:
            goal.plan = plan
        if pointing_after is not None:
            goal.pointing_after = convert.pointing_msg(pointing_after)
        check_strings(goal, "goal", nul_only=True)
        heard = [time.monotonic(), None]            # wall time of the last sign of life, last feedback

        def feedback(msg):
            heard[0], heard[1] = time.monotonic(), msg.feedback
            if on_feedback is not None:
                on_feedback(msg)

        send = self.execute_client.send_goal_async(goal, feedback_callback=feedback)
        rclpy.spin_until_future_complete(self, send, timeout_sec=GOAL_ANSWER_TIMEOUT)
        if not send.done():
            raise TimeoutError(f"the controller did not answer the goal within {GOAL_ANSWER_TIMEOUT:g} s")
        handle = send.result()
        if handle is None or not handle.accepted:
            raise RuntimeError("the controller rejected the goal (another maneuver is executing)")
        heard[0] = time.monotonic()
        return self._await_result(handle, heard, timeout, stall_timeout)

    def _await_result(self, handle, heard: list, timeout: float, stall_timeout: float) -> ExecuteManeuver.Result:
        """The goal's result; ABORTED when nothing was heard from the controller for
        ``stall_timeout`` s (the goal is then cancelled, in case the controller still lives);
        TimeoutError after ``timeout`` s."""
        done = handle.get_result_async()
        deadline = time.monotonic() + timeout
        while not done.done():
            rclpy.spin_until_future_complete(self, done, timeout_sec=POLL)
            now = time.monotonic()
            if done.done():
                break
            if now - heard[0] > stall_timeout:
                handle.cancel_goal_async()
                rclpy.spin_once(self, timeout_sec=POLL)
                last = heard[1]
                return ExecuteManeuver.Result(
                    success=False, error_code=int(ErrorCode.ABORTED),
                    message=f"the controller fell silent: no feedback for {stall_timeout:g} s of wall time "
                            f"(server {'still listed' if self.execute_client.server_is_ready() else 'gone'}); "
                            "the maneuver's outcome is unknown",
                    duration=float(last.elapsed) if last is not None else 0.0,
                    final_attitude_error=math.nan, final_rate=math.nan)
            if now > deadline:
                raise TimeoutError(f"maneuver not finished within {timeout} s")
        return done.result().result


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
