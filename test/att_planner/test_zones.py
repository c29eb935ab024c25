"""Zones that move: the Chebyshev representation, margins, the frozen baseline, the
request checks and the real sky."""
import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Zone
from att_planner import cones as cone_checks
from att_planner.problem import ManeuverProblem
from att_planner.reference.time_optimal_cases import case_problem
from att_planner.zones import FIT_TOLERANCE, FittedZones, zones_from_cones
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

R_E = 6378.137e3


class CircularEphemeris:
    """A synthetic sky: circular equatorial orbit of radius ``R_E + altitude`` (x at t = 0, moving
    towards y), the Sun fixed far along +x, the Moon fixed at 384 000 km along +y."""

    def __init__(self, altitude=580e3, period=5800.0):
        self.r, self.n = R_E + altitude, 2 * np.pi / period

    def position(self, t):
        u = self.n * np.asarray(t, float)
        return self.r * np.stack([np.cos(u), np.sin(u), np.zeros_like(u)], -1)

    def sun(self, t):
        return np.broadcast_to([1.496e11, 0.0, 0.0], np.shape(t) + (3,))

    def moon(self, t):
        return np.broadcast_to([0.0, 3.844e8, 0.0], np.shape(t) + (3,))

    def _from_spacecraft(self, p, t):
        d = p - self.position(t)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def sun_direction(self, t):
        return self._from_spacecraft(self.sun(t), t)

    def moon_direction(self, t):
        return self._from_spacecraft(self.moon(t), t)

    def nadir(self, t):
        p = self.position(t)
        return -p / np.linalg.norm(p, axis=-1, keepdims=True)

    def earth_angular_radius(self, t):
        return np.arcsin(R_E / np.linalg.norm(self.position(t), axis=-1))


SKY = CircularEphemeris()
Y = np.array([0.0, 1.0, 0.0])
ZONES = [Zone("sun", "sun", Y, math.radians(47)), Zone("moon", "moon", Y, math.radians(23)),
         Zone("limb", "earth_limb", Y, math.radians(10)),
         Zone("star", "inertial", [1.0, 0.0, 0.0], 0.3, direction=[0.0, 0.0, 1.0])]


@pytest.fixture(scope="module")
def long_sky():
    return FittedZones(ZONES, SKY, 20000.0)        # 3.4 orbits: several pieces


def test_fit_is_within_its_tolerance_between_the_check_points_and_its_derivative_is_exact(long_sky):
    zs = long_sky
    assert len(zs.pieces) > 2 and zs.degree <= 40 and zs.fit_error <= FIT_TOLERANCE
    t = np.random.default_rng(1).uniform(0, zs.window, 3000)
    assert np.abs(zs.axes(t) - zs.true_axes(t)).max() <= FIT_TOLERANCE
    assert np.abs(zs.half_angles(t) - zs.true_half_angles(t)).max() <= FIT_TOLERANCE
    h = 1e-2
    fd = (zs.true_axes(t + h) - zs.true_axes(t - h)) / (2 * h)
    assert np.abs(zs.axes_rate(t[10:-10]) - fd[10:-10]).max() < 1e-8        # |a'| = n ≈ 1.1e-3 /s
    # the limb turns at the orbit rate n about +z: da/dt = n ẑ × a
    limb = zs.axes_rate(t)[:, 2]
    np.testing.assert_allclose(limb, SKY.n * np.cross([0, 0, 1], zs.axes(t)[:, 2]), atol=1e-9)
    assert np.all(zs.axes_rate(t)[:, 3] == 0) and np.all(zs.half_angles_rate(t)[:, 3] == 0)


def test_casadi_evaluation_is_the_numpy_one(long_sky):
    import casadi as ca
    zs = long_sky
    t = ca.SX.sym("t")
    axes, half = zs.casadi(t)
    f = ca.Function("zones", [t], [ca.horzcat(*axes).T, ca.vertcat(*half)])
    df = ca.Function("rates", [t], [ca.jacobian(ca.vertcat(*axes), t)])
    for tk in (0.0, 1234.5, 9999.9, zs.pieces[1], zs.window):
        a, th = f(tk)
        np.testing.assert_allclose(np.array(a), zs.axes(tk), rtol=0, atol=1e-13)
        np.testing.assert_allclose(np.array(th).ravel(), zs.half_angles(tk), rtol=0, atol=1e-13)
        np.testing.assert_allclose(np.array(df(tk)).reshape(4, 3), zs.axes_rate(tk), rtol=0, atol=1e-13)
    # the constraints: keep-out a·b − cos θ ≤ 0 is the margin's sign
    R = ca.SX.sym("R", 3, 3)
    g = ca.Function("g", [t, R], [ca.vertcat(*zs.casadi_constraints(t, R))])
    q = rot.from_axis_angle([1.0, 0.3, 0.2], 2.0)
    m = zs.margins(700.0, q)[0]
    assert np.array_equal(np.array(g(700.0, rot.dcm_NB(q))).ravel() <= 0, m >= 0)


def test_outside_the_window_the_fit_refuses_but_the_truth_answers(long_sky):
    with pytest.raises(ValueError, match="outside the zones' window"):
        long_sky.axes(long_sky.window + 1.0)
    assert long_sky.true_axes(long_sky.window + 1.0).shape == (4, 3)
    assert FittedZones(ZONES[3:], None, 10.0).axes(1e6).shape == (1, 3)       # inertial: any time


def test_a_sky_that_is_not_finite_is_refused_not_fitted_or_judged():
    class Decayed(CircularEphemeris):
        def position(self, t):
            return np.where(np.asarray(t)[..., None] > 400.0, np.nan, super().position(t))

    with pytest.raises(ValueError, match="not finite at t = 4"):
        FittedZones(ZONES, Decayed(), 600.0)
    zs = FittedZones(ZONES, Decayed(), 300.0)
    with pytest.raises(ValueError, match="not finite"):
        zs.margins(np.array([100.0, 500.0]), rot.IDENTITY, true=True)


def test_earth_limb_at_580_km_is_66_deg_plus_its_margin():
    zs = FittedZones(ZONES[2:3], SKY, 600.0)
    expected = math.degrees(math.asin(R_E / (R_E + 580e3)))
    assert expected == pytest.approx(66.44, abs=0.01)
    assert math.degrees(zs.half_angles(300.0)[0]) == pytest.approx(expected + 10.0, abs=1e-6)


def test_a_zone_rotating_at_the_orbit_rate_margins_by_hand():
    """Boresight +y body = +x inertial at identity; the nadir −(cos nt, sin nt, 0) is π − nt away."""
    zs = FittedZones([Zone("limb", "earth_limb", Y, 0.0), Zone("limb in", "earth_limb", Y, 0.0, keep_in=True)],
                 SKY, 1200.0)
    q = rot.from_axis_angle([0.0, 0.0, 1.0], -math.pi / 2)          # body +y -> inertial +x
    t = np.linspace(0, 1200, 7)
    rho = math.asin(R_E / SKY.r)
    m = zs.margins(t, q)                                              # one attitude over 7 times
    np.testing.assert_allclose(m[:, 0], np.pi - SKY.n * t - rho, atol=1e-8)
    np.testing.assert_allclose(m[:, 1], -(np.pi - SKY.n * t - rho), atol=1e-8)     # keep-in: sign flipped
    np.testing.assert_allclose(zs.margins(t, np.tile(q, (7, 1)), true=True), m, atol=1e-8)
    assert zs.margins(600.0, np.tile(q, (3, 1))).shape == (3, 2)


def test_frozen_zones_stay_where_they_were_at_t0(long_sky):
    frozen = long_sky.frozen()
    assert not frozen.moving and long_sky.moving
    q = np.tile(rot.from_axis_angle([0.0, 0.0, 1.0], 1.0), (3, 1))
    t = np.array([0.0, 500.0, 1000.0])
    fm, mm = frozen.margins(t, q), long_sky.margins(t, q)
    np.testing.assert_allclose(fm[0], mm[0], atol=1e-8)
    np.testing.assert_allclose(fm, np.tile(fm[0], (3, 1)), atol=0)
    assert abs(mm[2, 2] - mm[0, 2]) > math.radians(30)        # the limb moved 62 deg in 1000 s
    assert fm[0, 2] == pytest.approx(mm[0, 2], abs=1e-8)


def test_cones_as_zones_reproduce_the_cone_margins_exactly():
    problem = case_problem("swift")
    q = rot.normalize(np.random.default_rng(2).normal(size=(500, 4)))
    expected = cone_checks.margins(q, problem.sensor_axis, problem.cones)
    zs = FittedZones(zones_from_cones(problem.cones, problem.sensor_axis), None, 600.0)
    assert np.array_equal(zs.margins(np.zeros(500), q), expected)
    assert np.array_equal(problem.zone_sky().margins(0.0, q, true=True), expected)
    assert problem.zone_sky() is problem.zone_sky()             # cached


def _problem(zones, q_final=None, **kw):
    sc = Spacecraft(np.eye(3), body_torque_max=1.0)
    q_final = rot.from_axis_angle([1.0, 0.0, 0.0], 0.5) if q_final is None else q_final
    return ManeuverProblem(sc, rot.IDENTITY.copy(), q_final, Y, zones=zones, sky=SKY, **kw)


@pytest.mark.parametrize("zone, code, words", [
    (Zone("x", "jupiter", Y, 0.2), ErrorCode.INVALID_ZONE, "body"),
    (Zone("x", "sun", [0.0, 0.0, 0.0], 0.2), ErrorCode.INVALID_ZONE, "sensor_axis"),
    (Zone("x", "sun", Y, math.pi), ErrorCode.INVALID_ZONE, "half_angle"),
    (Zone("x", "earth_limb", Y, -0.1), ErrorCode.INVALID_ZONE, "margin"),
    (Zone("x", "inertial", Y, 0.2), ErrorCode.INVALID_ZONE, "direction"),
    (Zone("x", "inertial", Y, 0.2, direction=[0.0, 1.0, 0.0]), ErrorCode.ZONE_AT_END, "start attitude is inside"),
    (Zone("x", "inertial", Y, 0.2, True, [0.0, 0.0, 1.0]), ErrorCode.ZONE_AT_END, "outside keep-in"),
])
def test_bad_zones_and_violated_ends_have_a_code_and_a_sentence(zone, code, words):
    issue = cone_checks.zone_issue(_problem([zone]))
    assert issue is not None and issue[0] == code and words in issue[1]
    with pytest.raises(RequestError) as err:
        cone_checks.check_zones(_problem([zone]))
    assert err.value.code == code


def test_contradictory_zones_and_a_goal_judged_at_t0():
    keep_in = Zone("antenna", "earth_limb", Y, 0.0, keep_in=True)        # the Earth's disc, 66 deg
    inside_out = Zone("big", "inertial", Y, math.radians(170), direction=[-1.0, 0.0, 0.0])
    code, why = cone_checks.zone_issue(_problem([keep_in, inside_out]))
    assert code == ErrorCode.CONTRADICTORY_ZONES and "entirely inside" in why
    a = Zone("a", "inertial", Y, 0.3, True, [1.0, 0.0, 0.0])
    b = Zone("b", "inertial", Y, 0.3, True, [0.0, 1.0, 0.0])
    code, why = cone_checks.zone_issue(_problem([a, b]))
    assert code == ErrorCode.CONTRADICTORY_ZONES and "do not meet" in why
    # another sensor's keep-in cone is no contradiction
    c = Zone("c", "inertial", [1.0, 0.0, 0.0], 0.3, True, [1.0, 0.0, 0.0])
    assert cone_checks.contradictory_zones(FittedZones([a, c], None, 10.0)) == ""
    # the goal (boresight −z) inside the Sun zone at t = 0
    sun = Zone("sun", "sun", Y, 0.5)
    goal = rot.from_axis_angle([0.0, 0.0, 1.0], -math.pi / 2)          # +y body -> +x: the Sun
    code, why = cone_checks.zone_issue(_problem([sun], goal))
    assert code == ErrorCode.ZONE_AT_END and "goal attitude is inside keep-out zone sun" in why
    assert "infeasible request" in cone_checks.blocked_endpoint(_problem([sun], goal))
    assert cone_checks.zone_issue(_problem([sun])) is None
    sky_less = ManeuverProblem(Spacecraft(np.eye(3), body_torque_max=1.0), rot.IDENTITY, rot.IDENTITY, Y, zones=[sun])
    code, why = cone_checks.zone_issue(sky_less)
    assert code == ErrorCode.INVALID_ZONE and "needs a sky" in why


def test_default_window_bounds_the_slew():
    p = _problem(ZONES)
    assert p.zone_sky().window == 600.0
    slow = ManeuverProblem(Spacecraft(np.eye(3) * 1e4, body_torque_max=0.01), rot.IDENTITY,
                           rot.from_axis_angle([0, 0, 1], 3.0), Y, zones=ZONES, sky=SKY)
    # 2 sqrt(φ J/T̄) = 2 sqrt(3e6) ≈ 3464 s, × 4
    assert slow.zone_sky().window == pytest.approx(8 * math.sqrt(3e6), rel=1e-9)
    assert slow.zone_sky(900.0).window == 900.0


def test_the_real_sky_of_leo_observatory_fits_within_tolerance():
    """A LEO TLE (≈ 577 km, 14.96 rev/day) on 2026-12-21: Sun, Moon and Earth limb + 10 deg."""
    from att_sim.models.ephemeris import Ephemeris
    from att_sim.models.orbit import TLEOrbit

    epoch = "2026-12-21T00:00:00Z"
    line1 = "1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    07"
    line2 = "2 28485  20.5600  60.0000 0005000  90.0000  10.0000 14.95764766    08"
    sky = Ephemeris(epoch, TLEOrbit(epoch, line1, line2))
    zs = FittedZones(ZONES[:3], sky, 3000.0)
    assert zs.moving and zs.fit_error <= FIT_TOLERANCE
    t = np.random.default_rng(3).uniform(0, 3000, 500)
    assert np.abs(zs.axes(t) - zs.true_axes(t)).max() <= FIT_TOLERANCE
    np.testing.assert_allclose(zs.true_axes(t)[:, 1], sky.moon_direction(t), atol=0)
    altitude = np.linalg.norm(sky.position(t), axis=-1) - R_E
    assert altitude.min() > 560e3 and altitude.max() < 600e3
    np.testing.assert_allclose(zs.half_angles(t)[:, 2], np.arcsin(R_E / (R_E + altitude)) + math.radians(10), atol=1e-8)
    # the limb turns at the orbit rate (2π / 96.3 min ≈ 3.7 deg/min), the Sun barely moves
    rates = np.linalg.norm(zs.axes_rate(t), axis=-1)
    assert np.degrees(rates[:, 2]).mean() * 60 == pytest.approx(360 / (1440 / 14.95764766), rel=0.02)
    assert np.degrees(rates[:, 0]).max() * 60 < 0.1


def test_a_goal_inside_a_moving_zone_at_t0_is_refused_only_if_no_arrival_time_clears_it():
    limb = Zone("limb", "earth_limb", Y, 0.0)          # 66.4 deg about nadir, nadir turning at 0.062 deg/s
    leaving = rot.from_axis_angle([0.0, 0.0, 1.0], math.radians(30))   # boresight 60 deg from nadir(0): clear at ~100 s
    assert SKY.earth_angular_radius(0.0) > math.radians(60)
    assert cone_checks.zone_issue(_problem([limb], leaving)) is None
    staying = rot.from_axis_angle([0.0, 0.0, 1.0], math.radians(90))   # boresight at nadir(0): inside for 600 s
    code, why = cone_checks.zone_issue(_problem([limb], staying))
    assert code == ErrorCode.ZONE_AT_END and "at every arrival time in [0, 600] s" in why
