"""A reading that stops changing (no ROS): a stuck gyro axis, tachometer or magnetometer.

A noisy sensor's consecutive samples differ: the gyro's by its angle random walk over a sample
(``√2 σ_v / √Δt``), a tachometer's and a magnetometer's by their white noise, so a channel whose
reading changes by at most ``threshold`` between every pair of samples for ``persistence_s`` is
stuck. The chance that a healthy channel repeats itself ``n`` times is ``p^n`` with ``p`` the chance
of one repeat (its quantum over its noise): the persistence makes it negligible. A sensor without
noise repeats itself legitimately and is not watched by this detector.
"""
from __future__ import annotations

import numpy as np

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict


class FrozenDetector:
    """Channels of one sensor kind, each stuck when it stops changing (module docstring)."""

    def __init__(self, component: str, detector: str, n_channels: int, threshold: float, persistence_s: float,
                 unit: str, single_unit: bool = False):
        """``single_unit``: the channels are the axes of one unit (the magnetometer: index 0, declared
        once, by its first stuck axis, named in the evidence); else each channel is a unit (a wheel's
        tachometer, a gyro axis)."""
        self.component, self.detector, self.threshold, self.unit = component, detector, threshold, unit
        self.single_unit = single_unit
        self.persistence = [Persistence(persistence_s) for _ in range(n_channels)]
        self.declared = [False] * n_channels
        self.last: np.ndarray | None = None
        self.last_t = 0.0

    def update(self, t: float, values) -> list[Verdict]:
        """A sample at ``t`` of every channel; the verdicts of the channels declared stuck at this sample."""
        values = np.asarray(values, float)
        if self.last is None:
            self.last, self.last_t = values, t
            return []
        change = np.abs(values - self.last)
        out = []
        for i, p in enumerate(self.persistence):
            if not p.holding and change[i] <= self.threshold:
                p.since = self.last_t          # unchanged since the sample before
            if p.update(bool(change[i] <= self.threshold), t) and not self.declared[i]:
                self.declared = [True] * len(self.declared) if self.single_unit else self.declared
                self.declared[i] = True
                where = f"axis {i}" if self.single_unit else f"{self.component} {i}"
                out.append(Verdict(t, self.component, 0 if self.single_unit else i, self.detector,
                                   f"{where} reading {values[i]:.6g} {self.unit} unchanged by more than "
                                   f"{self.threshold:g} {self.unit} since t = {p.since:.3f} s", since=p.since))
        self.last, self.last_t = values, t
        return out
