"""The planner service in the real sky (no ROS): where a request's epoch and orbit come from, zones
in the problem and through a solver child, the closed-sky test with moving zones and several
sensors, zone padding, requests without a sky planned against their cones alone, and the review of
a flown plan's zones."""
from __future__ import annotations

import math
import pickle
from datetime import UTC, datetime, timedelta

import numpy as np
import pytest

from att_msgs_py import convert
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Plan, Verification, Zone
from att_planner import methods
from att_planner.service.planning import padded
from att_planner.service.sky import relaxed_caps
from att_planner.service.worker import run_isolated, warm_up
from att_planner.tools.review.figures import figure_sky
from att_planner.tools.review.run import Run
from att_planner.tools.review.summary import summary_of, zone_sky_for
from att_planner.zones import FittedZones
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.ephemeris import Ephemeris
from att_sim.models.orbit import TLEOrbit
from helpers.maneuver_requests import EARTH, SUN, request, validate

TLE = ("1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    07",
       "2 28485  20.5600  60.0000 0005000  90.0000  10.0000 14.95764766    08")
# 72 min past the TLE epoch the Swift slew (sensor +x, identity to 135 deg about z) starts and ends
# ~45 deg beyond the Earth limb; the Moon lies 21 deg off its eigenaxis path, inside its 23 deg zone
EPOCH = datetime(2026, 12, 21, 1, 12, tzinfo=UTC)
X, Y = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
ZONES = [Zone("sun", "sun", X, math.radians(47)), Zone("moon", "moon", X, math.radians(23)),
         Zone("earth", "earth_limb", X, math.radians(10))]
SUN_Y = Zone("sun", "sun", Y, math.radians(47))
LEO_GOAL = rot.from_axis_angle([1, 0, 0], math.radians(135))      # the earth_obs slew of att-bench sky, sensor +y


def sky_request(epoch=EPOCH, zones=ZONES, tle=TLE, **fields):
    return request(**{"cones": [], "zones": list(zones), "epoch": convert.epoch_parts(convert.epoch_msg(epoch)),
                      "tle_line1": tle[0],
                      "tle_line2": tle[1], **fields})


def leo(epoch=None, zones=None):
    """The earth_obs slew in the leo_observatory scenario (its epoch unless ``epoch``, its TLE, its
    zones unless ``zones``)."""
    zones = scen.load("leo_observatory").zones if zones is None else zones
    return validate(sky_request(epoch=epoch, zones=zones, tle=("", ""), q_final=LEO_GOAL, sensor_axis=Y,
                                frame_id="gcrs"), frame_id="gcrs", default_spacecraft="leo_observatory")


def test_a_request_without_a_sky_is_the_problem_of_before():
    problem = validate(request(cones=[SUN, EARTH])).problem
    assert problem.zones == [] and problem.epoch is None and problem.sky is None
    assert [c.name for c in problem.cones] == ["sun", "earth"]


def test_zero_epoch_and_no_tle_take_the_scenario_epoch_and_orbit_but_not_its_zones():
    problem = leo(zones=[SUN_Y]).problem
    assert problem.epoch == datetime(2026, 12, 21, tzinfo=UTC)
    assert isinstance(problem.sky.orbit, TLEOrbit) and problem.sky.orbit_offset == 0.0
    assert [z.name for z in problem.zones] == ["sun"]          # a request states its zones


def test_a_request_epoch_moves_the_scenario_orbit_and_a_request_tle_starts_at_it():
    later = datetime(2026, 12, 21, 2, 0, 0, 500_000, tzinfo=UTC)
    problem = leo(later, zones=[SUN_Y]).problem
    assert problem.epoch == later and problem.sky.orbit_offset == pytest.approx(7200.5, abs=1e-6)
    own = validate(sky_request()).problem                                # swift_demo has no epoch, no TLE
    assert own.epoch == EPOCH and own.sky.orbit.line1 == TLE[0] and own.sky.orbit_offset == 0.0
    r_scenario = problem.sky.position(0.0)
    r_request = validate(sky_request(epoch=later, zones=[ZONES[0]])).problem.sky.position(0.0)
    assert np.linalg.norm(r_scenario - r_request) < 1e-3                 # one TLE, one instant: one place


def test_inertial_zones_need_no_epoch_and_get_no_sky():
    zone = Zone("star", "inertial", np.array([0.0, 0.0, 1.0]), 0.3, direction=np.array([0.0, 0.0, -1.0]))
    problem = validate(sky_request(epoch=None, tle=("", ""), zones=[zone])).problem
    assert problem.epoch is None and problem.sky is None and problem.zones[0].name == "star"


def test_an_unnamed_zone_is_named_by_its_index():
    zone = Zone("", "sun", X, math.radians(20))
    assert [z.name for z in validate(sky_request(zones=[ZONES[0], zone])).problem.zones] == ["sun", "zone1"]


def test_a_moving_zone_problem_crosses_to_a_solver_child_and_back():
    warm_up()
    problem = validate(sky_request()).problem
    restored = pickle.loads(pickle.dumps(problem))         # the sky and its TLE orbit as their recipes
    assert np.allclose(restored.sky.moon_direction(60.0), problem.sky.moon_direction(60.0), atol=1e-12)
    plan = run_isolated(methods.get("eigenaxis_smooth"), problem, {}, wait=20.0)
    assert plan is not None and "enters keep-out zone moon" in plan.message, plan.message   # the zones, moving


def test_moving_zones_relax_over_the_window_and_fixed_ones_do_not():
    problem = validate(sky_request(zones=ZONES + [Zone("radiator", "sun", -Y, math.radians(140), keep_in=True)])
                       ).problem
    zone_sky = problem.zone_sky()
    caps = {z.name: c for z, c in zip(zone_sky.zones, relaxed_caps(zone_sky, np.arange(4)))}
    theta0 = zone_sky.true_half_angles(0.0)
    # the nadir sweeps 37 deg in the 600 s window (4 deg/min): the Earth's fixed core is that much smaller
    assert zone_sky.window == 600.0
    assert theta0[2] - math.radians(38) < caps["earth"].half_angle < theta0[2] - math.radians(36)
    assert theta0[0] - math.radians(0.2) < caps["sun"].half_angle < theta0[0]      # the Sun barely moves
    assert caps["radiator"].keep_in and caps["radiator"].half_angle > theta0[3]
    fixed = FittedZones([Zone("c", "inertial", X, 0.4, direction=Y)], None, 600.0)
    assert relaxed_caps(fixed, np.arange(1))[0].half_angle == 0.4


def test_keep_in_and_keep_out_zones_close_the_sky_of_their_own_sensor():
    z = np.array([0.0, 0.0, 1.0])
    keep_in = Zone("antenna", "inertial", z, math.radians(60), keep_in=True, direction=z)
    # a wall of keep-out zones along the great circle 25 deg from +z towards +x crosses the keep-in
    # cap: the +z sensor's start (+z) and goal (50 deg towards +x) lie on either side
    p = np.array([math.sin(math.radians(25)), 0.0, math.cos(math.radians(25))])
    wall = [Zone(f"w{k}", "inertial", z, math.radians(14), direction=math.cos(a) * p + math.sin(a) * Y)
            for k, a in enumerate(np.radians(np.arange(-90, 91, 18)))]
    goal = rot.from_axis_angle([0, 1, 0], math.radians(50))
    with pytest.raises(RequestError) as err:
        validate(sky_request(epoch=None, tle=("", ""), zones=[keep_in, *wall], q_final=goal))
    assert err.value.code == ErrorCode.INFEASIBLE and "sensor axis [0.0, 0.0, 1.0]" in err.value.message
    gap = [keep_in, *wall[:5], *wall[6:]]            # the wall without its middle zone
    assert len(validate(sky_request(epoch=None, tle=("", ""), zones=gap, q_final=goal)).problem.zones) == 11


def test_padding_widens_keep_out_narrows_keep_in_and_spares_the_ends():
    radiator = Zone("radiator", "sun", -Y, math.radians(140), keep_in=True)
    problem = validate(sky_request(zones=ZONES + [radiator])).problem
    room = problem.zone_sky().margins(0.0, np.array([problem.q_initial, problem.q_final]), true=True).min(axis=0)
    pad = math.radians(2.0)
    wider = padded(problem, pad)
    for z, w, r in zip(problem.zones, wider.zones, room):
        expected = min(pad, 0.5 * r)
        assert w.half_angle == pytest.approx(z.half_angle + (-expected if z.keep_in else expected))
    assert wider.zone_sky().margins(0.0, np.array([wider.q_initial, wider.q_final]), true=True).min() > 0
    assert padded(problem, 0.0) is problem


def _rest_run(t0: float, plan) -> Run:
    """A reviewed segment of 100 s from sim time ``t0`` at rest at identity, flying ``plan``."""
    t = np.linspace(0.0, 100.0, 51)
    n, zero = len(t), np.zeros((len(t), 3))
    return Run(kind="maneuver", t0=t0, t=t, q=np.tile(rot.IDENTITY, (n, 1)), omega=zero, wheel_speeds=np.zeros((n, 0)),
               wheel_torques=np.zeros((n, 0)), dipole=zero, body_torque=zero, command_timeout=np.zeros(n, bool),
               cmd_t=np.zeros(0), cmd_mode=np.zeros(0, int), cmd_wheel_torques=np.zeros((0, 0)),
               cmd_dipole=np.zeros((0, 3)), goal=rot.IDENTITY, plan=plan, goal_end=100.0)


def test_the_review_places_moving_zones_where_the_simulator_flew_them(tmp_path):
    leo_scenario = scen.load("leo_observatory")
    t0 = 3000.0
    plan = Plan(t=np.array([0.0, 100.0]), torque=np.zeros((2, 3)), q=np.tile(rot.IDENTITY, (2, 1)),
                omega=np.zeros((2, 3)), sensor_axis=Y, zones=leo_scenario.zones, plan_id="p",
                epoch=leo_scenario.epoch + timedelta(seconds=t0 - 60.0), spacecraft="leo_observatory",
                verification=Verification(0.0, 0.0, 0.1, [0.1] * 3, 0.5, 0.0, 0.0, 10))
    run = _rest_run(t0, plan)
    zones, note = zone_sky_for(run, leo_scenario)
    sky = Ephemeris(leo_scenario.epoch, leo_scenario.orbit_model)          # sim time zero is the scenario's epoch
    assert np.allclose(zones.true_axes(0.0)[1], sky.moon_direction(t0), atol=1e-9)
    limb = math.acos(sky.nadir(t0 + 50.0) @ Y) - sky.earth_angular_radius(t0 + 50.0) - math.radians(10)
    assert zones.margins(50.0, rot.IDENTITY, true=True)[0, 2] == pytest.approx(limb, abs=1e-9)
    assert "flown from 2026-12-21T00:50:00" in note and "(+60.0 s)" in note
    summary = summary_of(run, leo_scenario.spacecraft, zones, note)
    assert summary["min_margin_deg"]["earth"] == pytest.approx(
        math.degrees(zones.margins(run.t, run.q, true=True)[:, 2].min()))
    assert figure_sky(run, tmp_path / "sky.png", zones).stat().st_size > 10_000
    dropped, why = zone_sky_for(run, scen.load("swift_demo"))      # no epoch: the simulator flew no real sky
    assert dropped.zones == [] and "has no epoch" in why
