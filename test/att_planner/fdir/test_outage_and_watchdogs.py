"""A star tracker that stops answering (within 30 s; a blinded one still answers and is not out), and
the attitude, rate and estimate watchdogs declaring after their persistence, never below threshold."""
from __future__ import annotations

import math

import numpy as np

from att_planner.fdir.outage import OutageDetector
from att_planner.fdir.watchdogs import Watchdog


def test_a_silent_tracker_is_out_and_back_when_heard():
    det = OutageDetector(["st1", "st2"], threshold_s=5.0)
    verdicts = []
    for k in range(1, 1001):                 # 200 s at 5 Hz; st2 silent in [50, 120) s
        t = 0.2 * k
        det.heard_from("st1", t)             # blinded or not, a measurement arrives
        if not 50.0 <= t < 120.0:
            det.heard_from("st2", t)
        det.heard_from("nobody", t)
        verdicts += det.update(t)
    assert [(v.index, v.active) for v in verdicts] == [(1, True), (1, False)]
    out, back = verdicts
    assert 50.0 < out.t <= 80.0 and math.isclose(out.since, 49.8, abs_tol=1e-9)
    assert math.isclose(back.t, 120.0, abs_tol=1e-6) and "heard again" in back.evidence


def test_a_tracker_never_heard_is_out_after_the_threshold_from_the_start():
    det = OutageDetector(["st1"], threshold_s=5.0)
    verdicts = [v for k in range(40) for v in det.update(0.2 * k)]
    assert [round(v.t, 6) for v in verdicts] == [5.2]


def test_a_watchdog_declares_after_its_persistence_once():
    rng = np.random.default_rng(4)
    dog = Watchdog("attitude", "attitude_error", 10.0, 5.0, "deg", "attitude error")
    quiet = [v for k in range(20000) for v in dog.update(0.1 * k, abs(rng.normal(0.0, 2.0)))]  # 2000 s below 5 sigma
    assert quiet == []
    verdicts = []
    for k in range(200):
        t = 3000.0 + 0.1 * k
        verdicts += dog.update(t, 12.0 if k != 20 else 9.0)      # one sample back below restarts the count
    assert [round(v.t, 6) for v in verdicts] == [3007.1]
    assert "attitude error 12 deg > 10 deg since t = 3002.100 s" in verdicts[0].evidence


def test_a_lost_estimate_is_above_any_threshold():
    dog = Watchdog("estimate", "estimate_uncertain", 2.0, 0.0, "deg", "attitude 3 sigma")
    assert [v.component for v in dog.update(1.0, math.inf)] == ["estimate"]
    nan_dog = Watchdog("rate", "rate_error", 1.0, 0.0, "deg/s", "rate error")
    assert len(nan_dog.update(1.0, math.nan)) == 1               # a value that cannot be read is not healthy
