"""A star tracker that stops answering (no ROS): no measurement, valid or not, for the threshold.

A tracker blinded by the Sun, the Earth or the Moon keeps sending measurements marked invalid with
the reason (``att_msgs/StarTracker.STATUS_*``); one that sends nothing at all for ``threshold_s`` is
out. The fault clears when it is heard again (the innovation detector then judges what it says).
"""
from __future__ import annotations

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict

DETECTOR = "tracker_outage"


class OutageDetector:
    """Silence of each tracker, timed in sim time from the first :meth:`update` (module docstring)."""

    def __init__(self, trackers: list[str], threshold_s: float, persistence_s: float = 0.0):
        self.names, self.threshold = list(trackers), threshold_s
        self.heard: dict[str, float] = {}
        self.persistence = {n: Persistence(persistence_s) for n in trackers}
        self.out = dict.fromkeys(trackers, False)

    def heard_from(self, name: str, t: float) -> None:
        """A measurement of tracker ``name`` arrived, taken at ``t`` (unknown names are ignored)."""
        if name in self.out:
            self.heard[name] = max(self.heard.get(name, t), t)

    def update(self, t: float) -> list[Verdict]:
        """The verdicts at sim time ``t``: a tracker silent for the threshold, one heard again."""
        out = []
        for i, name in enumerate(self.names):
            last = self.heard.setdefault(name, t)
            silent = t - last > self.threshold
            if self.persistence[name].update(silent, t) and not self.out[name]:
                self.out[name] = True
                out.append(Verdict(t, "star_tracker", i, DETECTOR, f"{name}: no measurement since t = {last:.3f} s "
                                   f"({t - last:.3g} s > {self.threshold:g} s)", since=last))
            elif not silent and self.out[name]:
                self.out[name] = False
                out.append(Verdict(t, "star_tracker", i, DETECTOR, f"{name}: heard again at t = {last:.3f} s",
                                   active=False, since=last))
        return out
