"""Planner node: serves ``/planner/plan_maneuver`` (PlanManeuver), ``/planner/plan_schedule``
(PlanSchedule), ``/planner/image_target`` (ImageTarget) and ``/planner/image_strip`` (ImageStrip:
:mod:`att_planner.service.imaging`, a slew onto a ground site or a strip's start, answered as a
maneuver) and publishes every returned plan on the latched ``/planner/plans`` for the controller and
the recorder; with ``plan_markers``
(default true) it also publishes the latest plan's boresight path for the 3D view on the latched
``/planner/plan_markers`` (visualization_msgs/MarkerArray, :func:`att_sim.models.scene.plan_shapes`): the
planner shows its own plans, so the simulator stays on the truth side.

Callbacks only translate: message -> :class:`ManeuverRequest` -> :func:`validate_maneuver` ->
:func:`plan_maneuver` -> message (:mod:`att_planner.service` holds the logic); the response names
the stage whose plan it carries and reports every stage's time (anytime planning: a request's
``time_budget`` of 50 ms is answered with the verified first plan). The real sky of a
request (epoch, zones, TLE) goes in as sent; every plan records its epoch and zones, which its
signature covers. Requests run
concurrently (reentrant callback group on a multi-threaded executor), so a long solve never
blocks a quick request; each request builds its own problem, nothing is shared between requests
but the read-only method registry.

Every plan it issues is signed with the Ed25519 private key ``signing_key``
(:mod:`att_msgs_py.signing`) after its last field is set, and names the spacecraft configuration
it was made for (``spacecraft_digest``); the response and the published plan are the same message.
Refusals and log lines are clipped (:func:`att_msgs_py.errors.clip`). A request is first held to
the size caps of :mod:`att_msgs_py.limits` (SIZE_LIMIT, before any field is converted), and after
each answer the node hands the memory it freed back to the system (:func:`att_msgs_py.memory.trim`).
"""
from __future__ import annotations

import math
import uuid

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from visualization_msgs.msg import MarkerArray

from att_msgs.msg import ManeuverPlan
from att_msgs.srv import ImageStrip, ImageTarget, PlanManeuver, PlanSchedule
from att_msgs_py import convert, limits, markers, memory, qos, signing, topics
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.node_runner import ParameterReader, read_scenario, run_node
from att_msgs_py.suite_node import SuiteNode
from att_msgs_py.types import Plan
from att_planner import methods
from att_planner.methods.schedule import plan_schedule
from att_planner.service.imaging import (
    ImageStripRequest,
    ImageTargetRequest,
    plan_image,
    validate_image_strip,
    validate_image_target,
)
from att_planner.service.planner_parameters import PLANNER
from att_planner.service.planning import PlanOutcome, plan_maneuver, plan_schedule_request, prepare, run_method
from att_planner.service.requests import ManeuverRequest, validate_maneuver, validate_schedule
from att_planner.service.warm import warm, warm_requests
from att_planner.service.worker import call_isolated, run_isolated, set_max_parallel, set_warm_up, start_pool, warm_up
from att_planner.verification import Tolerances
from att_sim.models import scenario as scen
from att_sim.models import scene


class PlannerNode(SuiteNode):
    def __init__(self):
        super().__init__("planner")
        scenario = scen.load_checked(read_scenario(self))
        self._scenario_name = scenario.name
        param = ParameterReader(self, PLANNER, scenario.node_params.get("planner", {}), str(scenario.node_params_path))
        self._frame_id = scenario.frame_id
        self._default_method = param("default_method") or methods.REGISTRY[0].name
        self._default_budget = param("time_budget_s")
        self._tolerances = Tolerances(attitude=math.radians(param("accept_attitude_error_deg")),
                                      rate=param("accept_final_rate_rad_s"),
                                      cone_penetration=math.radians(param("accept_cone_penetration_deg")))
        self._cone_padding = math.radians(param("cone_padding_deg"))
        self._schedule_rate_max = param("schedule_rate_max_rad_s")  # .inf: no bound
        self._min_elevation_deg = param("image_min_elevation_deg")
        self._scan_speed = param("strip_scan_speed_m_s")        # 0: the sub-satellite point's
        key_path = param("signing_key", str(signing.default_key_dir() / signing.PRIVATE_NAME))
        self._signing_key = self._load_signing_key(key_path)
        parallel = param("max_parallel_solves")
        set_max_parallel(parallel)
        show_plans = param("plan_markers")
        # every worker plans these scenarios' demo maneuvers before it serves (its NLPs built)
        names = [n.strip() for n in param("warm_up_scenarios", scenario.name).split(",") if n.strip()]
        param.refuse_unknown()
        warm_up()
        prepare(scenario.spacecraft)
        set_warm_up(warm, (warm_requests(names, frame_id=self._frame_id, default_method=self._default_method),
                           self._tolerances, self._cone_padding))
        start_pool(parallel)
        group = ReentrantCallbackGroup()
        self._plan_pub = self.create_publisher(ManeuverPlan, topics.PLANS, qos.LATCHED_QOS)
        self._marker_pub = (self.create_publisher(MarkerArray, topics.PLAN_MARKERS, qos.LATCHED_QOS)
                            if show_plans else None)
        self.create_service(PlanManeuver, topics.PLAN_MANEUVER, self.on_plan_maneuver, qos_profile=qos.SERVICE_QOS,
                            callback_group=group)
        self.create_service(PlanSchedule, topics.PLAN_SCHEDULE, self.on_plan_schedule, qos_profile=qos.SERVICE_QOS,
                            callback_group=group)
        self.create_service(ImageTarget, topics.IMAGE_TARGET, self.on_image_target, qos_profile=qos.SERVICE_QOS,
                            callback_group=group)
        self.create_service(ImageStrip, topics.IMAGE_STRIP, self.on_image_strip, qos_profile=qos.SERVICE_QOS,
                            callback_group=group)
        self.get_logger().info(f"methods: {', '.join(methods.METHODS)} (default {self._default_method}); plans "
                               f"signed with key {signing.key_id(self._signing_key.public_key())}")

    @staticmethod
    def _load_signing_key(path: str):
        try:
            return signing.load_private_key(path)
        except FileNotFoundError:
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"parameter 'signing_key': no plan-signing key at "
                                                        f"'{clip(path, 200)}': run att-keygen") from None
        except (OSError, ValueError, TypeError) as exc:
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"parameter 'signing_key': '{clip(path, 200)}' is not a "
                                                        f"readable Ed25519 private key ({clip(exc, 120)}): run "
                                                        "att-keygen") from None

    def on_plan_maneuver(self, request: PlanManeuver.Request, response: PlanManeuver.Response):
        try:
            valid = validate_maneuver(maneuver_from_msg(request), frame_id=self._frame_id,
                                      default_spacecraft=self._scenario_name, default_method=self._default_method,
                                      default_budget=self._default_budget)
        except RequestError as err:
            return self.refuse(response, err, "request")
        outcome = self._planned(plan_maneuver, valid, valid.method, response)
        self.answer(response, outcome, valid.spacecraft, valid.method.name, sensor_axis=valid.problem.sensor_axis,
                    cones=valid.problem.cones, zones=valid.problem.zones, epoch=valid.problem.epoch,
                    spacecraft_digest=valid.spacecraft_digest)
        return response

    def on_plan_schedule(self, request: PlanSchedule.Request, response: PlanSchedule.Response):
        try:
            limits.check(request, limits.PLAN_SCHEDULE)
            valid = validate_schedule(
                list(request.target_names), [convert.from_quaternion(q) for q in request.targets],
                convert.from_quaternion(request.start_attitude),
                None if request.return_to_start else convert.from_quaternion(request.end_attitude),
                request.spacecraft, request.time_budget,
                frame_id=self._frame_id, request_frame=request.header.frame_id,
                default_spacecraft=self._scenario_name, default_budget=self._default_budget,
                rate_max=self._schedule_rate_max, epoch=convert.epoch_parts(request.epoch),
                zones=[convert.zone_from_msg(z) for z in request.zones], tle=(request.tle_line1, request.tle_line2),
                observations=(list(request.dwell_times), list(request.window_opens), list(request.window_closes)))
        except RequestError as err:
            return self.refuse(response, err, "schedule")

        def runner(problem, wait):
            return call_isolated(plan_schedule, (problem,), {}, wait, on_death=lambda message: message)

        try:
            outcome = plan_schedule_request(valid, self._tolerances, runner=runner)
        except Exception as exc:  # a fault of the service itself is answered, never left hanging
            outcome = self.internal_error(exc)
        if outcome.code == ErrorCode.OK:
            response.order = outcome.plan.order
            response.passage_times = [float(p.time) for p in outcome.plan.passages]
            response.observation_ends = [float(p.time + p.dwell) for p in outcome.plan.passages]
        self.answer(response, outcome, valid.spacecraft, f"schedule of {len(valid.problem.targets)} targets",
                    zones=valid.problem.zones, epoch=valid.problem.epoch,
                    spacecraft_digest=valid.problem.spacecraft.digest)
        return response

    def on_image_target(self, request: ImageTarget.Request, response: ImageTarget.Response):
        try:
            limits.check(request, limits.IMAGE_TARGET)
            valid = validate_image_target(
                ImageTargetRequest(**_image_common(request), latitude_deg=request.latitude_deg,
                                   longitude_deg=request.longitude_deg, altitude_m=request.altitude_m,
                                   dwell_s=request.dwell_s, align_along_track=request.align_along_track),
                **self._image_defaults())
        except RequestError as err:
            return self.refuse(response, err, "image target")
        return self._image(valid, request, response, "image target")

    def on_image_strip(self, request: ImageStrip.Request, response: ImageStrip.Response):
        try:
            limits.check(request, limits.IMAGE_STRIP)
            valid = validate_image_strip(
                ImageStripRequest(**_image_common(request), start_latitude_deg=request.start_latitude_deg,
                                  start_longitude_deg=request.start_longitude_deg,
                                  end_latitude_deg=request.end_latitude_deg,
                                  end_longitude_deg=request.end_longitude_deg,
                                  by_azimuth=request.by_azimuth, azimuth_deg=request.azimuth_deg,
                                  length_m=request.length_m, altitude_m=request.altitude_m,
                                  scan_speed_m_s=request.scan_speed_m_s),
                **self._image_defaults(), rate_max=self._schedule_rate_max, default_scan_speed_m_s=self._scan_speed)
        except RequestError as err:
            return self.refuse(response, err, "image strip")
        return self._image(valid, request, response, "image strip")

    def _image_defaults(self) -> dict:
        return dict(frame_id=self._frame_id, default_spacecraft=self._scenario_name,
                    default_method=self._default_method, default_budget=self._default_budget,
                    min_elevation_deg=self._min_elevation_deg)

    def _image(self, valid, request, response, what: str):
        """Plan an image (:func:`att_planner.service.imaging.plan_image`) and answer as a maneuver."""
        outcome = self._planned(plan_image, valid, valid.maneuver.method, response)
        for name in ("image_start", "image_end"):
            setattr(response, name, float(getattr(outcome, name, math.nan)))
        response.lowest_elevation_deg = math.degrees(getattr(outcome, "lowest_elevation", math.nan))
        after = getattr(outcome, "pointing_after", None)
        if after is not None:
            response.pointing_after = convert.pointing_msg(after)
        problem = valid.maneuver.problem
        self.answer(response, outcome, valid.maneuver.spacecraft, f"{what} ({valid.maneuver.method.name})",
                    sensor_axis=problem.sensor_axis, cones=problem.cones, zones=problem.zones, epoch=problem.epoch,
                    spacecraft_digest=problem.spacecraft.digest)
        return response

    def _planned(self, plan, valid, method, response) -> PlanOutcome:
        """``plan(valid, tolerances, cone padding, runner)``, ``method`` run in a child process unless it
        is cheap; a fault of the service itself answered as an internal error; the response's stages
        filled from the outcome."""
        runner = run_method if method.cheap else run_isolated
        try:
            outcome = plan(valid, self._tolerances, self._cone_padding, runner)
        except Exception as exc:  # a fault of the service itself is answered, never left hanging
            outcome = self.internal_error(exc)
        response.stage = str(outcome.stage)
        response.stages = [convert.stage_msg(stage) for stage in outcome.stages]
        response.slowdown = outcome.slowdown
        return outcome

    def internal_error(self, exc: Exception) -> PlanOutcome:
        self.get_logger().error(clip(f"planning failed unexpectedly: {type(exc).__name__}: {exc}"))
        return PlanOutcome(ErrorCode.SOLVER_FAILED, clip(f"internal error while planning: {type(exc).__name__}: {exc}"),
                           None)

    def refuse(self, response, err: RequestError, what: str):
        self.get_logger().warning(clip(f"{what} rejected [{int(err.code)} {err.code.name}]: {err.message}"))
        response.success, response.error_code, response.message = False, int(err.code), clip(err.message)
        memory.trim()
        return response

    def answer(self, response, outcome: PlanOutcome, spacecraft: str, what: str, **context):
        """Fill the response from ``outcome``; a plan gets an id, the spacecraft digest, a stamp and
        its signature (in that order, the signature last); an accepted one is published."""
        response.success = outcome.code == ErrorCode.OK
        response.error_code, response.message = int(outcome.code), clip(outcome.message)
        plan: Plan | None = outcome.plan
        if plan is not None and len(plan.t) >= 2:
            plan.plan_id, plan.frame_id, plan.spacecraft = uuid.uuid4().hex[:12], self._frame_id, spacecraft
            for key, value in context.items():
                setattr(plan, key, value)
            plan.message = clip(plan.message)
            plan.verification = outcome.verification      # a refused plan goes out unverified
            response.plan = convert.plan_msg(plan)
            response.plan.header.stamp = self.get_clock().now().to_msg()
            signing.sign(response.plan, self._signing_key)
        if response.success:
            self.get_logger().info(clip(f"{what}: {outcome.message}"))
            self._plan_pub.publish(response.plan)
            # a schedule has no sensor axis of its own: its zones' (none without zones)
            s_B = context.get("sensor_axis", plan.zones[0].sensor_axis if plan.zones else None)
            if self._marker_pub is not None and s_B is not None:
                shapes = scene.plan_shapes(plan.q, s_B, self._frame_id)
                t = convert.from_time(response.plan.header.stamp)
                self._marker_pub.publish(markers.marker_array(shapes, t, self._frame_id))
        else:
            self.get_logger().warning(clip(f"{what} failed (code {response.error_code}): {outcome.message}"))
        memory.trim()            # what the request's checks and verification took goes back to the system


def maneuver_from_msg(request) -> ManeuverRequest:
    """The fields of a PlanManeuver request as a :class:`ManeuverRequest`, after its sizes are
    checked (:data:`att_msgs_py.limits.PLAN_MANEUVER`): an oversized request is refused (SIZE_LIMIT)
    before any field is converted."""
    limits.check(request, limits.PLAN_MANEUVER)
    return ManeuverRequest(
        frame_id=request.header.frame_id,
        q_initial=convert.from_quaternion(request.initial_attitude),
        q_final=convert.from_quaternion(request.final_attitude),
        sensor_axis=convert.from_vector3(request.sensor_axis),
        cones=[convert.cone_parts(c) for c in request.cones],
        method=request.method, time_budget=request.time_budget, spacecraft=request.spacecraft,
        option_names=list(request.option_names), option_values=list(request.option_values),
        semi_free=request.semi_free, sensor_target=convert.from_vector3(request.sensor_target),
        epoch=convert.epoch_parts(request.epoch), zones=[convert.zone_from_msg(z) for z in request.zones],
        tle_line1=request.tle_line1, tle_line2=request.tle_line2,
        wheel_speeds=list(request.wheel_speeds),
        end_pointing=convert.pointing_from_msg(request.end_pointing), healthy_wheels=list(request.healthy_wheels))


def _image_common(request) -> dict:
    """The fields every imaging request has, as :class:`att_planner.service.imaging.ImageCommon`'s."""
    return dict(frame_id=request.header.frame_id, q_initial=convert.from_quaternion(request.initial_attitude),
                sensor_axis=convert.from_vector3(request.sensor_axis),
                along_track_axis=convert.from_vector3(request.along_track_axis), method=request.method,
                time_budget=request.time_budget, spacecraft=request.spacecraft,
                epoch=convert.epoch_parts(request.epoch), wheel_speeds=list(request.wheel_speeds),
                zones=[convert.zone_from_msg(z) for z in request.zones])


def main(args=None):
    memory.reexec_with_c_allocator()
    # waiting requests hold a thread, not a core: many threads so quick requests never queue
    run_node(PlannerNode, args, make_executor=lambda: MultiThreadedExecutor(num_threads=16))


if __name__ == "__main__":
    main()
