"""Watchdogs on the attitude and rate errors and on the estimate's uncertainty (no ROS).

A value above its threshold for the persistence declares the fault (latched: the response, safe
mode, is left by the ground). The attitude error is the angle from the controller's reference, the
rate error the norm of the body rate's difference from the reference rate, the estimate's
uncertainty the 3σ of its attitude covariance (``inf`` while the estimate is lost or initialising):
the attitude can then not be controlled, or not be known.
"""
from __future__ import annotations

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict


class Watchdog:
    """One scalar against its threshold (module docstring)."""

    def __init__(self, component: str, detector: str, threshold: float, persistence_s: float, unit: str,
                 what: str):
        self.component, self.detector, self.threshold, self.unit, self.what = component, detector, threshold, unit, what
        self.persistence = Persistence(persistence_s)
        self.declared = False

    def update(self, t: float, value: float) -> list[Verdict]:
        """``value`` (in the threshold's unit) at ``t``; the verdict when it is declared."""
        if not self.persistence.update(not value <= self.threshold, t) or self.declared:
            return []
        self.declared = True
        return [Verdict(t, self.component, 0, self.detector, f"{self.what} {value:.4g} {self.unit} > "
                        f"{self.threshold:g} {self.unit} since t = {self.persistence.since:.3f} s",
                        since=self.persistence.since)]
