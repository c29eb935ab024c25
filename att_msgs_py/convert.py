"""The one place that converts between messages and the plain types of :mod:`att_msgs_py.types`.

Nodes call these functions; no other module builds or reads message fields by hand. Reading
functions take any object with the message's attributes (rclpy messages, or the objects the
MCAP decoder returns), so logs and live topics go through the same code. They return raw values:
deciding whether a value is acceptable is the receiver's job.
Quaternions are geometry_msgs order (x, y, z, w) = numpy order, body-to-inertial. An epoch is
a UTC ``datetime`` on the wire as ``builtin_interfaces/Time`` seconds since 1970 (the zero time
means "no epoch"; ``datetime`` keeps microseconds, so a wire epoch is read to the microsecond).
"""
from __future__ import annotations

from datetime import datetime, timedelta

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion, Vector3
from sensor_msgs.msg import Imu, JointState, MagneticField

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import (
    ActuatorCommand,
    AttitudeEstimate,
    CoarseSunSensors,
    ControllerStatus,
    FaultEvent,
    FaultStatus,
    KeepOutCone,
    ManeuverPlan,
    MissionEvent,
    PlanStage,
    PlanVerification,
    PointingMode,
    SensorTruth,
    SpacecraftState,
    StarTracker,
    Zone,
)
from att_msgs_py import types
from att_msgs_py.validation import UNIX_EPOCH


def vector3(v) -> Vector3:
    x, y, z = (float(c) for c in np.asarray(v, float).reshape(3))
    return Vector3(x=x, y=y, z=z)


def from_vector3(msg) -> np.ndarray:
    return np.array([msg.x, msg.y, msg.z], float)


def quaternion(q) -> Quaternion:
    x, y, z, w = (float(c) for c in np.asarray(q, float).reshape(4))
    return Quaternion(x=x, y=y, z=z, w=w)


def from_quaternion(msg) -> np.ndarray:
    """Raw components (not normalised: validation decides what to do with the norm)."""
    return np.array([msg.x, msg.y, msg.z, msg.w], float)


def time_msg(seconds: float) -> Time:
    """Rounded to the nanosecond, carrying into ``sec`` (3.9999999999 s -> 4 s 0 ns, not 3 s 0 ns)."""
    sec, nanosec = divmod(int(round(seconds * 1e9)), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


def from_time(msg) -> float:
    return msg.sec + msg.nanosec * 1e-9


def epoch_msg(epoch: datetime | None) -> Time:
    """``epoch`` as seconds and nanoseconds since 1970 (exact: a ``datetime`` has microseconds);
    None: the zero time. The message refuses seconds beyond int32 (before 1901-12-13T20:45:52Z,
    after 2038-01-19T03:14:07Z): :func:`att_msgs_py.validation.wire_epoch` checks first."""
    if epoch is None:
        return Time()
    delta = epoch - UNIX_EPOCH
    sec, microseconds = divmod((delta.days * 86_400 + delta.seconds) * 1_000_000 + delta.microseconds, 1_000_000)
    return Time(sec=sec, nanosec=microseconds * 1000)


def epoch_parts(msg) -> tuple[int, int]:
    """Raw (sec, nanosec) of a time message, for validation before it is read as an epoch."""
    return int(msg.sec), int(msg.nanosec)


def from_epoch(msg) -> datetime | None:
    """The UTC epoch of a time message (nanoseconds rounded to the microsecond); None for zero."""
    sec, nanosec = epoch_parts(msg)
    if sec == 0 and nanosec == 0:
        return None
    return UNIX_EPOCH + timedelta(seconds=sec, microseconds=round(nanosec / 1000))


def zone_msg(zone: types.Zone) -> Zone:
    """A zone on the wire; a body other than "inertial" has no direction (sent as zero)."""
    return Zone(name=zone.name, body=zone.body, sensor_axis=vector3(zone.sensor_axis),
                half_angle=float(zone.half_angle), keep_in=bool(zone.keep_in),
                direction=vector3(np.zeros(3) if zone.direction is None else zone.direction))


def zone_from_msg(msg) -> types.Zone:
    """The zone of a message, values as sent (validation decides: :func:`att_planner.cones.zone_issue`).
    A zero direction is read as none (the bodies have none); a non-zero one is kept, whatever the body."""
    direction = from_vector3(msg.direction)
    return types.Zone(name=msg.name, body=msg.body, sensor_axis=from_vector3(msg.sensor_axis),
                      half_angle=float(msg.half_angle), keep_in=bool(msg.keep_in),
                      direction=None if not np.any(direction) else direction)


def cone_msg(cone: types.Cone) -> KeepOutCone:
    return KeepOutCone(name=cone.name, direction=vector3(cone.direction), half_angle=float(cone.half_angle))


def cone_parts(msg) -> tuple[np.ndarray, float, str]:
    """Raw (direction, half_angle, name) of a cone message, for validation before a Cone is built."""
    return from_vector3(msg.direction), float(msg.half_angle), msg.name


# -- state and commands ------------------------------------------------------------------------

def state_msg(s: types.State) -> SpacecraftState:
    msg = SpacecraftState(body_frame_id=s.body_frame_id, command_timeout=bool(s.command_timeout))
    msg.header.stamp = time_msg(s.t)
    msg.header.frame_id = s.frame_id
    msg.attitude = quaternion(s.q)
    msg.body_rate = vector3(s.omega)
    msg.wheel_speeds = [float(v) for v in s.wheel_speeds]
    msg.wheel_torques = [float(v) for v in s.wheel_torques]
    msg.magnetic_field_body = vector3(s.field_body)
    msg.dipole = vector3(s.dipole)
    msg.applied_torque = vector3(s.applied_torque)
    msg.position = vector3(s.position)
    return msg


def state_from_msg(msg) -> types.State:
    return types.State(
        t=from_time(msg.header.stamp), q=from_quaternion(msg.attitude), omega=from_vector3(msg.body_rate),
        wheel_speeds=np.asarray(msg.wheel_speeds, float), wheel_torques=np.asarray(msg.wheel_torques, float),
        field_body=from_vector3(msg.magnetic_field_body), dipole=from_vector3(msg.dipole),
        applied_torque=from_vector3(msg.applied_torque), position=from_vector3(msg.position),
        command_timeout=bool(msg.command_timeout), frame_id=msg.header.frame_id, body_frame_id=msg.body_frame_id)


def command_msg(c: types.Command) -> ActuatorCommand:
    msg = ActuatorCommand(mode=int(c.mode), wheel_torques=[float(v) for v in c.wheel_torques],
                          dipole=vector3(c.dipole), body_torque=vector3(c.body_torque), plan_id=c.plan_id)
    msg.header.stamp = time_msg(c.t)
    msg.header.frame_id = c.frame_id
    return msg


def command_from_msg(msg) -> types.Command:
    return types.Command(mode=int(msg.mode), wheel_torques=np.asarray(msg.wheel_torques, float),
                         dipole=from_vector3(msg.dipole), body_torque=from_vector3(msg.body_torque),
                         plan_id=msg.plan_id, t=from_time(msg.header.stamp), frame_id=msg.header.frame_id)


def controller_status_msg(s: types.ControllerStatus) -> ControllerStatus:
    msg = ControllerStatus(mode=int(s.mode), plan_id=s.plan_id, plan_progress=float(s.plan_progress),
                           state_stale=bool(s.state_stale), message=s.message, guidance=s.guidance,
                           reference_attitude=quaternion(s.reference_q), reference_rate=vector3(s.reference_rate),
                           attitude_error=float(s.attitude_error), dumping=bool(s.dumping))
    msg.header.stamp = time_msg(s.t)
    msg.header.frame_id = s.frame_id
    return msg


def pointing_msg(p: types.PointingMode) -> PointingMode:
    return PointingMode(kind=p.kind, attitude=quaternion(p.attitude), primary_axis=vector3(p.primary_axis),
                        secondary_axis=vector3(p.secondary_axis), secondary=p.secondary,
                        secondary_direction=vector3(p.secondary_direction), yaw=float(p.yaw),
                        latitude=float(p.latitude), longitude=float(p.longitude), altitude=float(p.altitude),
                        target_direction=vector3(p.target_direction), end_latitude=float(p.end_latitude),
                        end_longitude=float(p.end_longitude), scan_speed=float(p.scan_speed),
                        scan_start=time_msg(p.scan_start))


def pointing_from_msg(msg) -> types.PointingMode:
    return types.PointingMode(kind=msg.kind, attitude=from_quaternion(msg.attitude),
                              primary_axis=from_vector3(msg.primary_axis),
                              secondary_axis=from_vector3(msg.secondary_axis), secondary=msg.secondary,
                              secondary_direction=from_vector3(msg.secondary_direction), yaw=float(msg.yaw),
                              latitude=float(msg.latitude), longitude=float(msg.longitude),
                              altitude=float(msg.altitude), target_direction=from_vector3(msg.target_direction),
                              end_latitude=float(msg.end_latitude), end_longitude=float(msg.end_longitude),
                              scan_speed=float(msg.scan_speed), scan_start=from_time(msg.scan_start))


# -- plans -------------------------------------------------------------------------------------

def verification_msg(v: types.Verification) -> PlanVerification:
    return PlanVerification(
        final_attitude_error=float(v.final_attitude_error), final_rate=float(v.final_rate),
        min_cone_margin=float(v.min_cone_margin), cone_margins=[float(m) for m in v.cone_margins],
        torque_ratio=float(v.torque_ratio), wheel_speed_ratio=float(v.wheel_speed_ratio),
        rate_max=float(v.rate_max), dense_samples=int(v.dense_samples), goal=v.goal)


def verification_from_msg(msg) -> types.Verification:
    return types.Verification(
        final_attitude_error=float(msg.final_attitude_error), final_rate=float(msg.final_rate),
        min_cone_margin=float(msg.min_cone_margin), cone_margins=[float(m) for m in msg.cone_margins],
        torque_ratio=float(msg.torque_ratio), wheel_speed_ratio=float(msg.wheel_speed_ratio),
        rate_max=float(msg.rate_max), dense_samples=int(msg.dense_samples), goal=msg.goal)


def plan_msg(plan: types.Plan) -> ManeuverPlan:
    msg = ManeuverPlan(plan_id=plan.plan_id, method=plan.method, status=str(plan.status), message=plan.message,
                       spacecraft=plan.spacecraft, duration=float(plan.duration),
                       control_kind=str(plan.control_kind), interpolation=str(plan.interpolation),
                       solve_seconds=float(plan.wall_time), spacecraft_digest=plan.spacecraft_digest,
                       key_id=plan.key_id, signature=bytes(plan.signature))
    msg.header.frame_id = plan.frame_id
    msg.times = [float(v) for v in plan.t]
    msg.attitudes = [quaternion(q) for q in plan.q]
    msg.rates = [vector3(w) for w in plan.omega]
    msg.torques = [vector3(u) for u in plan.torque]
    msg.sensor_axis = vector3(plan.sensor_axis)
    msg.cones = [cone_msg(c) for c in plan.cones]
    msg.epoch = epoch_msg(plan.epoch)
    msg.zones = [zone_msg(z) for z in plan.zones]
    if plan.verification is not None:
        msg.verification = verification_msg(plan.verification)
    return msg


def plan_from_msg(msg) -> types.Plan:
    """The plan of a message, arrays as sent: t (K,), q (K, 4), omega (K, 3), torque (K, 3).
    ``status``, ``control_kind`` and ``interpolation`` stay the strings sent (they compare equal
    to the vocabularies' members when they are one of them)."""
    return types.Plan(
        t=np.asarray(msg.times, float),
        torque=np.array([from_vector3(u) for u in msg.torques], float).reshape(-1, 3),
        q=np.array([from_quaternion(q) for q in msg.attitudes], float).reshape(-1, 4),
        omega=np.array([from_vector3(w) for w in msg.rates], float).reshape(-1, 3),
        control_kind=msg.control_kind, interpolation=msg.interpolation, method=msg.method, status=msg.status,
        message=msg.message, wall_time=float(msg.solve_seconds), plan_id=msg.plan_id, spacecraft=msg.spacecraft,
        frame_id=msg.header.frame_id, sensor_axis=from_vector3(msg.sensor_axis),
        cones=[types.Cone(*cone_parts(c)) for c in msg.cones], verification=verification_from_msg(msg.verification),
        # logs recorded before plans were signed have none of these three fields, nor (before the
        # real sky) an epoch and zones
        spacecraft_digest=getattr(msg, "spacecraft_digest", ""), key_id=getattr(msg, "key_id", ""),
        signature=bytes(getattr(msg, "signature", b"")),
        epoch=from_epoch(msg.epoch) if hasattr(msg, "epoch") else None,
        zones=[zone_from_msg(z) for z in getattr(msg, "zones", [])])


def stage_msg(stage: types.StageReport) -> PlanStage:
    return PlanStage(name=str(stage.name), method=stage.method, seconds=float(stage.seconds), status=str(stage.status),
                     verified=bool(stage.verified), duration=float(stage.duration), message=stage.message)


def stage_from_msg(msg) -> types.StageReport:
    """The stage of a message (``name`` and ``status`` the strings sent)."""
    return types.StageReport(name=msg.name, method=msg.method, seconds=float(msg.seconds), status=msg.status,
                             verified=bool(msg.verified), duration=float(msg.duration), message=msg.message)


# -- the ExecuteManeuver action -----------------------------------------------------------------

def feedback_msg(f: types.ManeuverFeedback) -> ExecuteManeuver.Feedback:
    return ExecuteManeuver.Feedback(elapsed=float(f.elapsed), progress=float(f.progress),
                                    attitude_error=float(f.attitude_error), min_cone_margin=float(f.min_cone_margin))


def result_msg(r: types.ManeuverResult) -> ExecuteManeuver.Result:
    return ExecuteManeuver.Result(success=bool(r.success), error_code=int(r.error_code), message=r.message,
                                  duration=float(r.duration), final_attitude_error=float(r.final_attitude_error),
                                  final_rate=float(r.final_rate))


# -- sensors and the estimate ----------------------------------------------------------

NOT_PROVIDED = [-1.0] + [0.0] * 8      # a covariance sensor_msgs marks "not provided"


def covariance9(c) -> list[float]:
    """A 3x3 covariance as the row-major float64[9] of a message."""
    return [float(v) for v in np.asarray(c, float).reshape(9)]


def from_covariance9(values) -> np.ndarray:
    return np.asarray(values, float).reshape(3, 3)


def _header(msg, t: float, frame_id: str):
    msg.header.stamp = time_msg(t)
    msg.header.frame_id = frame_id
    return msg


def gyro_msg(m: types.GyroMeasurement) -> Imu:
    """``sensor_msgs/Imu`` with the angular velocity only: orientation and linear acceleration are
    "not provided" (covariance[0] = -1, as the message defines)."""
    msg = _header(Imu(), m.t, m.frame_id)
    msg.orientation.w = 1.0
    msg.orientation_covariance = NOT_PROVIDED
    msg.angular_velocity = vector3(m.omega)
    msg.angular_velocity_covariance = covariance9(m.covariance)
    msg.linear_acceleration_covariance = NOT_PROVIDED
    return msg


def gyro_from_msg(msg) -> types.GyroMeasurement:
    return types.GyroMeasurement(t=from_time(msg.header.stamp), omega=from_vector3(msg.angular_velocity),
                                 covariance=from_covariance9(msg.angular_velocity_covariance),
                                 frame_id=msg.header.frame_id)


def star_tracker_msg(m: types.StarTrackerMeasurement) -> StarTracker:
    msg = _header(StarTracker(sensor_frame_id=m.name, valid=bool(m.valid), status=int(m.status)), m.t, m.frame_id)
    msg.attitude = quaternion(m.q if m.valid else [0.0, 0.0, 0.0, 1.0])
    msg.covariance = covariance9(m.covariance) if m.valid else NOT_PROVIDED
    return msg


def star_tracker_from_msg(msg) -> types.StarTrackerMeasurement:
    return types.StarTrackerMeasurement(t=from_time(msg.header.stamp), name=msg.sensor_frame_id,
                                        q=from_quaternion(msg.attitude), covariance=from_covariance9(msg.covariance),
                                        valid=bool(msg.valid), status=int(msg.status), frame_id=msg.header.frame_id)


def magnetometer_msg(m: types.MagnetometerMeasurement) -> MagneticField:
    msg = _header(MagneticField(), m.t, m.frame_id)
    msg.magnetic_field = vector3(m.field)
    msg.magnetic_field_covariance = covariance9(m.covariance)
    return msg


def magnetometer_from_msg(msg) -> types.MagnetometerMeasurement:
    return types.MagnetometerMeasurement(t=from_time(msg.header.stamp), field=from_vector3(msg.magnetic_field),
                                         covariance=from_covariance9(msg.magnetic_field_covariance),
                                         frame_id=msg.header.frame_id)


def sun_sensors_msg(m: types.SunSensorMeasurement) -> CoarseSunSensors:
    msg = _header(CoarseSunSensors(values=[float(v) for v in m.values], noise=float(m.noise)), m.t, m.frame_id)
    return msg


def sun_sensors_from_msg(msg) -> types.SunSensorMeasurement:
    return types.SunSensorMeasurement(t=from_time(msg.header.stamp), values=np.asarray(msg.values, float),
                                      noise=float(msg.noise), frame_id=msg.header.frame_id)


def wheel_speeds_msg(m: types.WheelSpeedMeasurement) -> JointState:
    """``sensor_msgs/JointState``: one joint per wheel (``wheel_0``, ...), velocity = speed relative
    to the body (what the tachometer measures)."""
    msg = _header(JointState(), m.t, m.frame_id)
    msg.name = [f"wheel_{i}" for i in range(len(m.speeds))]
    msg.velocity = [float(v) for v in m.speeds]
    return msg


def wheel_speeds_from_msg(msg) -> types.WheelSpeedMeasurement:
    return types.WheelSpeedMeasurement(t=from_time(msg.header.stamp), speeds=np.asarray(msg.velocity, float),
                                       frame_id=msg.header.frame_id)


def sensor_truth_msg(m: types.SensorTruth) -> SensorTruth:
    msg = _header(SensorTruth(), m.t, m.frame_id)
    msg.gyro_bias = vector3(m.gyro_bias)
    msg.magnetometer_bias = vector3(m.magnetometer_bias)
    return msg


def estimate_msg(e: types.AttitudeEstimate) -> AttitudeEstimate:
    msg = _header(AttitudeEstimate(body_frame_id=e.body_frame_id, health=int(e.health), message=e.message,
                                   time_since_update=float(e.time_since_update),
                                   rejected_measurements=int(min(e.rejected, 2**32 - 1))), e.t, e.frame_id)
    msg.attitude = quaternion(e.q)
    msg.body_rate = vector3(e.omega)
    msg.gyro_bias = vector3(e.gyro_bias)
    msg.attitude_covariance = covariance9(e.attitude_covariance)
    msg.bias_covariance = covariance9(e.bias_covariance)
    return msg


def estimate_from_msg(msg) -> types.AttitudeEstimate:
    return types.AttitudeEstimate(
        t=from_time(msg.header.stamp), q=from_quaternion(msg.attitude), omega=from_vector3(msg.body_rate),
        gyro_bias=from_vector3(msg.gyro_bias), attitude_covariance=from_covariance9(msg.attitude_covariance),
        bias_covariance=from_covariance9(msg.bias_covariance), health=int(msg.health),
        time_since_update=float(msg.time_since_update), rejected=int(msg.rejected_measurements),
        message=msg.message, frame_id=msg.header.frame_id, body_frame_id=msg.body_frame_id)


def mission_event_msg(e: types.MissionEvent) -> MissionEvent:
    msg = _header(MissionEvent(event=str(e.event), target=e.target, start=float(e.start), end=float(e.end),
                               plan_id=e.plan_id, message=e.message), e.t, e.frame_id)
    msg.attitude = quaternion(e.attitude)
    msg.direction = vector3(e.direction)
    msg.sensor_axis = vector3(e.sensor_axis)
    msg.tolerance = float(e.tolerance)
    if e.pointing is not None:
        msg.pointing = pointing_msg(e.pointing)
    msg.zones = [str(z) for z in e.zones]
    return msg


def mission_event_from_msg(msg) -> types.MissionEvent:
    return types.MissionEvent(
        t=from_time(msg.header.stamp), event=types.MissionEventKind(msg.event), target=msg.target,
        start=float(msg.start), end=float(msg.end), attitude=from_quaternion(msg.attitude),
        direction=from_vector3(msg.direction), sensor_axis=from_vector3(msg.sensor_axis),
        tolerance=float(msg.tolerance), plan_id=msg.plan_id, message=msg.message,
        frame_id=msg.header.frame_id, pointing=_site_pointing(msg), zones=tuple(getattr(msg, "zones", ())))


def fault_event_msg(e: types.FaultEvent) -> FaultEvent:
    return _header(FaultEvent(component=e.component, index=int(e.index), kind=e.kind, factor=float(e.factor),
                              bias_rad=[float(v) for v in e.bias_rad], bias_rad_s=float(e.bias_rad_s),
                              source=str(e.source)), e.t, e.frame_id)


def fault_event_from_msg(msg) -> types.FaultEvent:
    return types.FaultEvent(t=from_time(msg.header.stamp), component=msg.component, index=int(msg.index),
                            kind=msg.kind, factor=float(msg.factor), bias_rad=tuple(float(v) for v in msg.bias_rad),
                            bias_rad_s=float(msg.bias_rad_s), source=types.FaultSource(msg.source),
                            frame_id=msg.header.frame_id)


def fault_status_msg(s: types.FaultStatus) -> FaultStatus:
    return _header(FaultStatus(fault_id=s.fault_id, component=s.component, index=int(s.index), detector=s.detector,
                               evidence=s.evidence, response=s.response, active=bool(s.active),
                               detected_at=time_msg(s.detected_at)), s.t, s.frame_id)


def fault_status_from_msg(msg) -> types.FaultStatus:
    return types.FaultStatus(t=from_time(msg.header.stamp), fault_id=msg.fault_id, component=msg.component,
                             index=int(msg.index), detector=msg.detector, evidence=msg.evidence,
                             response=msg.response, active=bool(msg.active), detected_at=from_time(msg.detected_at),
                             frame_id=msg.header.frame_id)


def _site_pointing(msg) -> types.PointingMode | None:
    """A mission event's pointing mode: None for a source, and in logs recorded before events had one."""
    pointing = getattr(msg, "pointing", None)
    return pointing_from_msg(pointing) if pointing is not None and pointing.kind else None
