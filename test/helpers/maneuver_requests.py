"""A valid PlanManeuver request as plain fields, and its validation with the test defaults."""
from __future__ import annotations

import math

import numpy as np

from att_planner.service.requests import ManeuverRequest, validate_maneuver
from att_sim.models import rotations as rot

NAN, INF = float("nan"), float("inf")
GOAL = rot.from_axis_angle([0, 0, 1], math.radians(135))
SUN = ([0.5, 0.866, 0.0], math.radians(47), "sun")
EARTH = ([0.0, 0.0, -1.0], math.radians(33), "earth")


def request(**fields) -> ManeuverRequest:
    base = dict(frame_id="eci", q_initial=rot.IDENTITY, q_final=GOAL, sensor_axis=np.array([1.0, 0, 0]),
                cones=[SUN, EARTH], method="eigenaxis_smooth")
    base.update(fields)
    return ManeuverRequest(**base)


def validate(req, **kw):
    args = dict(frame_id="eci", default_spacecraft="swift_demo", default_method="eigenaxis_smooth",
                default_budget=5.0)
    args.update(kw)
    return validate_maneuver(req, **args)
