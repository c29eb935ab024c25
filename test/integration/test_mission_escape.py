"""att-mission through the nodes when the last target leaves nothing to wait at: m87 and 3c273 (10 deg
apart) on leo_observatory's real sky; once both are observed the Earth limb comes over the held
attitude and no source of the mission stays clear, so the spacecraft must leave for a park of the
scheduler's sky. The day keeps every zone, checked here from the truth states against the Sun, the
Moon and the Earth's limb recomputed from the sky, apart from the day's own report."""
from __future__ import annotations

import numpy as np
import pytest

from att_msgs_py import convert
from att_msgs_py.log import read_log
from att_msgs_py.topics import MISSION_EVENTS, STATE
from att_msgs_py.types import MissionEventKind as Kind
from att_sim.models import rotations as rot
from att_sim.models.ephemeris import Ephemeris
from helpers.missions import fly_observatory_sources

pytestmark = [pytest.mark.ros, pytest.mark.slow]     # 2400 s of sim time at --rtf max: about a minute
SOURCES = {"m87": 60.0, "3c273": 60.0}
EARTH_RADIUS_M = 6378137.0                          # WGS-84 equatorial, the limb's radius in the suite's zones


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    return fly_observatory_sources(tmp_path_factory.mktemp("escape"), SOURCES)


def test_after_the_last_target_the_spacecraft_parks_at_the_sky_and_keeps_every_zone(flown):
    mission, mcap, report = flown
    assert report["observed"] == 2 and report["missed"] == 0, report["targets"]
    log = read_log(mcap, topics=[STATE, MISSION_EVENTS], keep_messages=[MISSION_EVENTS])
    events = [convert.mission_event_from_msg(m) for m in log[MISSION_EVENTS].messages]
    last_dwell = max(e.end for e in events if e.event == Kind.DWELL)
    parks = [e for e in events if e.event == Kind.PARK and e.start >= last_dwell]
    assert parks and all(e.target.startswith("sky_") for e in parks), [(e.event, e.target) for e in events]
    # every zone kept over the whole day, recomputed from the truth states
    t, q = np.asarray(log[STATE]["header.stamp"]), np.asarray(log[STATE]["attitude"])
    r = np.asarray(log[STATE]["position"])
    boresight = np.einsum("nij,j->ni", rot.dcm_NB(q), mission.sensor_axis)
    sky = Ephemeris(mission.scenario.epoch, mission.scenario.orbit_model)
    zones = {z.body: z for z in mission.zones}
    for body, direction in (("sun", sky.sun_direction(t)), ("moon", sky.moon_direction(t))):
        angle = np.arccos(np.clip(np.einsum("ni,ni->n", boresight, direction), -1, 1))
        assert angle.min() > zones[body].half_angle, body
    assert "earth_limb" in zones              # the limb: the half-angle beyond the Earth's apparent radius
    nadir = -r / np.linalg.norm(r, axis=1)[:, None]
    earth_radius = np.arcsin(np.clip(EARTH_RADIUS_M / np.linalg.norm(r, axis=1), -1, 1))
    angle = np.arccos(np.clip(np.einsum("ni,ni->n", boresight, nadir), -1, 1))
    assert (angle - earth_radius).min() > zones["earth_limb"].half_angle
    assert report["min_margin_deg"] > 0.0
