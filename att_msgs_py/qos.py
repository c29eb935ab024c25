"""QoS of every suite topic and service (nodes, recorder, replay)."""
from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from att_msgs_py import topics

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
# Mission events: reliable and latched, deep enough for a day's events to reach a recorder that starts late.
MISSION_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
CLOCK_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.VOLATILE)


def recorded_topics() -> dict[str, tuple[str, QoSProfile]]:
    """Topic -> (ROS type name, QoS) for everything the recorder writes."""
    qos = {topics.CLOCK: CLOCK_QOS, topics.PLANS: LATCHED_QOS, topics.PLAN_MARKERS: LATCHED_QOS,
           topics.MISSION_EVENTS: MISSION_QOS, topics.TARGET_FIX: MISSION_QOS, topics.SIM_FAULTS: MISSION_QOS,
           topics.CONTROLLER_FAULTS: MISSION_QOS, topics.ESTIMATOR_FAULTS: MISSION_QOS}
    return {topic: (type_name, qos.get(topic, STREAM_QOS)) for topic, type_name in topics.RECORDED.items()}
