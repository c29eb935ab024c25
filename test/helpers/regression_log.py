"""The regression log ``test/data/swift_short.mcap`` and what it holds.

Recorded by the suite (``test/data/make_fixture.py`` regenerates it when the format changes on
purpose): a 45° keep-out maneuver of the swift_demo spacecraft, states and commands at 10 Hz, the
sensors at their rates and the estimate the controller flew on.
"""
import math
from pathlib import Path

from att_msgs_py import topics
from att_sim.models import rotations as rot

FIXTURE = Path(__file__).parents[1] / "data" / "swift_short.mcap"
# a channel for every recorded topic; no message on those the fixture's run never publishes on (no
# mission, no injected or detected fault, no coarse Sun sensors on swift_demo)
SILENT_TOPICS = {topics.MISSION_EVENTS, topics.BORESIGHT_FIX, topics.SUBSATELLITE_FIX, topics.TARGET_FIX,
                 topics.SIM_FAULTS, topics.CONTROLLER_FAULTS, topics.ESTIMATOR_FAULTS, topics.SUN_SENSORS}
CHANNEL_TYPES = dict(topics.RECORDED)                                                     # a channel each
TOPIC_TYPES = {t: name for t, name in CHANNEL_TYPES.items() if t not in SILENT_TOPICS}    # with messages
STATE_FIELDS = {"header.stamp", "header.frame_id", "body_frame_id", "attitude", "body_rate", "wheel_speeds",
                "wheel_torques", "magnetic_field_body", "dipole", "applied_torque", "position", "command_timeout"}
GOAL = rot.from_axis_angle([0, 1, 0], math.radians(-45))      # the fixture's maneuver (make_fixture.py)
