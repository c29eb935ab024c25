"""att-mission of Earth observation through the nodes: one ground site on the
leo_observatory orbit (a pass 30 deg high from 1200 s), flown by the simulator, estimator, controller
and planner nodes: the slew arrives at rest on the site's tracking attitude as it rises, the controller blends
into the ground pointing mode over 180 s and follows the site through its dwell. The pointing error is checked
from the truth states against skyfield's line of sight (its own WGS-84 site and SGP4), apart from
the day's report."""
from __future__ import annotations

import numpy as np
import pytest

from att_msgs_py import convert
from att_msgs_py.log import read_log
from att_msgs_py.topics import MISSION_EVENTS, STATE
from att_msgs_py.types import MissionEventKind as Kind
from att_sim.models import rotations as rot
from helpers.independent import site_sight
from helpers.missions import fly_written

pytestmark = [pytest.mark.ros, pytest.mark.slow]     # the module's flight: 85 s of setup
SITE = {"name": "new_guinea", "lat_deg": -4.0, "lon_deg": 145.0, "alt_m": 0.0, "dwell_s": 30.0}


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    out = tmp_path_factory.mktemp("mission_ground")
    return fly_written(out, {"kind": "ground", "scenario": "leo_observatory", "min_elevation_deg": 30.0,
                             "targets": [SITE]},
                       {"sensor_axis": [0, 1, 0], "secondary": "velocity", "secondary_axis": [0, 0, 1],
                        "zones": ["sun", "moon"], "horizon_s": 1700, "start_lead_s": 240, "time_budget_s": 5,
                        "rate_Hz": 2.5,
                        "pointing_tolerance_deg": 0.1, "site_arrival": "at_rest", "handover_blend_s": 180}, rtf=0.0)


def test_the_site_is_observed_within_the_tolerance_in_the_report(flown):
    mission, _, report = flown
    assert report["observed"] == 1 and report["missed"] == 0, report["targets"]
    (row,) = report["targets"]
    assert row["pointing_error_deg"] <= 0.1 and row["end_s"] - row["start_s"] == SITE["dwell_s"]
    assert [z["name"] for z in report["zones"]] == ["sun", "moon"] and report["min_margin_deg"] > 0.0


def test_the_truth_follows_skyfields_line_of_sight_through_the_dwell(flown):
    mission, mcap, report = flown
    log = read_log(mcap, topics=[STATE, MISSION_EVENTS], keep_messages=[MISSION_EVENTS])
    events = [convert.mission_event_from_msg(m) for m in log[MISSION_EVENTS].messages]
    (dwell,) = [e for e in events if e.event == Kind.DWELL]
    assert dwell.pointing is not None and dwell.pointing.kind == "ground" and dwell.zones == ("sun", "moon")
    t, q = np.asarray(log[STATE]["header.stamp"]), np.asarray(log[STATE]["attitude"])
    held = (t >= dwell.start) & (t <= dwell.end)
    assert held.sum() >= mission.rate * SITE["dwell_s"] - 1
    sight = site_sight(mission.scenario.epoch.isoformat(), report["tle"], SITE["lat_deg"], SITE["lon_deg"],
                       SITE["alt_m"], t[held])
    boresight = np.einsum("nij,j->ni", rot.dcm_NB(q[held]), mission.sensor_axis)
    error = np.degrees(np.arccos(np.clip(np.einsum("ni,ni->n", boresight, sight), -1, 1)))
    assert error.max() <= 0.1
    moved = np.degrees(np.arccos(np.clip(sight[0] @ sight[-1], -1, 1)))
    assert moved > 5.0                                    # the site moved across the sky: it was followed
