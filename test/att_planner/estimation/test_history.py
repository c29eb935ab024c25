"""The measurement history: where a late measurement sends the filter back to, the steps that rebuild
the states after it, and what is forgotten (by age, and before a loss)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_planner.estimation.history import MeasurementHistory, Record
from att_planner.estimation.mekf import FilterState


def state(t: float) -> FilterState:
    return FilterState(t, np.array([0.0, 0.0, 0.0, 1.0]), np.zeros(3), np.eye(6))


def history_at(times) -> MeasurementHistory:
    """Gyro samples at ``times`` (rate t, saturated after 0.3 s) with a state kept after each."""
    h = MeasurementHistory(span=1.0, max_gyro_gap=0.5)
    for t in times:
        h.keep_gyro(t, np.full(3, t), t > 0.3)
        h.snapshots.append((t, state(t)))
    return h


def test_a_late_record_replays_from_the_last_state_before_it_through_every_later_sample():
    h = history_at([0.1, 0.2, 0.3, 0.4])
    assert h.newest == 4 and h.state.t == 0.4
    late, later = Record(0.25, "tracker", None), Record(0.35, "sun", None)
    assert h.insert(later) == 3                           # the state at 0.3 is the last before 0.35
    assert h.insert(late) == 2                            # ... at 0.2 before 0.25
    assert [r.t for r in h.records] == [0.25, 0.35]       # kept sorted by instant
    x, steps = h.replay_from(2)
    assert x.t == 0.2 and [t for t, _ in h.snapshots] == [-math.inf, 0.1, 0.2]
    # to each record's instant on the gyro sample of its interval, then to the sample's own instant
    assert [(s.t, float(s.omega_BN_B_measured[0]), s.saturated, s.record) for s in steps] == [
        (0.25, 0.3, False, late), (0.3, 0.3, False, None), (0.35, 0.4, True, later), (0.4, 0.4, True, None)]
    assert h.insert(Record(0.45, "sun", None)) is None     # after the newest state: the next sample applies it


def test_records_outside_the_history_or_ahead_of_the_gyro_are_refused_unkept():
    h = history_at([0.1, 0.2])
    h.snapshots.popleft()                                 # the oldest state kept is at 0.1
    for t in (0.05, 0.1, 0.71):
        with pytest.raises(RequestError) as err:
            h.insert(Record(t, "tracker", None))
        assert err.value.code == ErrorCode.STALE_MEASUREMENT
    assert h.records == [] and h.insert(Record(0.7, "tracker", None)) is None


def test_what_is_older_than_the_span_or_before_a_loss_is_forgotten():
    h = history_at([0.5, 1.0, 1.5, 2.0, 2.5])
    for t in (0.7, 1.2, 2.2):
        h.records.append(Record(t, "sun", None))
    h.trim(2.5)                                           # the span is 1 s: the state at 1.5 is the oldest kept
    assert [t for t, _ in h.snapshots] == [1.5, 2.0, 2.5]
    assert [t for t, _, _ in h.gyro] == [2.0, 2.5] and [r.t for r in h.records] == [2.2]
    h.forget_before(2.1)
    assert [t for t, _ in h.snapshots] == [2.5] and h.records == []
    h.forget_before(1.0)                                  # before the oldest: nothing
    assert [t for t, _ in h.snapshots] == [2.5]
    h.clear()
    assert h.state is None and h.newest == 0 and h.last_gyro is None
