"""att-mission through the nodes: a short mission of two sources on leo_observatory's
real sky, flown by the simulator, estimator, controller and planner nodes as ``--rtf max`` flies it
(as fast as the lockstep goes, sim time held while the planner plans); the log holds every event
and plan, each source is held for its dwell on target (checked here from the truth states against
the source's direction, with the Sun and Moon from the sky, apart from the day's own report), and the
review draws the day and lists the targets. The two sources, m87 and 3c273 (10 deg apart), leave nothing
to wait at once both are observed: the Earth limb comes over the held attitude and no source of the
mission stays clear, so the spacecraft must leave for a park of the scheduler's sky, keeping every zone
(checked from the truth states against the Sun, the Moon and the Earth's limb recomputed from the sky)."""
from __future__ import annotations

import re

import numpy as np
import pytest

from att_msgs_py import convert
from att_msgs_py.log import read_log
from att_msgs_py.topics import MISSION_EVENTS, PLANS, STATE
from att_msgs_py.types import MissionEventKind as Kind
from att_planner.tools.review import review
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.ephemeris import Ephemeris
from helpers.missions import fly_observatory_sources

pytestmark = [pytest.mark.ros, pytest.mark.slow]     # 2400 s of sim time at --rtf max: about a minute
SOURCES = {"m87": 60.0, "3c273": 60.0}
EARTH_RADIUS_M = 6378137.0                          # WGS-84 equatorial, the limb's radius in the suite's zones


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    return fly_observatory_sources(tmp_path_factory.mktemp("mission"), SOURCES)


def test_both_sources_are_observed_within_the_tolerance(flown):
    mission, _, report = flown
    assert report["observed"] == 2 and report["missed"] == 0, report["targets"]
    for row in report["targets"]:
        assert row["pointing_error_deg"] <= 0.05 and row["end_s"] - row["start_s"] == SOURCES[row["name"]]
    assert report["min_margin_deg"] > 0.0 and 0.0 < report["peak_wheel_ratio"] < 1.0
    assert report["sim_seconds"] >= mission.horizon - 1.0 and report["rtf"] > 1.0     # the day flown whole


def test_the_log_holds_the_events_plans_and_the_dwells_on_target(flown):
    mission, mcap, _ = flown
    log = read_log(mcap, topics=[STATE, PLANS, MISSION_EVENTS], keep_messages=[PLANS, MISSION_EVENTS])
    events = [convert.mission_event_from_msg(m) for m in log[MISSION_EVENTS].messages]
    kinds = [e.event for e in events]
    assert kinds[0] == Kind.SCHEDULED and kinds[-1] == Kind.ENDED
    # every slew to a source the controller flew to its end is followed by its dwell (a plan that came
    # back after its start is refused without a slew event: the sim does not wait for the planner; a
    # slew to a park has no dwell)
    refused = {e.plan_id for e in events if e.event == Kind.REFUSED and e.plan_id}
    parks = {e.target for e in events if e.event == Kind.PARK}
    flown_slews = [e.target for e in events if e.event == Kind.SLEW and e.plan_id not in refused
                   and e.target not in parks]
    assert set(flown_slews) == set(SOURCES)
    assert [e.target for e in events if e.event == Kind.DWELL] == flown_slews
    plan_ids = {m.plan_id for m in log[PLANS].messages}
    assert {e.plan_id for e in events if e.event == Kind.SLEW} <= plan_ids
    t, q = np.asarray(log[STATE]["header.stamp"]), np.asarray(log[STATE]["attitude"])
    sky = Ephemeris(mission.scenario.epoch, mission.scenario.orbit_model)
    zones = {z.body: z for z in mission.scenario.zones}
    dipole = np.asarray(log[STATE]["dipole"])
    for e in (e for e in events if e.event == Kind.DWELL):
        held = (t >= e.start) & (t <= e.end)
        assert held.sum() >= mission.rate * (e.end - e.start) - 1
        assert np.abs(dipole[held]).max() > 0.0                   # held in pointing mode: momentum dumped
        boresight = np.einsum("nij,j->ni", rot.dcm_NB(q[held]), mission.sensor_axis)
        assert np.degrees(np.arccos(np.clip(boresight @ e.direction, -1, 1))).max() <= 0.05
        for body, direction in (("sun", sky.sun_direction(t[held])), ("moon", sky.moon_direction(t[held]))):
            angle = np.arccos(np.clip(np.einsum("ni,ni->n", boresight, direction), -1, 1))
            assert angle.min() > zones[body].half_angle, (e.target, body)


def test_sim_time_stood_still_while_the_planner_planned_and_from_the_end_of_the_day(flown):
    """--rtf max: every plan request was made with sim time held and released at the same instant;
    at the end of the day sim time is held for good, so the log ends at the horizon, not wherever the
    nodes were when they stopped."""
    mission, mcap, _ = flown
    text = (mcap.parent / "simulator.log").read_text()
    held = [float(t) for t in re.findall(r"sim time held at t = ([0-9.]+) s", text)]
    released = [float(t) for t in re.findall(r"sim time released at t = ([0-9.]+) s", text)]
    log = read_log(mcap, topics=[PLANS, STATE])
    assert len(held) >= 3 and held[:-1] == released, (held, released)
    assert len(held) - 1 >= len(log[PLANS]) > 0
    assert mission.horizon <= held[-1] == log[STATE]["header.stamp"][-1] < mission.horizon + 120.0, held


def test_the_review_draws_the_day_and_lists_the_targets(flown):
    _, mcap, _ = flown
    result = review(mcap, scenario="leo_observatory")
    assert {"mission", "mission sky"} <= set(result.figures)
    assert all(result.figures[k].stat().st_size > 10_000 for k in ("mission", "mission sky"))
    assert result.summary["mission"]["observed"] == 2
    assert all(re.search(rf"^ *{name} +observed from", result.text, re.M) for name in SOURCES), result.text
    assert scen.load("leo_observatory").epoch.isoformat()[:10] in result.text


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
