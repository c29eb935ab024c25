"""The maneuver a controller flies (no ROS): its plan, start, zones and the law it hands over to.

The feedback's ``min_cone_margin`` covers the plan's cones and zones at their true positions now:
a :class:`~att_planner.zones.FittedZones` of the plan (:func:`plan_zones`), built once when it starts,
on the controller's ``sky`` (:class:`att_sim.models.ephemeris.Ephemeris` at the scenario epoch, whose
time is sim time), evaluated straight from the ephemeris at the current state's time (one
evaluation per feedback). The truth does not depend on the plan's epoch: a plan made for another
start instant shows the margins it really has. Without a ``sky`` (a scenario with no epoch) the
moving zones are left out: the margin is that of the cones and inertial zones only.
"""
from __future__ import annotations

from dataclasses import dataclass

from att_msgs_py.types import Plan
from att_planner.zones import FittedZones, zones_from_cones
from att_sim.models.ephemeris import Ephemeris

ZONE_FIT_WINDOW = 1.0                          # s: a FittedZones needs a window; the controller uses its truth only


@dataclass
class Maneuver:
    """The plan being executed, from sim time ``t0``, its zones (:func:`plan_zones`) and the
    pointing law it hands over to at its end (None: hold its final attitude after a settle time)."""

    plan: Plan
    t0: float
    zones: FittedZones | None = None
    ticks: int = 0
    after: object = None


def plan_zones(plan: Plan, sky: Ephemeris | None) -> FittedZones | None:
    """The plan's cones and zones on ``sky`` (moving zones left out without one); None when there
    are none. Only its truth is used (any time): the fit is over a short window."""
    zones = zones_from_cones(plan.cones, plan.sensor_axis) + [z for z in plan.zones
                                                              if sky is not None or z.body == "inertial"]
    if not zones:
        return None
    moving = any(z.body != "inertial" for z in zones)
    return FittedZones(zones, sky if moving else None, window=ZONE_FIT_WINDOW)
