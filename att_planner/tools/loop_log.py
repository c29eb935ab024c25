"""An MCAP of an in-process closed loop (:class:`~att_planner.tools.closed_loop.ClosedLoop`): every
message the nodes would publish — the sensors, the state, the faults the truth started, the
estimate, the commands and the controller's status — converted by :mod:`att_msgs_py.convert` and
written in the recorder's rosbag2 layout (:class:`att_msgs_py.log.writer.LogWriter`), stamped with
sim time. ``att-review`` and ``read_log`` read it as any recording.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from rclpy.serialization import serialize_message

from att_msgs_py import convert, qos, topics
from att_msgs_py.log.writer import LogWriter
from att_msgs_py.types import Plan

MESSAGES = {
    topics.IMU: convert.gyro_msg, topics.STAR_TRACKER: convert.star_tracker_msg,
    topics.MAGNETOMETER: convert.magnetometer_msg, topics.SUN_SENSORS: convert.sun_sensors_msg,
    topics.WHEEL_SPEEDS: convert.wheel_speeds_msg, topics.SENSOR_TRUTH: convert.sensor_truth_msg,
    topics.STATE: convert.state_msg, topics.ESTIMATE: convert.estimate_msg, topics.COMMAND: convert.command_msg,
    topics.CONTROLLER_STATUS: convert.controller_status_msg, topics.SIM_FAULTS: convert.fault_event_msg,
}


def open_loop_log(path: Path, plan: Plan | None = None) -> tuple[LogWriter, Callable]:
    """A log at ``path`` with every topic of :data:`MESSAGES` (and ``plan`` on the plans' topic) and the
    tap that writes to it (``ClosedLoop.tap``); close the writer when the loop is done."""
    log = LogWriter(path)
    recorded = qos.recorded_topics()
    for topic in (*MESSAGES, topics.PLANS):
        type_name, profile = recorded[topic]
        log.add_topic(topic, type_name, profile)
    if plan is not None:
        log.write(topics.PLANS, serialize_message(convert.plan_msg(plan)), 0)

    def tap(topic: str, t: float, message) -> None:
        log.write(topic, serialize_message(MESSAGES[topic](message)), int(round(t * 1e9)))

    return log, tap
