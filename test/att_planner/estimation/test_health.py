"""The health monitor: INITIALISING, DIVERGED, CONVERGED and PROPAGATING as its rules say, the gate's
rejections counted and ``lost_after`` in a row losing the estimate."""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import Health
from att_planner.estimation import mekf
from att_planner.estimation.health import HealthMonitor
from att_planner.estimation.history import Record


def state(attitude_sigma: float) -> mekf.FilterState:
    P = np.diag([attitude_sigma**2, (attitude_sigma / 2) ** 2, 0.0, 1e-12, 1e-12, 1e-12])
    return mekf.FilterState(0.0, np.array([0.0, 0.0, 0.0, 1.0]), np.zeros(3), P)


def test_health_follows_the_fixes_and_the_attitude_sigma():
    m = HealthMonitor(propagate_timeout=2.0, converged_attitude_sigma=3e-4, lost_after=2, has_trackers=True)
    assert m.health(0.0, None) == Health.INITIALISING
    m.initialised(Record(1.0, "tracker", None))
    good, wide = state(0.99e-4), state(1.01e-4)            # 3σ of the largest axis just inside, just outside
    assert m.health(3.0, good) == Health.CONVERGED and m.health(3.0, wide) == Health.PROPAGATING
    assert m.health(3.01, good) == Health.PROPAGATING     # no fix for more than propagate_timeout
    m.accepted(Record(2.5, "sun", None))                  # a vector is not a fix with trackers on board
    assert m.last_fix == 1.0 and m.health(3.01, good) == Health.PROPAGATING
    m.accepted(Record(2.5, "tracker", None))
    assert m.last_fix == 2.5 and m.health(3.01, good) == Health.CONVERGED
    m.keep_largest_attitude_variance(good, 1e-6)          # a batch's value for this state is used
    assert m.health(3.01, good) == Health.PROPAGATING
    m.lose(3.1, "test")
    assert m.health(3.2, None) == Health.DIVERGED and m.lost_at == 3.1
    assert "estimate diverged (test): reinitialising" in m.take_report().notes
    without = HealthMonitor(2.0, 3e-4, 2, has_trackers=False)
    without.accepted(Record(2.5, "sun", None))            # without trackers a vector is a fix
    assert without.last_fix == 2.5


def test_tracker_rejections_in_a_row_lose_the_estimate_and_an_acceptance_resets_them():
    m = HealthMonitor(2.0, 3e-4, lost_after=2, has_trackers=True)
    x = state(1e-4)
    rejected, accepted = mekf.Update(x, False, 50.0), mekf.Update(x, True, 1.0)
    assert not m.judged(Record(1.0, "tracker", None), rejected, 21.1)
    assert not m.judged(Record(1.1, "tracker", None), accepted, 21.1)          # resets the run
    assert not m.judged(Record(1.2, "tracker", None), rejected, 21.1)
    assert not m.judged(Record(1.25, "sun", None), rejected, 21.1)              # a vector: counted, not in the run
    r = Record(1.3, "tracker", None)
    assert m.judged(r, rejected, 21.1) and r.accepted is False
    report = m.take_report()
    assert m.rejected == 4 and report.rejected == 4 and m.rejected_in_a_row == 0
    assert any("d² = 50 > 21.1" in n for n in report.notes) and m.take_report().rejected == 0
    m.restart()
    assert m.rejected == 4 and m.last_fix == -math.inf and not m.diverged
