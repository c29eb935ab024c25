"""The full log of one run (``att-mc rerun SEED --mcap PATH``): every message the nodes would
publish during the in-process run — the sensors, the state, the estimate, the commands and the
controller's status, plus the plan — converted by :mod:`att_msgs_py.convert` and written in the
recorder's rosbag2 layout (:class:`att_msgs_py.log.writer.LogWriter`), stamped with sim time.

Why in process and not through the nodes: the log is then of exactly the run whose row the
campaign's table holds (same cores, same seed, same order of events, bit for bit); over DDS the
same run differs by the scheduling of the nodes. ``att-review`` and ``read_log`` read it as any
recording.
"""
from __future__ import annotations

from pathlib import Path

from rclpy.serialization import serialize_message

from att_msgs_py import convert, qos, topics
from att_msgs_py.log.writer import LogWriter
from att_planner.tools.monte_carlo.run import Setup, fly

MESSAGES = {
    topics.IMU: convert.gyro_msg, topics.STAR_TRACKER: convert.star_tracker_msg,
    topics.MAGNETOMETER: convert.magnetometer_msg, topics.SUN_SENSORS: convert.sun_sensors_msg,
    topics.WHEEL_SPEEDS: convert.wheel_speeds_msg, topics.SENSOR_TRUTH: convert.sensor_truth_msg,
    topics.STATE: convert.state_msg, topics.ESTIMATE: convert.estimate_msg, topics.COMMAND: convert.command_msg,
    topics.CONTROLLER_STATUS: convert.controller_status_msg,
}


def write_run_log(setup: Setup, seed: int, path: Path, run: int = -1) -> dict:
    """Fly the run of seed ``seed`` with every message written to the MCAP at ``path``; its row."""
    log = LogWriter(path)
    recorded = qos.recorded_topics()
    for topic in (*MESSAGES, topics.PLANS):
        type_name, profile = recorded[topic]
        log.add_topic(topic, type_name, profile)
    plan = convert.plan_msg(setup.plan)
    log.write(topics.PLANS, serialize_message(plan), 0)

    def tap(topic: str, t: float, message) -> None:
        log.write(topic, serialize_message(MESSAGES[topic](message)), int(round(t * 1e9)))
    try:
        return fly(setup, seed, run, tap=tap)
    finally:
        log.close()
