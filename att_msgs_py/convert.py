"""The one place that converts between att_msgs / geometry_msgs messages and numpy.

Nodes call these functions; no other module builds or reads message fields by hand.
Quaternions are geometry_msgs order (x, y, z, w) = numpy order, body-to-inertial.
"""
from __future__ import annotations

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion, Vector3

from att_msgs.msg import KeepOutCone, ManeuverPlan, PlanVerification, SpacecraftState

from att_planner.cones import Cone
from att_planner.problem import ManeuverPlan as PlanData
from att_planner.verify import Verification


def vector3(v) -> Vector3:
    x, y, z = (float(c) for c in np.asarray(v, float).reshape(3))
    return Vector3(x=x, y=y, z=z)


def from_vector3(msg: Vector3) -> np.ndarray:
    return np.array([msg.x, msg.y, msg.z])


def quaternion(q) -> Quaternion:
    x, y, z, w = (float(c) for c in np.asarray(q, float).reshape(4))
    return Quaternion(x=x, y=y, z=z, w=w)


def from_quaternion(msg: Quaternion) -> np.ndarray:
    """Raw components (not normalised: validation decides what to do with the norm)."""
    return np.array([msg.x, msg.y, msg.z, msg.w])


def time_msg(seconds: float) -> Time:
    """Rounded to the nanosecond, carrying into ``sec`` (3.9999999999 s -> 4 s 0 ns, not 3 s 0 ns)."""
    sec, nanosec = divmod(int(round(seconds * 1e9)), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


def from_time(msg: Time) -> float:
    return msg.sec + msg.nanosec * 1e-9


def cone_msg(cone: Cone) -> KeepOutCone:
    return KeepOutCone(name=cone.name, direction=vector3(cone.direction), half_angle=float(cone.half_angle))


def cone_parts(msg: KeepOutCone) -> tuple[np.ndarray, float, str]:
    """Raw (direction, half_angle, name) of a cone message, for validation before a Cone is built."""
    return from_vector3(msg.direction), float(msg.half_angle), msg.name


def state_msg(t: float, x: np.ndarray, *, frame_id: str, body_frame_id: str, wheel_torques=(),
              field_body=(0, 0, 0), dipole=(0, 0, 0), applied_torque=(0, 0, 0), position=(0, 0, 0),
              command_timeout: bool = False) -> SpacecraftState:
    msg = SpacecraftState()
    msg.header.stamp = time_msg(t)
    msg.header.frame_id = frame_id
    msg.body_frame_id = body_frame_id
    msg.attitude = quaternion(x[:4])
    msg.body_rate = vector3(x[4:7])
    msg.wheel_speeds = [float(v) for v in x[7:]]
    msg.wheel_torques = [float(v) for v in wheel_torques]
    msg.magnetic_field_body = vector3(field_body)
    msg.dipole = vector3(dipole)
    msg.applied_torque = vector3(applied_torque)
    msg.position = vector3(position)
    msg.command_timeout = bool(command_timeout)
    return msg


def state_arrays(msg: SpacecraftState) -> dict:
    """Numpy view of a state message: t, q, omega, wheel_speeds, field_body, dipole, ..."""
    return {
        "t": from_time(msg.header.stamp),
        "q": from_quaternion(msg.attitude),
        "omega": from_vector3(msg.body_rate),
        "wheel_speeds": np.asarray(msg.wheel_speeds, float),
        "wheel_torques": np.asarray(msg.wheel_torques, float),
        "field_body": from_vector3(msg.magnetic_field_body),
        "dipole": from_vector3(msg.dipole),
        "applied_torque": from_vector3(msg.applied_torque),
        "position": from_vector3(msg.position),
    }


def verification_msg(v: Verification) -> PlanVerification:
    return PlanVerification(
        final_attitude_error=v.final_attitude_error, final_rate=v.final_rate,
        min_cone_margin=v.min_cone_margin, cone_margins=[float(m) for m in v.cone_margins],
        torque_ratio=v.torque_ratio, wheel_speed_ratio=v.wheel_speed_ratio, rate_max=v.rate_max,
        dense_samples=int(v.dense_samples))


def plan_msg(plan: PlanData, *, plan_id: str, frame_id: str, spacecraft: str, sensor_axis, cones,
             verification: Verification | None, control_kind: str = "body_torque") -> ManeuverPlan:
    msg = ManeuverPlan()
    msg.header.frame_id = frame_id
    msg.plan_id = plan_id
    msg.method = plan.method
    msg.status = plan.status
    msg.message = plan.message
    msg.spacecraft = spacecraft
    msg.duration = float(plan.duration)
    msg.control_kind = control_kind
    msg.interpolation = plan.interpolation
    msg.times = [float(v) for v in plan.t]
    msg.attitudes = [quaternion(q) for q in plan.q]
    msg.rates = [vector3(w) for w in plan.omega]
    msg.torques = [vector3(u) for u in plan.torque]
    msg.sensor_axis = vector3(sensor_axis)
    msg.cones = [cone_msg(c) for c in cones]
    if verification is not None:
        msg.verification = verification_msg(verification)
    msg.solve_seconds = float(plan.solve_seconds)
    return msg


def plan_arrays(msg: ManeuverPlan) -> dict:
    """Numpy view of a plan message: t (K,), q (K,4), omega (K,3), torque (K,3) and metadata."""
    return {
        "plan_id": msg.plan_id,
        "method": msg.method,
        "status": msg.status,
        "control_kind": msg.control_kind,
        "interpolation": msg.interpolation,
        "duration": msg.duration,
        "t": np.asarray(msg.times, float),
        "q": np.array([from_quaternion(q) for q in msg.attitudes]).reshape(-1, 4),
        "omega": np.array([from_vector3(w) for w in msg.rates]).reshape(-1, 3),
        "torque": np.array([from_vector3(u) for u in msg.torques]).reshape(-1, 3),
        "sensor_axis": from_vector3(msg.sensor_axis),
        "cones": [Cone(*cone_parts(c)[:2], c.name) for c in msg.cones],
    }
