"""Names, types and QoS of every suite topic and service, in one place (nodes, recorder, replay)."""
from __future__ import annotations

import importlib

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

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

# Streams: reliable, keep the last 1000 (about 10 s of every stream at full speed on a loaded machine: a
# recorder starved of CPU for a while catches up instead of dropping messages).
STREAM_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.VOLATILE)
# Plans: latched so that a controller or recorder that starts later still receives them.
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=20, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
# Services: deep queues so that bursts of requests (100 at once from several clients) are queued,
# not dropped (the ROS default keeps 10).
SERVICE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=500, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.VOLATILE)
CLOCK_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.VOLATILE)


def recorded_topics() -> dict[str, tuple[str, QoSProfile]]:
    """Topic -> (ROS type name, QoS) for everything the recorder writes."""
    return {
        CLOCK: ("rosgraph_msgs/msg/Clock", CLOCK_QOS),
        STATE: ("att_msgs/msg/SpacecraftState", STREAM_QOS),
        COMMAND: ("att_msgs/msg/ActuatorCommand", STREAM_QOS),
        CONTROLLER_STATUS: ("att_msgs/msg/ControllerStatus", STREAM_QOS),
        PLANS: ("att_msgs/msg/ManeuverPlan", LATCHED_QOS),
    }


def message_class(type_name: str):
    """Message class of ``pkg/msg/Type``."""
    pkg, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{pkg}.{kind}"), name)
