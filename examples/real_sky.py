"""A slew in the real sky, without ROS: Sun, Moon and Earth-limb zones that move, planned and verified."""
from datetime import timedelta

import numpy as np

from att_planner.tools.closed_loop import plan_in_process
from att_sim.models import rotations as rot
from att_sim.models import scenario

leo = scenario.load("leo_observatory")             # TLE orbit, IGRF-14, DE421 Sun and Moon, frame gcrs
zones = leo.zones                                  # Sun 47 deg, Moon 23 deg, Earth limb + 10 deg on sensor +y
start = leo.epoch + timedelta(seconds=500)         # the maneuver's t = 0: the zones move from there
epoch = (int(start.timestamp()), start.microsecond * 1000)
goal = rot.from_axis_angle([1, 0, 0], np.radians(135))
plan = plan_in_process(leo, rot.IDENTITY, goal, [0, 1, 0], zones=zones, method="time_optimal", epoch=epoch)
margins = np.degrees(plan.verification.cone_margins)       # each zone at its true position along the path
print(f"plan: {plan.status} by {plan.method}, {plan.duration:.1f} s from {start:%Y-%m-%d %H:%M:%S} UTC")
print("verified margins:", ", ".join(f"{z.name} {m:.2f} deg" for z, m in zip(zones, margins)))
