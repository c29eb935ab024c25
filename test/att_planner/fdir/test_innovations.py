"""Tracker and gyro health from the innovations: a tracker's attitude jump excluded (and re-admitted
once it is gone), a gyro bias step isolated to the gyro and its axis, and no verdict in 2000 s of
fault-free innovations drawn with the LEO observatory's tracker noise."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.estimation.health import Innovation
from att_planner.fdir.innovations import InnovationDetector
from att_sim.models import rotations as rot

ARCSEC = math.pi / 180.0 / 3600.0
THRESHOLD = 21.1                 # chi-square 3 dof, 0.9999


def noise_B(tracker) -> np.ndarray:
    """A tracker's measurement covariance in body axes (the estimator's ``C R_S Cᵀ``)."""
    R_S = np.diag([tracker.cross_boresight_arcsec, tracker.cross_boresight_arcsec,
                   tracker.about_boresight_arcsec]) ** 2 * ARCSEC**2
    C = rot.dcm_NB(np.array(tracker.mounting))
    return C @ R_S @ C.T


def innovations(leo, duration_s, jump=None, jump_from=math.inf, jump_to=math.inf, bias_axis=None,
                bias_at=math.inf, bias_rad_s=1.75e-4, seed=11):
    """Both trackers at 5 Hz: the estimate's error drawn from its covariance (2 arcsec per axis), each
    tracker's noise from its datasheet; a jump of ``jump`` (rad, body) on st1 in [jump_from, jump_to);
    a gyro bias step about ``bias_axis`` from ``bias_at`` (the error it integrates, not corrected)."""
    rng = np.random.default_rng(seed)
    trackers = leo.sensors.star_trackers
    R = [noise_B(tr) for tr in trackers]
    P = np.eye(3) * (2.0 * ARCSEC) ** 2
    S_inv = [np.linalg.inv(P + r) for r in R]
    for k in range(int(round(duration_s * 5.0))):
        t = (k + 1) * 0.2
        error = rng.multivariate_normal(np.zeros(3), P)
        if t >= bias_at:
            error[bias_axis] += bias_rad_s * (t - bias_at)
        batch = []
        for i, tr in enumerate(trackers):
            y = error + rng.multivariate_normal(np.zeros(3), R[i])
            if i == 0 and jump_from <= t < jump_to:
                y = y + jump
            batch.append(Innovation(t + 0.01 * i, tr.name, y, float(y @ S_inv[i] @ y), R[i]))
        yield batch


def detector(leo):
    return InnovationDetector([tr.name for tr in leo.sensors.star_trackers], THRESHOLD, 1.0, 30.0, THRESHOLD, 1.0)


def run(det, batches):
    out = []
    for batch in batches:
        out += det.update(batch)
    return out


def test_a_tracker_jump_excludes_that_tracker_and_it_is_readmitted_once_gone(leo):
    det = detector(leo)
    jump = np.array([60.0, -40.0, 0.0]) * ARCSEC
    verdicts = run(det, innovations(leo, 200.0, jump=jump, jump_from=100.0, jump_to=150.0))
    assert [(v.component, v.index, v.active) for v in verdicts] == [("star_tracker", 0, True),
                                                                   ("star_tracker", 0, False)]
    out, back = verdicts
    assert 100.0 < out.t <= 130.0 and "disagrees with st2" in out.evidence
    assert 180.0 <= back.t <= 181.0 and "re-admitted" in back.evidence
    assert det.excluded == set()


def test_a_lasting_jump_keeps_the_tracker_excluded(leo):
    det = detector(leo)
    run(det, innovations(leo, 300.0, jump=np.array([0.0, 80.0, 0.0]) * ARCSEC, jump_from=100.0))
    assert det.excluded == {"st1"}


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_gyro_bias_step_is_isolated_to_the_gyro_and_its_axis(leo, axis):
    verdicts = run(detector(leo), innovations(leo, 130.0, bias_axis=axis, bias_at=111.1))
    assert [(v.component, v.index, v.detector) for v in verdicts] == [("gyro", axis, "gyro_innovation")]
    assert 111.1 < verdicts[0].t <= 116.1


def test_no_verdict_on_2000_s_of_fault_free_innovations(leo):
    det = detector(leo)
    assert run(det, innovations(leo, 2000.0, seed=12)) == []


def test_a_lone_tracker_is_blamed_itself():
    det = InnovationDetector(["st1"], THRESHOLD, 0.4)
    R = np.eye(3) * 1e-10
    out = run(det, [[Innovation(0.2 * k, "st1", np.array([1e-4, 0, 0]), 100.0, R)] for k in range(5)])
    assert [(v.index, v.t) for v in out] == [(0, 0.4)] and "no partner" in out[0].evidence
