"""The day's table (issue 17) from a log's events and truth states: a dwell held within the
tolerance is observed; one that drifts, one a zone covers, one the log cuts short, and a miss are
not, each with why."""
import math
from datetime import UTC, datetime

import numpy as np
import pytest

from att_msgs_py.types import MissionEvent, MissionEventKind
from att_planner.mission.day import boresight_errors, target_table
from att_planner.mission.targets import pointing_attitude
from att_sim import rotations as rot

EPOCH = datetime(2026, 12, 21, tzinfo=UTC)
SENSOR = np.array([0.0, 1.0, 0.0])
TOL = math.radians(0.05)


def dwell(name, start, end, direction):
    return MissionEvent(start, MissionEventKind.DWELL, name, start, end, pointing_attitude(SENSOR, direction),
                        np.asarray(direction, float), SENSOR, TOL)


def test_the_boresight_error_is_the_angle_from_the_source():
    d = np.array([0.0, 0.0, 1.0])
    q = pointing_attitude(SENSOR, d)
    tilted = rot.multiply(q, rot.from_axis_angle([1.0, 0.0, 0.0], 0.01))
    assert boresight_errors(np.array([q, tilted]), SENSOR, d) == pytest.approx([0.0, 0.01], abs=1e-9)


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
    rows = {r["name"]: r for r in target_table(events, t, q, margins, EPOCH)}
    assert list(rows) == ["a", "b", "c", "d", "e"]
    assert rows["a"]["observed"] and rows["a"]["pointing_error_deg"] < 1e-6
    assert rows["a"]["start"] == "2026-12-21T00:00:10+00:00" and rows["a"]["end_s"] == 90.0
    assert not rows["b"]["observed"] and "tolerance" in rows["b"]["why"]
    assert rows["b"]["pointing_error_deg"] == pytest.approx(0.09, abs=1e-3)
    assert not rows["c"]["observed"] and "zone" in rows["c"]["why"]
    assert not rows["d"]["observed"] and "log ends" in rows["d"]["why"]
    assert not rows["e"]["observed"] and rows["e"]["why"] == "a sun zone" and rows["e"]["start"] is None
