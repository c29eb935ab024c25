"""Names and types of every suite topic, service and action, in one place (no ROS needed: the
QoS profiles that go with them are in :mod:`att_msgs_py.qos`)."""
from __future__ import annotations

import importlib

STATE = "/spacecraft/state"
COMMAND = "/actuator/command"
CONTROLLER_STATUS = "/controller/status"
PLANS = "/planner/plans"
CLOCK = "/clock"

PLAN_MANEUVER = "/planner/plan_maneuver"
PLAN_SCHEDULE = "/planner/plan_schedule"
SET_CONTROLLER_MODE = "/controller/set_mode"
RESET_SIMULATOR = "/simulator/reset"
EXECUTE_MANEUVER = "/controller/execute"

# Topic -> ROS type name of everything the recorder writes.
RECORDED = {
    CLOCK: "rosgraph_msgs/msg/Clock",
    STATE: "att_msgs/msg/SpacecraftState",
    COMMAND: "att_msgs/msg/ActuatorCommand",
    CONTROLLER_STATUS: "att_msgs/msg/ControllerStatus",
    PLANS: "att_msgs/msg/ManeuverPlan",
}


def message_class(type_name: str):
    """Message class of ``pkg/msg/Type``."""
    pkg, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{pkg}.{kind}"), name)
