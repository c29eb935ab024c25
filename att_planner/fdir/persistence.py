"""A condition held in sim time (no ROS): the persistence every detector counts before a verdict."""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass
class Persistence:
    """Whether a condition has held continuously for ``persistence_s`` of sim time.

    :meth:`update` is told the condition at each sample; the condition's run starts at the first
    sample it holds (``since``) and is broken by a sample where it does not. A persistence of 0
    declares at the first sample the condition holds."""

    persistence_s: float
    since: float = math.nan              # start of the current run (nan: not holding)

    def update(self, holds: bool, t: float) -> bool:
        """The condition at sample time ``t``; True when it has held from ``since`` for the persistence."""
        if not holds:
            self.since = math.nan
            return False
        if math.isnan(self.since):
            self.since = t
        return t - self.since >= self.persistence_s - 1e-9

    @property
    def holding(self) -> bool:
        return not math.isnan(self.since)
