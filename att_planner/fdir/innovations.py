"""Sensor health from the estimator's innovations (no ROS): a star tracker or the gyro.

Each star tracker measurement gives the filter an innovation ``y_k`` (the small rotation from the
estimate to the measured attitude, body axes) with covariance ``S_k = H P Hᵀ + R_k`` and normalised
innovation squared ``d²_k = y_kᵀ S_k⁻¹ y_k``, χ²-distributed with 3 degrees of freedom while filter
and sensor are healthy (Bar-Shalom, Li & Kirubarajan 2001, §5.4). A measurement is *inconsistent*
when ``d²_k > threshold``. Which part failed:

* two trackers measure the same body attitude, so the difference of two innovations close in time
  ``y_k − y_j = v_k − v_j`` cancels the estimate's error; its ``d²_kj = (y_k − y_j)ᵀ (R_k + R_j)⁻¹
  (y_k − y_j)`` is χ²₃ while both trackers are healthy. An inconsistent tracker that **disagrees**
  with a healthy partner (``d²_kj > threshold``, its own ``d²`` the larger) is the faulty one;
* an inconsistent tracker that **agrees** with its partner (``d²_kj ≤ threshold``) shares its error
  with it: the common cause is the propagation, the gyro (a bias step); its axis is the largest
  component of the mean innovation over the run (the attitude error the bias integrates). The run
  is broken by a tracker inconsistent on its own or by every tracker consistent, not by one
  consistent tracker while another is not (a tracker's noise about its boresight hides an error
  about that axis longer than its partner's does);
* a lone tracker (no partner within :data:`PAIR_WINDOW_S`, others excluded) that is inconsistent is
  taken as faulty itself.

Each condition held for its persistence gives a verdict. An excluded tracker's innovations are still
computed by the estimator (:attr:`att_planner.estimation.estimator.Estimator.excluded`), not applied;
after ``readmit_s`` of consistent ones it is re-admitted (a verdict with ``active`` False).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_planner.estimation.health import Innovation
from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict

PAIR_WINDOW_S = 0.5            # s: two trackers' innovations this close in time are compared
TRACKER, GYRO = "tracker_innovation", "gyro_innovation"


@dataclass
class _Tracker:
    persistence: Persistence
    readmit: Persistence
    last: Innovation | None = None
    excluded: bool = False


class InnovationDetector:
    """Tracker and gyro health from tracker innovations (module docstring). A ``None`` threshold
    leaves that detector off."""

    def __init__(self, trackers: list[str], tracker_threshold: float | None = None,
                 tracker_persistence_s: float = 0.0, readmit_s: float = math.inf,
                 gyro_threshold: float | None = None, gyro_persistence_s: float = 0.0):
        self.names = list(trackers)
        self.trackers = {n: _Tracker(Persistence(tracker_persistence_s), Persistence(readmit_s)) for n in trackers}
        self.tracker_threshold, self.gyro_threshold = tracker_threshold, gyro_threshold
        self.gyro = Persistence(gyro_persistence_s)
        self.gyro_declared = False
        self.gyro_run: list[np.ndarray] = []        # innovations of the current common-cause run

    def update(self, innovations: list[Innovation]) -> list[Verdict]:
        """The innovations since the last call (in the order of their instants); the verdicts."""
        out: list[Verdict] = []
        for inn in sorted(innovations, key=lambda i: i.t):
            if inn.sensor in self.trackers:
                out += self._one(inn)
        return out

    def _partner(self, inn: Innovation) -> Innovation | None:
        """The latest innovation of another tracker in use within :data:`PAIR_WINDOW_S` of ``inn``."""
        best = None
        for name, tr in self.trackers.items():
            last = tr.last
            if name == inn.sensor or tr.excluded or last is None or abs(last.t - inn.t) > PAIR_WINDOW_S:
                continue
            if best is None or abs(last.t - inn.t) < abs(best.t - inn.t):
                best = last
        return best

    def _one(self, inn: Innovation) -> list[Verdict]:
        tr = self.trackers[inn.sensor]
        index = self.names.index(inn.sensor)
        threshold = self.tracker_threshold if self.tracker_threshold is not None else self.gyro_threshold
        inconsistent = inn.d2 > threshold
        partner = self._partner(inn)
        agreement = math.nan
        if partner is not None:
            dy = inn.y - partner.y
            agreement = float(dy @ np.linalg.solve(inn.R + partner.R, dy))
        tracker_fault = inconsistent and (partner is None or (agreement > threshold and inn.d2 > partner.d2))
        common = inconsistent and partner is not None and agreement <= threshold
        tr.last = inn
        out = []
        if tr.excluded:
            if tr.readmit.update(not inconsistent, inn.t):
                tr.excluded = False
                tr.persistence.since = math.nan
                out.append(Verdict(inn.t, "star_tracker", index, TRACKER, f"{inn.sensor}: consistent (d² ≤ "
                                   f"{threshold:g}) since t = {tr.readmit.since:.3f} s: re-admitted",
                                   active=False, since=tr.readmit.since))
                tr.readmit.since = math.nan
            return out
        if self.tracker_threshold is not None and tr.persistence.update(tracker_fault, inn.t):
            tr.excluded = True
            why = "no partner to compare" if partner is None else (
                f"disagrees with {partner.sensor} (d² of the difference {agreement:.4g})")
            out.append(Verdict(inn.t, "star_tracker", index, TRACKER, f"{inn.sensor}: d² = {inn.d2:.4g} > "
                               f"{threshold:g} since t = {tr.persistence.since:.3f} s; {why}",
                               since=tr.persistence.since))
        out += self._gyro(inn, common, inconsistent and not common, agreement)
        return out

    def _gyro(self, inn: Innovation, common: bool, own: bool, agreement: float) -> list[Verdict]:
        """The gyro's condition after ``inn``: held by a common-cause inconsistency, broken by a
        tracker inconsistent on its own (``own``) or by every tracker consistent, left as it is by a
        consistent tracker while another is not (a tracker blind along the error's axis)."""
        if self.gyro_threshold is None or self.gyro_declared:
            return []
        consistent_everywhere = not (inn.d2 > self.gyro_threshold) and all(
            tr.last is None or tr.excluded or not (tr.last.d2 > self.gyro_threshold) for tr in self.trackers.values())
        if not common and not consistent_everywhere and not own:
            return []
        if consistent_everywhere or own:
            self.gyro.update(False, inn.t)
            self.gyro_run = []
            return []
        self.gyro_run.append(inn.y)
        if not self.gyro.update(True, inn.t):
            return []
        self.gyro_declared = True
        mean = np.mean(self.gyro_run, axis=0)
        axis = int(np.argmax(np.abs(mean)))
        return [Verdict(inn.t, "gyro", axis, GYRO, f"every tracker inconsistent together since t = "
                        f"{self.gyro.since:.3f} s ({inn.sensor} d² = {inn.d2:.4g} > {self.gyro_threshold:g}, "
                        f"agreeing with its partner: d² of the difference {agreement:.4g}); mean innovation "
                        f"{np.array2string(mean, precision=3)} rad, largest about axis {axis}", since=self.gyro.since)]

    @property
    def excluded(self) -> set[str]:
        """The trackers this detector excluded and has not re-admitted."""
        return {n for n, tr in self.trackers.items() if tr.excluded}
