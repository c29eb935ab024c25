"""A gyro bias step seen in the estimator's bias estimate (no ROS).

The filter estimates the gyro bias ``b̂`` (:mod:`att_planner.estimation.mekf`); a healthy gyro's bias
wanders by its bias instability (hundredths of a degree per hour for a navigation-grade unit), so the
estimate moves little over seconds. A bias step makes the attitude measurements disagree with the
propagation until the filter has moved ``b̂`` by the step: a change ``|b̂_k(t) − b̂_k(t − window_s)|``
above the threshold on axis ``k`` for the persistence is a bias step of that axis. The detector is
armed once the filter is first sure of the bias (3σ of its bias covariance below the threshold):
while it converges on the turn-on bias it moves ``b̂`` by as much as that bias. Once armed it stays
armed, and a change counts only beyond the larger of the threshold and the bias 3σ of the moment:
a filter that re-initialises (after a tracker jump it rejected, or a step) keeps its bias estimate
but opens its covariance, and the estimate then wanders within that 3σ while it re-converges,
whereas a step moves it beyond. This needs one
star tracker only (the innovation detector needs two to tell the gyro from a tracker,
:mod:`.innovations`), and sees the step once the filter has followed it, seconds later.
"""
from __future__ import annotations

from collections import deque

import numpy as np

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict

DETECTOR = "gyro_bias_jump"
RAD_S_PER_DEG_H = np.pi / 180.0 / 3600.0


class BiasJumpDetector:
    """The bias estimate's change over a window, per axis (module docstring)."""

    def __init__(self, threshold_deg_h: float, window_s: float, persistence_s: float):
        self.threshold, self.window = threshold_deg_h * RAD_S_PER_DEG_H, window_s
        self.threshold_deg_h = threshold_deg_h
        self.persistence = Persistence(persistence_s)
        self.samples: deque = deque()            # (t, b̂)
        self.declared = False
        self.armed = False

    def update(self, t: float, bias_B, bias_covariance=None) -> list[Verdict]:
        """The bias estimate (rad/s, body axes) and its covariance ((rad/s)²; None: taken as sure) of
        an estimate at ``t`` that has an attitude."""
        bias = np.asarray(bias_B, float)
        limit = self.threshold
        if bias_covariance is not None:
            sigma3 = 3.0 * float(np.sqrt(max(np.linalg.eigvalsh(np.asarray(bias_covariance, float)).max(), 0.0)))
            self.armed = self.armed or sigma3 < self.threshold
            limit = max(limit, sigma3)
        if not (self.armed or bias_covariance is None):
            return []
        self.samples.append((t, bias))
        while len(self.samples) > 1 and self.samples[1][0] <= t - self.window + 1e-9:
            self.samples.popleft()
        t0, before = self.samples[0]
        if t - t0 < self.window - 1e-9 or self.declared:
            return []
        change = bias - before
        axis = int(np.argmax(np.abs(change)))
        if not self.persistence.update(bool(abs(change[axis]) > limit), t):
            return []
        self.declared = True
        return [Verdict(t, "gyro", axis, DETECTOR, f"bias estimate of axis {axis} moved by "
                        f"{change[axis] / RAD_S_PER_DEG_H:+.4g} deg/h in {t - t0:.3g} s (beyond "
                        f"{limit / RAD_S_PER_DEG_H:.3g} deg/h: the threshold {self.threshold_deg_h:g} deg/h or "
                        f"the bias 3 sigma) since t = {self.persistence.since:.3f} s",
                        since=self.persistence.since)]
