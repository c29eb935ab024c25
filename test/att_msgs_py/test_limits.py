"""The size caps checked on a message before it is read: every table's field exists on its message
type, each cap refuses one element above it (SIZE_LIMIT naming the field) and passes the cap itself,
and the caps the receivers check after conversion are these same values."""
from __future__ import annotations

import time

import pytest
from sensor_msgs.msg import Imu, JointState, MagneticField

from att_msgs.action import ExecuteManeuver
from att_msgs.msg import ActuatorCommand, AttitudeEstimate, CoarseSunSensors, ManeuverPlan, SpacecraftState, StarTracker
from att_msgs.srv import InjectFault, PlanManeuver, PlanSchedule, ResetSimulator, SetControllerMode
from att_msgs_py import limits, validation
from att_msgs_py.errors import ErrorCode

TABLES = {
    "PLAN_MANEUVER": PlanManeuver.Request, "PLAN_SCHEDULE": PlanSchedule.Request, "MANEUVER_PLAN": ManeuverPlan,
    "EXECUTE_MANEUVER": ExecuteManeuver.Goal, "SET_CONTROLLER_MODE": SetControllerMode.Request,
    "SPACECRAFT_STATE": SpacecraftState, "ATTITUDE_ESTIMATE": AttitudeEstimate, "ACTUATOR_COMMAND": ActuatorCommand,
    "RESET_SIMULATOR": ResetSimulator.Request, "INJECT_FAULT": InjectFault.Request, "JOINT_STATE": JointState,
    "STAR_TRACKER": StarTracker,
    "SUN_SENSORS": CoarseSunSensors, "HEADER_ONLY": Imu,
}


def _element(msg, path: str):
    """An element suited to the sequence field ``path`` of ``msg`` (a default message, a float, a string)."""
    parent = msg
    for part in path.split(".")[:-1]:
        parent = getattr(parent, part)
    name = path.split(".")[-1]
    slot = dict(zip(parent.get_fields_and_field_types(), parent.SLOT_TYPES))[name]
    value_type = getattr(slot, "value_type", None)
    if value_type is None:
        return "x"                                            # a string
    if hasattr(value_type, "namespaces"):                     # a message: its class
        module = __import__(".".join(value_type.namespaces), fromlist=[value_type.name])
        return getattr(module, value_type.name)()
    if "String" in type(value_type).__name__:
        return "x"
    return {"octet": b"\0", "uint8": 0}.get(getattr(value_type, "typename", ""), 0.0)


def _fill(msg, path: str, n: int):
    """``msg`` with ``n`` elements (or characters) in the field ``path`` (no ``[]`` in it)."""
    parent = msg
    for part in path.split(".")[:-1]:
        parent = getattr(parent, part)
    name = path.split(".")[-1]
    current = getattr(parent, name)
    if isinstance(current, str):
        setattr(parent, name, "x" * n)
    elif isinstance(current, bytes):
        setattr(parent, name, bytes(n))
    else:
        setattr(parent, name, [_element(msg, path)] * n)
    return msg


def _plain_fields(table: dict) -> list[tuple[str, int]]:
    return [(path, cap) for path, cap in table.items() if "[]" not in path]


CASES = [(table, kind, path, cap) for table, kind in TABLES.items()
         for path, cap in _plain_fields(getattr(limits, table))]


@pytest.mark.parametrize("table, kind, path, cap", CASES, ids=[f"{t}:{p}" for t, _, p, _ in CASES])
def test_each_cap_refuses_one_above_it_naming_the_field_and_passes_the_cap(table, kind, path, cap):
    caps = getattr(limits, table)
    assert limits.issue(_fill(kind(), path, cap), caps, "m") is None
    err = limits.issue(_fill(kind(), path, cap + 1), caps, "m")
    assert err is not None and err.code == ErrorCode.SIZE_LIMIT
    assert err.message.startswith(f"m.{path} has {cap + 1} ") and err.message.endswith(f"at most {cap}")


def test_every_element_of_a_sequence_is_held_to_its_field_cap():
    req = PlanManeuver.Request()
    req.zones = [_element(req, "zones") for _ in range(3)]
    req.zones[2].name = "z" * (limits.MAX_NAME_LENGTH + 1)
    err = limits.issue(req, limits.PLAN_MANEUVER)
    assert err.code == ErrorCode.SIZE_LIMIT and err.message.startswith("zones[].name has 129 characters")


def test_an_inline_plan_is_held_to_the_plan_caps_under_its_goal():
    goal = ExecuteManeuver.Goal(use_inline_plan=True)
    goal.plan.times = [0.0] * (limits.MAX_PLAN_SAMPLES + 1)
    assert limits.issue(goal, limits.EXECUTE_MANEUVER) is None
    err = limits.issue(goal, limits.inline_plan())
    assert err.message.startswith(f"plan.times has {limits.MAX_PLAN_SAMPLES + 1} entries")


def test_a_hundred_thousand_zones_are_refused_by_a_len_not_by_reading_them():
    req = PlanManeuver.Request()
    req.zones = [_element(req, "zones") for _ in range(100_000)]
    start = time.process_time()
    for _ in range(100):
        err = limits.issue(req, limits.PLAN_MANEUVER)
    per_check = (time.process_time() - start) / 100
    assert err.message == f"zones has 100000 entries; at most {limits.MAX_ZONES}"
    assert per_check < 0.01            # one len(): microseconds; reading the zones takes about a second


def test_the_receivers_check_the_same_declared_caps():
    from att_planner.control import plan_checks
    from att_planner.mission import schema as target_schema
    from att_planner.service import real_sky, requests

    assert validation.MAX_PLAN_SAMPLES is limits.MAX_PLAN_SAMPLES and validation.MAX_PLAN_BYTES is limits.MAX_PLAN_BYTES
    assert (requests.MAX_CONES, requests.MAX_OPTIONS, requests.MAX_TARGETS) == (16, 16, 20)
    assert plan_checks.MAX_CONES is limits.MAX_CONES and plan_checks.MAX_ZONES is limits.MAX_ZONES
    assert real_sky.MAX_ZONES is limits.MAX_ZONES and real_sky.MAX_TLE_LENGTH is limits.MAX_TLE_LENGTH
    assert target_schema.MAX_TARGETS is requests.MAX_TARGETS is limits.MAX_TARGETS     # a target list's cap
    assert any(getattr(m, "max_length", None) == limits.MAX_TARGETS
               for m in target_schema.InertialTargets.model_fields["targets"].metadata)


def test_magnetometer_has_only_its_header_to_cap():
    msg = MagneticField()
    msg.header.frame_id = "f" * 129
    assert limits.issue(msg, limits.HEADER_ONLY, "magnetometer").message.startswith(
        "magnetometer.header.frame_id has 129 characters")
