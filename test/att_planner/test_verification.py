"""The verification judges every zone at its true position at each dense sample's time."""
import math
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.types import Cone, Status, Zone
from att_planner.methods.constrained_axis import plan_constrained_axis
from att_planner.methods.eigenaxis import plan_eigenaxis
from att_planner.problem import ManeuverProblem
from att_planner.verification import TOLERANCES, rejection, verify
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

R_E = 6378.137e3
Y = np.array([0.0, 1.0, 0.0])


class PolarEphemeris:
    """Only the Earth of a synthetic sky: circular orbit of radius 26 378 km in the x-z plane,
    at phase ``u0`` at t = 0, period 5800 s (the nadir turns 3.7 deg a minute about −y); the Earth's
    disc is 14.0 deg in radius, the limb zone with its 10 deg margin 24.0 deg."""

    def __init__(self, u0_deg):
        self.r, self.n, self.u0 = R_E + 20000e3, 2 * np.pi / 5800.0, math.radians(u0_deg)

    def position(self, t):
        u = self.n * np.asarray(t, float) + self.u0
        return self.r * np.stack([np.cos(u), np.zeros_like(u), np.sin(u)], -1)

    def nadir(self, t):
        return -self.position(t) / self.r

    def earth_angular_radius(self, t):
        return np.full(np.shape(t), math.asin(R_E / self.r))


def _problem(u0_deg=240, **kw):
    """The earth_obs slew (J = diag(3000, 4500, 6000), 0.25 N m, 135 deg about body x, sensor +y)
    with the limb zone moving across the eigenaxis path: at u0 = 240 deg the path clears the zone
    as it is at t = 0 by 6.0 deg and enters the moving one by 6.4 deg."""
    sc = Spacecraft(np.diag([3000.0, 4500.0, 6000.0]), body_torque_max=0.25)
    zones = [Zone("limb", "earth_limb", Y, math.radians(10))] + kw.pop("zones", [])
    return ManeuverProblem(sc, rot.IDENTITY.copy(), rot.from_axis_angle([1.0, 0.0, 0.0], math.radians(135)), Y,
                           zones=zones, sky=PolarEphemeris(u0_deg), **kw)


@pytest.fixture(scope="module")
def frozen_plan():
    moving = _problem()
    frozen = replace(moving, zones=moving.zone_sky().frozen_zones(), sky=None)
    return moving, frozen, plan_eigenaxis(frozen)


def test_a_plan_that_clears_the_frozen_zone_is_caught_entering_the_moving_one(frozen_plan):
    moving, frozen, plan = frozen_plan
    assert plan.status == Status.FEASIBLE                  # verified against the frozen zones
    assert plan.verification.min_cone_margin == pytest.approx(math.radians(6.01), abs=math.radians(0.02))
    ver = verify(moving, plan, steps=400)
    assert ver.min_cone_margin == pytest.approx(math.radians(-6.43), abs=math.radians(0.02))
    assert ver.zone_names == ["limb"] and ver.zone_keep_in == [False]
    assert rejection(ver) == f"enters keep-out zone limb by {math.degrees(-ver.min_cone_margin):.3f} deg"


def test_cones_come_first_and_a_keep_in_zone_left_is_named(frozen_plan):
    moving, _, plan = frozen_plan
    cone = Cone(np.array([0.0, 0.0, -1.0]), math.radians(5.0), "down")
    antenna = Zone("antenna", "inertial", [0.0, 0.0, 1.0], math.radians(60), True, [0.0, 0.0, 1.0])
    pb = replace(moving, cones=[cone], zones=moving.zones + [antenna])
    ver = verify(pb, plan, steps=400)
    assert ver.zone_names == ["down", "limb", "antenna"] and ver.zone_keep_in == [False, False, True]
    # body +z starts on +z inertial and turns 135 deg about x: 75 deg beyond the 60 deg keep-in cone
    assert ver.cone_margins[2] == pytest.approx(math.radians(-75.0), abs=1e-3)
    assert rejection(ver).startswith("leaves keep-in zone antenna by 75.0")
    assert ver.min_cone_margin == min(ver.cone_margins) and TOLERANCES.cone_penetration == 0.0


def test_constrained_axis_clears_the_moving_zone(frozen_plan):
    moving, _, frozen = frozen_plan
    plan = plan_constrained_axis(moving)
    assert plan.status == Status.FEASIBLE and plan.message == "route: tilt +30 deg about normal 2"
    assert plan.verification.min_cone_margin > 0 and rejection(plan.verification) is None
    assert plan.duration == pytest.approx(480.0, abs=0.5) and frozen.duration < 340     # what the motion costs
    # the ride round the limb as it is mid-ride, widened by its motion, clears it too (slower)
    ride = next(c for c in plan.stats["candidates"] if c["route"] == "ride limb + then roll")
    assert ride["min_margin"] > 0 and 0 < ride["ride_time"] < ride["tf"] and ride["widening"] > 0


def test_a_figure_that_is_nan_is_never_acceptable(frozen_plan):
    ver = frozen_plan[2].verification
    assert rejection(ver) is None
    for name in ("final_attitude_error", "final_rate", "min_cone_margin", "torque_ratio", "wheel_speed_ratio"):
        assert rejection(replace(ver, **{name: math.nan})) is not None, name
    nan_zone = replace(ver, min_cone_margin=math.nan, cone_margins=[math.nan])
    assert rejection(nan_zone) == "enters keep-out zone limb by nan deg"
    assert rejection(replace(ver, passage_attitude_errors=[math.nan], passage_rates_z=[0.0])).startswith("passage 0")
