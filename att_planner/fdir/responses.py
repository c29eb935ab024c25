"""The responses, a pure function of the active faults (no ROS).

From the faults the monitor holds active (:class:`~.status.FaultStatus`, each with its table's
response) follow what the flight software flies on:

* ``exclude_wheel`` on wheel ``i`` (a wheel or its tachometer): wheel ``i`` out of the healthy set;
  the allocation is re-made on the others (:func:`att_planner.control.wheels.healthy_allocation`)
  and the planner is told their envelope (:mod:`.envelope`);
* ``exclude_sensor``: the tracker of that index, or the magnetometer, in the estimator's exclusion
  set (:attr:`att_planner.estimation.estimator.Estimator.excluded`);
* ``safe_mode``: safe mode (:mod:`.safe_mode`); also when the healthy wheels no longer span the body
  (the attitude cannot be controlled on them);
* any fault on the gyro: the gyro is not trusted (safe mode damps with B-dot).
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import FaultStatus


@dataclass(frozen=True)
class Responses:
    """What the flight software flies on, given the active faults."""

    healthy_wheels: tuple[bool, ...]
    wheels_controllable: bool          # the healthy wheels span the body
    excluded_sensors: frozenset[str]   # tracker names, "magnetometer"
    gyro_trusted: bool
    safe_mode: bool
    why: tuple[str, ...]               # the fault ids (or the reason) that ask for safe mode


def responses(active: Iterable[FaultStatus], wheel_axes, trackers: list[str]) -> Responses:
    """The responses to the ``active`` faults on a spacecraft with ``wheel_axes`` (3 × N) and the star
    trackers ``trackers`` (their names by index)."""
    G = np.asarray(wheel_axes, float).reshape(3, -1)
    healthy = np.ones(G.shape[1], bool)
    excluded, why, gyro_trusted = set(), [], True
    for f in active:
        if not f.active:
            continue
        if f.response == "exclude_wheel" and 0 <= f.index < healthy.size:
            healthy[f.index] = False
        elif f.response == "exclude_sensor":
            if f.component == "star_tracker" and 0 <= f.index < len(trackers):
                excluded.add(trackers[f.index])
            elif f.component == "magnetometer":
                excluded.add("magnetometer")
        elif f.response == "safe_mode":
            why.append(f.fault_id)
        if f.component == "gyro":
            gyro_trusted = False
    controllable = bool(healthy.any()) and np.linalg.matrix_rank(G[:, healthy]) == 3
    if G.shape[1] and not controllable:
        why.append("the healthy wheels do not span the body")
    return Responses(tuple(healthy.tolist()), controllable, frozenset(excluded), gyro_trusted, bool(why),
                     tuple(sorted(set(why))))
