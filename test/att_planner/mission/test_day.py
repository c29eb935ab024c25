"""The day's table from a log's events and truth states: a dwell held within the
tolerance is observed; one that drifts, one a zone covers, one the log cuts short, and a miss are
not, each with why; a ground site's dwell is judged along its moving line of sight."""
import math
from datetime import UTC, datetime

import numpy as np
import pytest

from att_msgs_py.types import MissionEvent, MissionEventKind
from att_planner.mission.day import target_table
from att_planner.mission.ground import GroundTrack, site_mode
from att_planner.mission.targets import Site, pointing_attitude
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

EPOCH = datetime(2026, 12, 21, tzinfo=UTC)
SCENARIO = scen.load("leo_observatory")                     # its epoch is EPOCH
SENSOR = np.array([0.0, 1.0, 0.0])
TOL = math.radians(0.05)


def dwell(name, start, end, direction):
    return MissionEvent(start, MissionEventKind.DWELL, name, start, end, pointing_attitude(SENSOR, direction),
                        np.asarray(direction, float), SENSOR, TOL)


def test_a_site_is_judged_along_its_moving_line_of_sight():
    """Singapore's pass at 6700-6840 s: the tracking law's attitudes are observed with no error; the
    attitude of the pass's start held still drifts off the site by degrees."""
    site = Site("singapore", math.radians(1.35), math.radians(103.82), 0.0, 60.0)
    track = GroundTrack(SCENARIO, site, site_mode(site, SENSOR, [0.0, 0.0, 1.0], "velocity"), math.radians(30))
    t = np.arange(6700.0, 6840.0, 1.0)
    assert track.elevation(t).min() >= math.radians(30)
    tracked, held = track.attitudes(t), np.broadcast_to(track.attitudes(t[0])[0], (t.size, 4))
    event = MissionEvent(6700.0, MissionEventKind.DWELL, "singapore", 6710.0, 6830.0, tracked[10],
                         track.line_of_sight(6710.0)[0], SENSOR, TOL, pointing=track.mode)
    for q, observed in ((tracked, True), (held, False)):
        row = target_table([event], t, q, np.ones((t.size, 1)), SCENARIO)[0]
        assert row["observed"] is observed
        assert (row["pointing_error_deg"] < 1e-5) if observed else (row["pointing_error_deg"] > 1.0)


def test_each_dwell_is_judged_from_the_truth():
    t = np.arange(0.0, 400.0, 0.2)
    a, b, c = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    q = np.empty((t.size, 4))
    q[t < 100] = pointing_attitude(SENSOR, a)
    drift = (t >= 100) & (t < 200)                         # b's boresight drifts 0.001 deg/s: 0.09 deg at its end
    q_b = pointing_attitude(SENSOR, b)
    q[drift] = [rot.multiply(q_b, rot.from_axis_angle([1, 0, 0], math.radians(0.001 * (x - 100)))) for x in t[drift]]
    q[t >= 200] = pointing_attitude(SENSOR, c)
    margins = np.ones((t.size, 2))
    margins[(t > 250) & (t < 260), 1] = -0.01                          # a zone crosses c's boresight
    events = [dwell("a", 10.0, 90.0, a), dwell("b", 110.0, 190.0, b), dwell("c", 210.0, 290.0, c),
              dwell("d", 300.0, 500.0, c), MissionEvent(0.0, MissionEventKind.MISSED, "e", message="a sun zone"),
              dwell("a", 300.0, 350.0, a)]                             # a target's first dwell is the one judged
    rows = {r["name"]: r for r in target_table(events, t, q, margins, SCENARIO)}
    assert list(rows) == ["a", "b", "c", "d", "e"]
    assert rows["a"]["observed"] and rows["a"]["pointing_error_deg"] < 1e-6
    assert rows["a"]["start"] == "2026-12-21T00:00:10+00:00" and rows["a"]["end_s"] == 90.0
    assert not rows["b"]["observed"] and "tolerance" in rows["b"]["why"]
    assert rows["b"]["pointing_error_deg"] == pytest.approx(0.09, abs=1e-3)
    assert not rows["c"]["observed"] and "zone" in rows["c"]["why"]
    assert not rows["d"]["observed"] and "log ends" in rows["d"]["why"]
    assert not rows["e"]["observed"] and rows["e"]["why"] == "a sun zone" and rows["e"]["start"] is None
