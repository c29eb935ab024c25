"""Names and types of every suite topic, service and action, in one place (no ROS needed: the
QoS profiles that go with them are in :mod:`att_msgs_py.qos`)."""
from __future__ import annotations

import importlib

STATE = "/spacecraft/state"
COMMAND = "/actuator/command"
CONTROLLER_STATUS = "/controller/status"
PLANS = "/planner/plans"
CLOCK = "/clock"
IMU = "/sensors/imu"
STAR_TRACKER = "/sensors/star_tracker"
MAGNETOMETER = "/sensors/magnetometer"
SUN_SENSORS = "/sensors/sun_sensors"
WHEEL_SPEEDS = "/sensors/wheel_speeds"
SENSOR_TRUTH = "/simulator/sensor_truth"
ESTIMATE = "/estimator/attitude"
TF = "/tf"                                   # the 3D view: the body frame under the inertial one
SIM_MARKERS = "/simulator/markers"           # zones, boresights, Sun/Moon/Earth directions
ZONE_MARGINS = "/simulator/zone_margins"     # the zones' truth margins, for plots
PLAN_MARKERS = "/planner/plan_markers"       # the latest plan's boresight path
MISSION_EVENTS = "/mission/events"           # att-mission's decisions, slews, dwells and missed targets

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
    IMU: "sensor_msgs/msg/Imu",
    STAR_TRACKER: "att_msgs/msg/StarTracker",
    MAGNETOMETER: "sensor_msgs/msg/MagneticField",
    SUN_SENSORS: "att_msgs/msg/CoarseSunSensors",
    WHEEL_SPEEDS: "sensor_msgs/msg/JointState",
    SENSOR_TRUTH: "att_msgs/msg/SensorTruth",
    ESTIMATE: "att_msgs/msg/AttitudeEstimate",
    TF: "tf2_msgs/msg/TFMessage",
    SIM_MARKERS: "visualization_msgs/msg/MarkerArray",
    ZONE_MARGINS: "att_msgs/msg/ZoneMargins",
    PLAN_MARKERS: "visualization_msgs/msg/MarkerArray",
    MISSION_EVENTS: "att_msgs/msg/MissionEvent",
}


def message_class(type_name: str):
    """Message class of ``pkg/msg/Type``."""
    pkg, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{pkg}.{kind}"), name)
