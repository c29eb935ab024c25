"""What a detector says and what the fault monitor reports (no ROS, plain dataclasses).

A detector's :class:`Verdict` names the component and unit it isolated, the detector, the evidence
(the numbers it saw against its threshold) and whether the condition is active (a detector that
clears, such as a tracker re-admitted after a consistent window, says so with ``active`` False).
The monitor (:mod:`.monitor`) turns a verdict into a :class:`att_msgs_py.types.FaultStatus`, the
fault topic's message (``att_msgs/FaultStatus``: header, fault id, component, index, detector,
evidence, response, active, detected_at), with the fault id and response of the table's entry.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Verdict:
    """A detector's decision at sim time ``t`` about unit ``index`` of ``component``."""

    t: float                   # s of sim time: when the condition had held for its persistence
    component: str             # "wheel", "star_tracker", "gyro", ... (att_planner.fdir.table.RESPONSES)
    index: int                 # the unit: wheel number, tracker number, gyro axis (0-based); 0 for a single unit
    detector: str              # the table's detector name
    evidence: str              # what was measured against what threshold, in words and numbers
    active: bool = True        # False: the condition cleared (a sensor re-admitted, a tracker heard again)
    since: float = float("nan")  # s of sim time the condition started to hold
