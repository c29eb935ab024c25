"""Schedules among zones that move: every leg keeps every zone at its physical time along
the whole tour (a leg starts when the earlier legs end), checked by att_planner.verification at the
zones' true positions."""
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.types import Cone, Status, Zone
from att_planner.methods import schedule as sch
from att_planner.reference import olivares_staffetti as ref
from att_planner.verification import predict, rejection, verify
from att_sim.models import rotations as rot
from helpers.skies import DescendingEphemeris

GRID = 10
X = np.array([1.0, 0.0, 0.0])
C = np.sqrt(0.5)


@pytest.fixture(scope="module")
def tour():
    """Out to 90° about z and back: the sensor x sweeps azimuth 0 → 90° → 0 in the xy-plane, about
    140 s each way. A 15° Sun zone descends through that plane at azimuth 45° about 210 s in (the
    return leg's middle) and is far above it during the outbound leg."""
    free = ref.problem(targets={"t": rot.from_axis_angle([0.0, 0.0, 1.0], np.deg2rad(90.0))})
    moving = replace(free, zones=[Zone("sun", "sun", X, np.deg2rad(15.0))], sky=DescendingEphemeris())
    options = {"search_intervals": GRID, "intervals": GRID}
    return moving, sch.plan_schedule(free, **options), sch.plan_schedule(moving, **options)


def _leg_margins(problem, plan):
    """Smallest true zone margin (rad) on each leg of an integrated plan."""
    traj = predict(problem, plan)
    m = problem.zone_sky().margins(traj.t, traj.q_BN, true=True).min(axis=1)
    ends = [0.0, *(p.time for p in plan.passages), plan.duration]
    return [m[(traj.t >= a) & (traj.t <= b)].min() for a, b in zip(ends[:-1], ends[1:])]


def test_a_moving_zone_is_kept_on_every_leg_at_its_time_in_the_tour(tour):
    moving, free_plan, plan = tour
    assert moving.zone_sky().moving
    # without the zone the return leg runs into it where it is at that time (not on the outbound leg)
    outbound, back = _leg_margins(moving, free_plan)
    assert outbound > np.deg2rad(10.0) and back < -np.deg2rad(10.0)
    assert rejection(verify(moving, free_plan)).startswith("enters keep-out zone sun")
    # with it, every leg clears the true zone and the passage and the final rest are met
    assert plan.status in (Status.OPTIMAL, Status.FEASIBLE), plan.message
    assert rejection(plan.verification) is None, rejection(plan.verification)
    outbound, back = _leg_margins(moving, plan)
    assert outbound > np.deg2rad(20.0)
    # the zone binds on the return leg only: it is met at the leg's physical time, t = sum of the
    # earlier legs' durations + time in the leg
    assert 0.0 <= back < np.deg2rad(1.0)
    assert 0.0 < plan.passages[0].time < plan.duration


def test_a_cone_across_the_tour_and_a_keep_in_zone_of_another_sensor_are_kept():
    """A cone centred on the sensor's straight path (the slerp guess runs through its axis) and a
    keep-in zone of body z about inertial z: the tour goes round the cone within the keep-in zone."""
    z = np.array([0.0, 0.0, 1.0])
    problem = replace(ref.problem(targets={"t": rot.from_axis_angle(z, np.deg2rad(90.0))}),
                      cones=[Cone(np.array([C, C, 0.0]), np.deg2rad(15.0), "sun")],
                      zones=[Zone("antenna", "inertial", z, np.deg2rad(30.0), True, z)])
    plan = sch.plan_schedule(problem, search_intervals=GRID, intervals=GRID)
    assert plan.status in (Status.OPTIMAL, Status.FEASIBLE), plan.message
    ver = plan.verification
    assert rejection(ver) is None, rejection(ver)
    assert min(ver.cone_margins) >= 0.0 and ver.zone_keep_in == [False, True]


def test_zone_options_are_checked():
    problem = ref.problem(targets={})
    with pytest.raises(ValueError, match="cone_margin_deg"):
        sch.plan_schedule(problem, cone_margin_deg=-1.0)
    with pytest.raises(ValueError, match="zone_refinements"):
        sch.plan_schedule(problem, zone_refinements=-1)
