"""The estimator's measurement history (no ROS): what it keeps to apply a late measurement at its instant.

A star tracker's message arrives its latency later than the instant it was taken, so the estimator
keeps the last ``span`` seconds of gyro samples, of filter states (one after each gyro sample, with
the measurements up to it applied) and of measurements; a measurement older than the newest state
sends the filter back to the last state before it, from which everything since is reprocessed
(out-of-sequence measurements by reprocessing; Bar-Shalom, Li & Kirubarajan 2001 §10.4). This
module keeps the books and says what to replay (:meth:`MeasurementHistory.replay_from`); the
filter itself (:mod:`.mekf`) and the replay (:func:`att_planner.estimation.estimator.replay`) are
elsewhere.
"""
from __future__ import annotations

import math
from bisect import bisect_right
from collections import deque
from dataclasses import dataclass
from operator import attrgetter
from typing import NamedTuple

import numpy as np

from att_msgs_py.errors import ErrorCode, RequestError
from att_planner.estimation.mekf import FilterState


@dataclass
class Record:
    """A measurement kept for reprocessing: its instant, kind, data and the gate's decision."""

    t: float
    kind: str                              # "tracker", "magnetometer", "sun"
    data: object
    accepted: bool | None = None           # None until it is first processed


class Step(NamedTuple):
    """One step of a replay: propagate to ``t`` on the gyro sample ``(omega_BN_B_measured, saturated)``
    of the interval holding ``t``, then apply ``record`` (None: ``t`` is the sample's own instant,
    whose state is kept)."""

    t: float
    omega_BN_B_measured: np.ndarray
    saturated: bool
    record: Record | None


_instant = attrgetter("t")                 # a record's instant: the records' sort key


class MeasurementHistory:
    """Gyro samples ``(t, omega_BN_B_measured, saturated)``, filter states at the gyro instants (the
    first one the anchor: the oldest state kept) and measurement records sorted by instant."""

    def __init__(self, span: float, max_gyro_gap: float):
        """``span``: s of samples kept; ``max_gyro_gap``: s a measurement may be ahead of the gyro."""
        self.span, self.max_gyro_gap = span, max_gyro_gap
        self.clear()

    def clear(self) -> None:
        """Forget every state, sample and measurement (a new timeline)."""
        self.gyro: deque[tuple[float, np.ndarray, bool]] = deque()
        self.snapshots: deque[tuple[float, FilterState | None]] = deque([(-math.inf, None)])
        self.records: list[Record] = []
        self.forgotten: dict[str, float] = {}      # kind: instant of the newest accepted record forgotten

    @property
    def state(self) -> FilterState | None:
        """The newest filter state (None: no estimate)."""
        return self.snapshots[-1][1]

    @property
    def newest(self) -> int:
        """Index of the newest state: a replay from it catches up with a new gyro sample."""
        return len(self.snapshots) - 1

    @property
    def last_gyro(self) -> float | None:
        """Instant of the newest gyro sample (None: none kept)."""
        return self.gyro[-1][0] if self.gyro else None

    def keep_gyro(self, t: float, omega_BN_B_measured: np.ndarray, saturated: bool) -> None:
        self.gyro.append((t, omega_BN_B_measured, saturated))

    def insert(self, record: Record) -> int | None:
        """Keep ``record``; the last state before its instant when that is not the newest (the state
        to replay from; None: the next gyro sample applies it). RequestError (321) for a record
        older than the history or further than ``max_gyro_gap`` ahead of the gyro."""
        if record.t <= self.snapshots[0][0]:
            oldest = self.snapshots[0][0]
            raise RequestError(ErrorCode.STALE_MEASUREMENT,
                               f"{record.kind} measurement of t = {record.t:.6g} s is older than the filter's history "
                               f"(from t = {oldest:.6g} s, {self.span:g} s)")
        newest = self.last_gyro
        if newest is not None and record.t > newest + self.max_gyro_gap:
            raise RequestError(ErrorCode.STALE_MEASUREMENT,
                               f"{record.kind} measurement of t = {record.t:.6g} s is ahead of the gyro (t = "
                               f"{newest:.6g} s) by more than max_gyro_gap_s = {self.max_gyro_gap:g} s")
        self.records.append(record)
        self.records.sort(key=_instant)               # stable: equal instants keep their arrival order
        if record.t <= self.snapshots[-1][0]:
            return max(i for i, (t, _) in enumerate(self.snapshots) if t < record.t)
        return None

    def replay_from(self, start: int) -> tuple[FilterState | None, list[Step]]:
        """Drop the states after snapshot ``start``; that state and the steps that rebuild them: through
        each later gyro interval, stopping at each measurement's instant, ending at the sample's."""
        t0, x = self.snapshots[start]
        while len(self.snapshots) > start + 1:
            self.snapshots.pop()
        records = self.records_after(t0)
        steps, k = [], 0
        for t_j, omega, saturated in self.gyro_after(t0):
            while k < len(records) and records[k].t <= t_j:
                steps.append(Step(records[k].t, omega, saturated, records[k]))
                k += 1
            steps.append(Step(t_j, omega, saturated, None))
        return x, steps

    def forget_before(self, t: float) -> None:
        """Drop the states and records before ``t`` (an estimate lost then: nothing before it is replayed)."""
        if t > self.snapshots[0][0]:
            while len(self.snapshots) > 1 and self.snapshots[0][0] < t:
                self.snapshots.popleft()
            self._forget_records()

    def records_after(self, t: float) -> list[Record]:
        """The records later than ``t`` (kept sorted by time)."""
        return self.records[bisect_right(self.records, t, key=_instant):]

    def gyro_after(self, t: float) -> list[tuple[float, np.ndarray, bool]]:
        """The gyro samples later than ``t``, oldest first (their stamps increase)."""
        after = []
        for sample in reversed(self.gyro):
            if sample[0] <= t:
                break
            after.append(sample)
        return after[::-1]

    def partner(self, kind: str, t: float, window: float) -> Record | None:
        """The newest record of ``kind`` within ``window`` s of ``t`` (None: none)."""
        return next((p for p in reversed(self.records) if p.kind == kind and abs(p.t - t) <= window), None)

    def trim(self, now: float) -> None:
        """Forget what is older than ``span`` s before ``now`` (one snapshot stays: the oldest state kept)."""
        horizon = now - self.span
        while len(self.snapshots) > 1 and self.snapshots[1][0] <= horizon:
            self.snapshots.popleft()
        while self.gyro and self.gyro[0][0] <= self.snapshots[0][0]:
            self.gyro.popleft()
        self._forget_records()

    def _forget_records(self) -> None:
        """Drop the records up to the oldest state, keeping the instant of the newest accepted one of each kind."""
        i = bisect_right(self.records, self.snapshots[0][0], key=_instant)
        for r in self.records[:i]:
            if r.accepted:
                self.forgotten[r.kind] = max(self.forgotten.get(r.kind, -math.inf), r.t)
        del self.records[:i]

    def last_accepted(self, kind: str, t: float) -> float:
        """Instant of the newest accepted record of ``kind`` taken at or before ``t``, kept or forgotten
        since :meth:`clear` (-inf: none)."""
        i = bisect_right(self.records, t, key=_instant)
        return next((r.t for r in reversed(self.records[:i]) if r.kind == kind and r.accepted),
                    self.forgotten.get(kind, -math.inf))
