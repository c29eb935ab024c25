"""A gyro bias step seen in the bias estimate: isolated to its axis within 5 s of the estimate
following it, the turn-on convergence ignored until the filter is sure of its bias, and no verdict in
2000 s of a healthy estimate wandering by the LEO observatory gyro's bias instability."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.fdir.bias import RAD_S_PER_DEG_H, BiasJumpDetector


def estimates(leo, duration_s, step_axis=None, step_at=math.inf, step_deg_h=36.0, seed=4):
    """(t, b̂, P_b) at 20 Hz: the estimate converging from zero on a 1 deg/h turn-on bias in the first
    minute (its covariance shrinking from the prior), then wandering by the bias instability and the
    filter's noise; a step followed with a 3 s lag."""
    g = leo.sensors.gyro
    rng = np.random.default_rng(seed)
    turn_on = rng.normal(0.0, g.initial_bias_deg_per_h, 3) * RAD_S_PER_DEG_H
    wander = np.zeros(3)
    step = np.zeros(3)
    for k in range(int(round(duration_s * 20))):
        t = (k + 1) / 20.0
        wander += rng.normal(0.0, g.bias_instability_deg_per_h * RAD_S_PER_DEG_H / math.sqrt(20 * 100), 3)
        if t > step_at:
            step[step_axis] = step_deg_h * RAD_S_PER_DEG_H * (1.0 - math.exp(-(t - step_at) / 3.0))
        converging = 1.0 - math.exp(-t / 15.0)
        sigma = 3.0 * g.initial_bias_deg_per_h * RAD_S_PER_DEG_H * max(math.exp(-t / 20.0), 0.01)
        noise = rng.normal(0.0, 0.005 * RAD_S_PER_DEG_H, 3)
        yield t, turn_on * converging + wander + step + noise, np.eye(3) * sigma**2


def run(det, stream):
    return [v for t, b, P in stream for v in det.update(t, b, P)]


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_bias_step_is_isolated_to_its_axis(leo, axis):
    verdicts = run(BiasJumpDetector(2.0, 10.0, 0.5), estimates(leo, 320.0, axis, 300.3))
    assert [(v.component, v.index, v.detector) for v in verdicts] == [("gyro", axis, "gyro_bias_jump")]
    assert 300.3 < verdicts[0].t <= 305.3 and "deg/h" in verdicts[0].evidence


def test_the_turn_on_convergence_is_not_a_step():
    """A 6 deg/h turn-on bias converged on with a 10 s time constant while the bias 3 sigma shrinks
    from 9 deg/h: seen by a detector armed from the start, not by one that waits for the filter to be
    sure of its bias."""
    def stream(with_covariance):
        for k in range(1, 2401):
            t = 0.05 * k
            b = np.array([6.0 * (1.0 - math.exp(-t / 10.0)), 0.0, 0.0]) * RAD_S_PER_DEG_H
            sigma = 3.0 * RAD_S_PER_DEG_H * math.exp(-t / 20.0)
            yield t, b, (np.eye(3) * sigma**2 if with_covariance else None)

    assert [v.index for v in run(BiasJumpDetector(2.0, 10.0, 0.5), stream(False))] == [0]
    assert run(BiasJumpDetector(2.0, 10.0, 0.5), stream(True)) == []


def test_no_verdict_on_2000_s_of_a_healthy_estimate(leo):
    assert run(BiasJumpDetector(2.0, 10.0, 0.5), estimates(leo, 2000.0, seed=6)) == []


def test_the_change_is_measured_over_the_window():
    """Independent recomputation: a ramp of 1 deg/h per s crosses 2 deg/h over a 10 s window once
    the window is full, and the evidence carries the change."""
    det = BiasJumpDetector(2.0, 10.0, 0.0)
    out = [v for k in range(400) for v in det.update(0.05 * k, np.array([0.0, 0.0, 0.05 * k * RAD_S_PER_DEG_H * 0.3]))]
    (v,) = out
    assert v.index == 2 and v.t == pytest.approx(10.0) and "+3 deg/h in 10 s" in v.evidence
