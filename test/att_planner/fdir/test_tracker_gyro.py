"""Each star tracker against the gyro's propagation: the GLR against an independent least-squares
recomputation, a tracker's jump isolated to that tracker, a gyro rate step to the gyro and its axis
(a lone tracker and two), no verdict in fault-free flight drawn with the LEO observatory's datasheets."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.fdir.tracker_gyro import GAP_S, GyroRampDetector, Residuals, TrackerStepDetector
from att_sim.models import rotations as rot
from att_sim.models.sensor_specs import sensors_from_model

THRESHOLD = 40.0
DEG_S = math.radians(0.01)          # the fault study's gyro bias step


@pytest.fixture(scope="module")
def trackers(leo):
    return list(sensors_from_model(leo.sensors).star_trackers)


def fly(trackers, duration_s, seed, on=(0, 1), bias_step=None, jump=None, rate=(0.0, 0.003, 0.001),
        residuals=None):
    """A body turning at ``rate`` (rad/s), its gyro at 20 Hz (the datasheet's angle random walk and a
    1 deg/h bias, plus ``bias_step`` = (t, axis, rad/s)), trackers ``on`` at 5 Hz with their noise
    (``jump`` = (tracker, t, rad about the sensor axes) added from t); the verdicts of both detectors."""
    rng = np.random.default_rng(seed)
    res = residuals or Residuals(trackers, 12.0, 4.0)
    detectors = [TrackerStepDetector(res, THRESHOLD, 1.0), GyroRampDetector(res, THRESHOLD, 0.4)]
    arw = math.radians(0.005) / 60.0                 # rad/sqrt(s)
    q = rot.normalize(np.array([0.1, 0.2, 0.3, 0.9]))
    w, dt, out = np.asarray(rate, float), 0.05, []
    for k in range(int(round(duration_s / dt))):
        t = (k + 1) * dt
        q = rot.propagate_constant_rate(q, w, dt)
        bias = np.full(3, math.radians(1.0) / 3600.0)
        if bias_step is not None and t >= bias_step[0]:
            bias[bias_step[1]] += bias_step[2]
        measured = w + bias + rng.normal(0.0, arw / math.sqrt(dt), 3)
        for d in detectors:
            out += d.on_gyro(t, measured)
        if k % 4 != 3:
            continue
        for i in on:
            s = trackers[i]
            noise = rng.normal(0.0, 1.0, 3) * np.sqrt(np.diag(s.covariance))
            if jump is not None and i == jump[0] and t >= jump[1]:
                noise = noise + np.asarray(jump[2])
            q_SN = rot.multiply(rot.multiply(q, s.mounting), rot.exp_map(noise))
            for d in detectors:
                out += d.on_tracker(t, s.name, q_SN, True)
    return out


def test_the_glr_is_the_least_squares_fit_with_and_without_the_signature(trackers):
    res = Residuals(trackers, 12.0, 4.0)
    rng = np.random.default_rng(3)
    s = trackers[1]
    C = rot.dcm_NB(s.mounting)
    L = np.linalg.cholesky(C @ s.covariance @ C.T)
    q_B0 = rot.normalize(np.array([0.3, -0.1, 0.2, 0.9]))
    rows = []
    for k in range(61):
        t = 0.2 * k
        r = L @ rng.normal(size=3) + np.array([1e-5, -2e-5, 3e-5]) * t + (np.array([0.0, 2e-4, 0.0]) if t > 10 else 0)
        q_G = rot.exp_map(np.array([0.0, 0.0, 0.001 * t]))           # any gyro propagation
        rows.append((t, q_G, rot.multiply(rot.multiply(q_B0, q_G), rot.exp_map(r))))
    test = res._test(s.name, rows)
    # independent: residuals from the first sample's anchor, whitened, fitted with lstsq
    ts = np.array([x[0] for x in rows])
    r = np.array([2.0 * rot.error_vector(x[2], rot.multiply(rot.multiply(rows[0][2], rot.conjugate(rows[0][1])), x[1]))
                  for x in rows])
    Z = np.linalg.solve(L, r.T).T
    base = np.column_stack([np.ones_like(ts), ts])
    rss0 = np.sum(np.linalg.lstsq(base, Z, rcond=None)[1])
    best = {}
    for j in np.flatnonzero(ts > ts[-1] - 4.0):
        for kind, sig in (("step", (ts >= ts[j]).astype(float)), ("ramp", np.maximum(ts - ts[j], 0.0))):
            if kind == "ramp" and j > len(ts) - 4:
                continue
            rss1 = np.sum(np.linalg.lstsq(np.column_stack([base, sig]), Z, rcond=None)[1])
            best[(kind, j)] = rss0 - rss1
    (kind, j), g = max(best.items(), key=lambda kv: kv[1])
    assert test.stat == pytest.approx(g, rel=1e-6) and test.kind == kind and test.onset == pytest.approx(ts[j])
    other = max(v for (k, _), v in best.items() if k != kind)
    assert test.margin == pytest.approx(g - other, rel=1e-6)
    assert test.kind == "step" and test.amplitude_B[1] == pytest.approx(2e-4, abs=3e-5)


def test_fault_free_flight_gives_no_verdict_and_chi_square_tests(trackers):
    res = Residuals(trackers, 12.0, 4.0)
    stats = []
    original = res._test

    def recorded(name, w):
        out = original(name, w)
        stats.append(out.stat)
        return out

    res._test = recorded
    assert fly(trackers, 150.0, 1, residuals=res) == []
    assert len(stats) > 1200 and max(stats) < THRESHOLD
    # each onset's GLR is chi-square (3 dof); the largest over about 37 onsets exceeds the 0.999
    # quantile of one (16.3) in a few per cent of the tests, never the threshold
    assert 0.005 < np.mean(np.array(stats) > 16.27) < 0.2


@pytest.mark.parametrize("on", [(1,), (0, 1)])
def test_a_tracker_jump_is_isolated_to_that_tracker(trackers, on):
    verdicts = fly(trackers, 45.0, 7, on=on, jump=(1, 30.0, (2e-4, -2e-4, 0.0)))
    assert [(v.component, v.index, v.detector) for v in verdicts] == [("star_tracker", 1, "tracker_step")]
    assert 30.0 < verdicts[0].t <= 31.6 and "st2" in verdicts[0].evidence


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_gyro_rate_step_is_isolated_to_the_gyro_axis_with_a_lone_tracker(trackers, axis):
    verdicts = fly(trackers, 40.0, 20 + axis, on=(1,), bias_step=(30.0, axis, DEG_S))
    assert [(v.component, v.index, v.detector) for v in verdicts] == [("gyro", axis, "gyro_ramp")]
    assert 30.0 < verdicts[0].t <= 35.0        # about st2's boresight (body x) the slowest


def test_a_gyro_rate_step_with_two_trackers_is_seen_within_two_seconds(trackers):
    verdicts = fly(trackers, 40.0, 31, bias_step=(30.0, 0, DEG_S))
    assert [(v.component, v.index) for v in verdicts] == [("gyro", 0)]
    assert 30.0 < verdicts[0].t <= 32.0 and "deg/s about axis 0" in verdicts[0].evidence


def test_an_invalid_measurement_or_a_gap_starts_the_window_again(trackers):
    res = Residuals(trackers, 12.0, 4.0)
    s = trackers[0]
    q = rot.multiply(np.array([0.0, 0.0, 0.0, 1.0]), s.mounting)
    for k in range(240):
        res.on_gyro(0.05 * k, np.zeros(3))
        if k % 4 == 3 and k < 180:
            res.on_tracker(0.05 * k, s.name, q, True)
    assert len(res.windows[s.name].samples) == 45 and res.epoch[s.name] == 0
    assert res.on_tracker(9.0, s.name, q, False) is None and not res.windows[s.name].samples
    res.on_tracker(9.2, s.name, q, True)
    res.on_tracker(9.2 + GAP_S + 0.1, s.name, q, True)
    assert len(res.windows[s.name].samples) == 1 and res.epoch[s.name] == 2
    assert res.on_tracker(9.3, "st9", q, True) is None                 # an unknown tracker: ignored


def test_an_onset_span_outside_the_window_is_refused(trackers):
    with pytest.raises(ValueError, match="onset_s must be in"):
        Residuals(trackers, 4.0, 4.0)
    with pytest.raises(ValueError, match="discontinuity_rad must be > 0"):
        Residuals(trackers, 12.0, 4.0, float("nan"))


def test_the_attitude_itself_moving_is_no_fault_of_a_unit(trackers):
    """A jump of the truth's attitude (a simulation reset: every tracker moves, the gyro saw nothing)
    beyond the discontinuity starts the window again; below it, it is a tracker's step."""
    out = {}
    for discontinuity in (math.radians(1.0), math.inf):
        res = Residuals(trackers, 12.0, 4.0, discontinuity)
        out[discontinuity] = fly(trackers, 40.0, 5, on=(1,), jump=(1, 30.0, (0.03, -0.02, 0.0)), residuals=res)
        assert res.epoch["st2"] == 1          # started again: at the jump, or after the verdict
    assert out[math.radians(1.0)] == []
    assert [(v.component, v.index) for v in out[math.inf]] == [("star_tracker", 1)]
