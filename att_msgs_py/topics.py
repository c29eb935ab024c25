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
BORESIGHT_FIX = "/mission/boresight_fix"     # att-mission of ground sites: the boresight's ground point
SUBSATELLITE_FIX = "/mission/subsatellite_fix"   # ... and the sub-satellite point, for a map
TARGET_FIX = "/mission/target_fix"           # ... and the site slewed to or imaged
SIM_FAULTS = "/simulator/faults"             # every hardware fault the truth started (evaluation only)
CONTROLLER_FAULTS = "/controller/faults"     # the faults the controller's monitor detected and its responses
ESTIMATOR_FAULTS = "/estimator/faults"       # the sensor faults the estimator's monitor detected

PLAN_MANEUVER = "/planner/plan_maneuver"
PLAN_SCHEDULE = "/planner/plan_schedule"
IMAGE_TARGET = "/planner/image_target"
IMAGE_STRIP = "/planner/image_strip"
SET_CONTROLLER_MODE = "/controller/set_mode"
RESET_SIMULATOR = "/simulator/reset"
HOLD_SIMULATOR = "/simulator/hold"
INJECT_FAULT = "/simulator/inject_fault"
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
    BORESIGHT_FIX: "sensor_msgs/msg/NavSatFix",
    SUBSATELLITE_FIX: "sensor_msgs/msg/NavSatFix",
    TARGET_FIX: "sensor_msgs/msg/NavSatFix",
    SIM_FAULTS: "att_msgs/msg/FaultEvent",
    CONTROLLER_FAULTS: "att_msgs/msg/FaultStatus",
    ESTIMATOR_FAULTS: "att_msgs/msg/FaultStatus",
}


# What each topic, service and action carries (the documentation's node pages are generated from this).
ABOUT = {
    STATE: "the truth state at `publish_rate_Hz` (sim time): attitude, rate, wheel speeds, field, position, "
           "`command_timeout`",
    CLOCK: "sim time (the controller reads it itself, for its clock-skew check)",
    COMMAND: "wheel torques, dipole or body torque, and the mode",
    CONTROLLER_STATUS: "mode, plan progress, guidance law, reference, attitude error, dumping, watchdog state",
    PLANS: "every plan returned (latched), for the controller and the log",
    IMU: "gyro: mean body rate over the sample interval and its covariance; orientation and acceleration "
         "not provided (covariance[0] = -1)",
    STAR_TRACKER: "sensor-frame attitude, validity and status (Sun, Earth, Moon, excluded, rate), covariance; "
                  "stamped at the instant measured",
    MAGNETOMETER: "field in body axes (T) and its covariance",
    SUN_SENSORS: "the coarse sun sensors' cosine detector outputs",
    WHEEL_SPEEDS: "tachometers: `wheel_i` velocity relative to the body",
    SENSOR_TRUTH: "the gyro's and magnetometer's actual biases, for evaluation only (no flight node reads it)",
    ESTIMATE: "attitude, rate, gyro bias, their covariances, health",
    TF: "the body frame under the inertial frame (rotation: the truth attitude, no translation) at `tf_rate_Hz`; "
        "with an epoch also the Earth-fixed frame `itrs`",
    SIM_MARKERS: "the zones as cones at their current directions (keep-out red, keep-in green), the sensor "
                 "boresights, Sun, Moon and Earth directions, at `marker_rate_Hz`",
    ZONE_MARGINS: "each scenario zone's truth margin (rad, >= 0 clear) and the smallest, at `tf_rate_Hz`",
    PLAN_MARKERS: "the latest plan's boresight path (inertial frame, latched)",
    MISSION_EVENTS: "a mission's decisions, slews, dwells, parks and missed targets with why (latched)",
    BORESIGHT_FIX: "`att-mission` of ground sites: where the sensor axis meets the WGS-84 ellipsoid (truth state; "
                   "status NO_FIX while it misses the Earth), once per s of sim time, for a map",
    SUBSATELLITE_FIX: "`att-mission` of ground sites: the sub-satellite point and the spacecraft's altitude (truth "
                      "state), once per s of sim time, for a map",
    TARGET_FIX: "`att-mission` of ground sites: the site of each slew and dwell as it is reported (latched)",
    SIM_FAULTS: "each hardware fault the truth started: component, index, kind, parameters, source (latched; "
                "for evaluation only, no flight node reads it)",
    CONTROLLER_FAULTS: "each fault the controller's monitor declared or cleared (with `fault_table`): fault id, "
                       "component and index isolated, detector, evidence, response, detection time",
    ESTIMATOR_FAULTS: "each sensor fault the estimator's monitor declared or cleared (with `fault_table`): a star "
                      "tracker, the gyro or the magnetometer, its evidence and response (the controller acts on "
                      "safe mode)",
    INJECT_FAULT: "inject a hardware fault into the truth at a sim time (refused unless the scenario sets "
                  "`allow_fault_injection`)",
    PLAN_MANEUVER: "plan a rest-to-rest maneuver (or one ending on a pointing law), verified and signed",
    PLAN_SCHEDULE: "the fastest tour through target attitudes, each flown through or observed (held for its "
                   "dwell, within its window, never while a zone covers it)",
    IMAGE_TARGET: "plan a slew that ends on a ground site at its line of sight's rate, for a dwell seen above the "
                  "instrument's minimum elevation (docs/strips.md), verified and signed",
    IMAGE_STRIP: "plan a slew that ends on a strip's first point at its scan's rate (the strip then followed at its "
                 "scan speed, the detector across it; docs/strips.md), verified and signed",
    SET_CONTROLLER_MODE: "idle, magnetorquer PD, safe or pointing (a `PointingMode`); momentum dumping on or off",
    RESET_SIMULATOR: "reset attitude, rate, wheel speeds and orbit phase",
    HOLD_SIMULATOR: "hold sim time (true) or let it run again (false); a hold ends after `max_hold_s` of wall time",
    EXECUTE_MANEUVER: "execute a plan (by id or inline), with feedback while it runs",
}


def message_class(type_name: str):
    """Message class of ``pkg/msg/Type``."""
    pkg, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{pkg}.{kind}"), name)
