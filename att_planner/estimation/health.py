"""The estimator's health monitor (no ROS): what the estimate is worth, from what the filter did.

``AttitudeEstimate.HEALTH_*``: INITIALISING without an attitude; DIVERGED when the covariance stops
being positive definite or ``lost_after`` tracker measurements in a row are rejected (the estimate
is dropped and the filter reinitialises from the next measurements); CONVERGED while an attitude fix
— a star tracker measurement, or a vector measurement on a spacecraft without trackers — was
accepted within ``propagate_timeout`` s and the attitude's 3σ is below ``converged_attitude_sigma``;
PROPAGATING otherwise (on the gyro, with at most the coarse aid of the vectors while the trackers
are blind). The monitor also counts the gate's rejections, keeps the notes the node logs and the tracker
innovations a fault monitor judges the sensors by (:class:`Innovation`).
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import Health
from att_planner.estimation import mekf
from att_planner.estimation.history import Record

MAX_NOTES = 100                    # notes kept for the node between two reports
MAX_INNOVATIONS = 1000             # innovations kept between two takes (the oldest dropped)


@dataclass(frozen=True)
class Innovation:
    """A tracker measurement's innovation as the filter computed it when the measurement first arrived:
    ``y`` the measured small rotation from the estimate (rad, body axes), ``d² = yᵀ S⁻¹ y``, ``R`` the
    measurement noise in body axes (rad²); ``used`` False when the tracker was excluded."""

    t: float
    sensor: str
    y: np.ndarray
    d2: float
    R: np.ndarray
    used: bool = True


@dataclass
class Report:
    """What the estimator has to say since it was last asked (the node logs it)."""

    notes: deque = field(default_factory=lambda: deque(maxlen=MAX_NOTES))
    rejected: int = 0


class HealthMonitor:
    def __init__(self, propagate_timeout: float, converged_attitude_sigma: float, lost_after: int,
                 has_trackers: bool):
        self.propagate_timeout, self.converged_attitude_sigma = propagate_timeout, converged_attitude_sigma
        self.lost_after, self.has_trackers = lost_after, has_trackers
        self.rejected = 0
        self.report = Report()
        self.innovations: deque = deque(maxlen=MAX_INNOVATIONS)
        self._sigma3: tuple = (None, 0.0)        # (state, its attitude 3σ): the cache of health()
        self.restart()

    def restart(self) -> None:
        """A new timeline: initialising again (the rejection count and the notes carry on)."""
        self.diverged, self.lost_at = False, -math.inf        # lost_at: instant the estimate was last dropped
        self.last_update = -math.inf             # time of the last accepted attitude measurement
        self.last_tracker = -math.inf            # ... of the last accepted tracker measurement
        self.rejected_in_a_row = 0

    @property
    def last_fix(self) -> float:
        """Time of the last accepted attitude fix (tracker, or any attitude measurement without trackers)."""
        return self.last_tracker if self.has_trackers else self.last_update

    def health(self, t: float, x: mekf.FilterState | None) -> Health:
        """The health at ``t`` of the newest state ``x``."""
        if x is None:
            return Health.DIVERGED if self.diverged else Health.INITIALISING
        if self._sigma3[0] is not x:          # asked several times per state: its largest eigenvalue once
            self.keep_largest_attitude_variance(x, mekf.largest_attitude_variance(x.P[None])[0])
        recent = t - self.last_fix <= self.propagate_timeout
        return Health.CONVERGED if recent and self._sigma3[1] <= self.converged_attitude_sigma else Health.PROPAGATING

    def keep_largest_attitude_variance(self, x: mekf.FilterState, largest: float) -> None:
        """The largest eigenvalue of the attitude covariance of ``x``, the newest state, which
        :meth:`health` needs (computed for a batch of estimators at once by their replay)."""
        self._sigma3 = (x, 3.0 * math.sqrt(max(largest, 0.0)))

    def lose(self, t: float, why: str) -> None:
        """Drop the estimate at ``t``: DIVERGED until the next initialisation. Returns None (no state)."""
        self.diverged, self.lost_at = True, max(self.lost_at, t)
        self.report.notes.append(f"estimate diverged ({why}): reinitialising")

    def initialised(self, r: Record) -> None:
        """A first state from the measurement ``r``."""
        r.accepted = True
        self.diverged = False
        self.last_update = r.t
        if r.kind == "tracker":
            self.last_tracker = r.t
        self.report.notes.append(f"estimate initialised at t = {r.t:.3f} s from {r.kind}")

    def accepted(self, r: Record) -> None:
        """An update by the measurement ``r`` went through."""
        self.last_update = max(self.last_update, r.t)
        if r.kind == "tracker":
            self.last_tracker = max(self.last_tracker, r.t)

    def judged(self, r: Record, update: mekf.Update, gate: float) -> bool:
        """Record the gate's decision on ``r`` (its first processing); True when it loses the estimate
        (``lost_after`` tracker measurements in a row rejected)."""
        r.accepted = update.accepted
        if update.accepted:
            if r.kind == "tracker":
                self.rejected_in_a_row = 0
            return False
        self.rejected += 1
        self.report.rejected += 1
        self.report.notes.append(f"{r.kind} measurement of t = {r.t:.3f} s rejected by the gate (d² = "
                                 f"{update.d2:.4g} > {gate:.4g})")
        if r.kind != "tracker":
            return False
        self.rejected_in_a_row += 1
        if self.rejected_in_a_row < self.lost_after:
            return False
        self.rejected_in_a_row = 0
        return True

    def innovation(self, innovation: Innovation) -> None:
        """Keep a tracker measurement's innovation for :meth:`take_innovations`."""
        self.innovations.append(innovation)

    def take_innovations(self) -> list[Innovation]:
        out = list(self.innovations)
        self.innovations.clear()
        return out

    def take_report(self) -> Report:
        out, self.report = self.report, Report()
        return out
