"""The relaxed MILP bound: its slots cover each imaging interval, its slew-time bound stays below
the planner's slews, and on a short horizon it lies between the planned images and the accessible sites."""
from __future__ import annotations

import math

import numpy as np

from att_planner.imaging import bound, slews
from att_sim.models import rotations as rot

from .conftest import SCENARIO


def test_the_slots_cover_each_window_s_imaging_interval(planner):
    w, a, b = bound.slots(planner.windows, 2.0)
    for k in range(len(planner.windows)):
        mine = w == k
        assert math.isclose(a[mine].min(), planner.windows.open_s[k])
        assert math.isclose(b[mine].max(), planner.windows.close_s[k] - 2.0)
        assert np.all(b[mine] - a[mine] <= bound.SLOT_S + 1e-9) and np.all(a[mine][1:] == b[mine][:-1])


def test_the_slew_time_lower_bound_is_below_the_planner_s_slews(planner):
    sc = SCENARIO.spacecraft
    laws = planner.laws
    source, target = laws(0), laws(3)
    slew = slews.fastest(source(200.0), 200.0, target, planner.limits)
    angle = float(rot.angle_between(slew.plan.q[0], slew.plan.q[-1]))
    t_min = bound.slew_time_lower_bound(angle, sc.inertia, sc.wheel_torque_max, planner.limits.rate_max_rad_s)
    assert 0.0 < t_min < slew.duration_s
    assert np.all(np.diff(bound.slew_time_lower_bound(np.linspace(0, 3, 20), sc.inertia, 0.4, 0.087)) > 0)


def test_the_bound_lies_between_the_planned_images_and_the_accessible_sites(planner):
    result = bound.relaxed_bound(planner.windows, planner.sites, planner)
    planned = max(len(planner.plan(p).images) for p in ("greedy", "ours"))
    assert planned <= result["images"] + 1e-6 <= planner.windows.accessible().sum() + 1e-6
    assert result["images_lp"] >= result["images"] - 1e-6
