"""The strip's geometry and its reference, against independent recomputations: the path's start on the
geodetic point, its length and the scan speed from chords, the two constructions agreeing, the
boresight on the aim point, the detector's across-track axis across the strip's ground direction,
the closed-form rate and acceleration against central differences of the attitude."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.guidance import reference
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry, geodetic_to_itrs
from att_planner.guidance.strip import MAX_STRIP_LENGTH_M, Strip, StripLaw, strip_start_goal, tracking_demand
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

AEOS = scen.load("aeos")
GEOMETRY = PointingGeometry.of(world.Environment.from_scenario(AEOS))
BORESIGHT, ALONG = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
START = 300.0                      # s: the scan's start
SPEED = 6000.0                     # m/s


def strip(azimuth_deg: float = 60.0, length_m: float = 50e3) -> Strip:
    lat, lon = site_in_view(GEOMETRY, START, math.radians(20.0), math.radians(90.0))
    return Strip.from_azimuth(lat, lon, math.radians(azimuth_deg), length_m, 100.0, SPEED)


def test_the_path_starts_on_the_site_and_is_as_long_as_asked():
    s = strip()
    lat, lon = site_in_view(GEOMETRY, START, math.radians(20.0), math.radians(90.0))
    assert np.linalg.norm(s.point(0.0)[0] - geodetic_to_itrs(lat, lon, 100.0)) < 1e-6
    # the length from 2000 chords (a curve longer than its chords by ~ L κ² h² / 24: below 1 mm here)
    theta = np.linspace(0.0, s.theta_end, 2001)
    points = np.array([s.point(x)[0] for x in theta])
    assert abs(np.linalg.norm(np.diff(points, axis=0), axis=1).sum() - 50e3) < 1e-3
    # the azimuth: the first step heads 60 deg east of north
    up = geodetic_to_itrs(lat, lon, 1.0) - geodetic_to_itrs(lat, lon, 0.0)
    north = geodetic_to_itrs(lat + 1e-7, lon, 100.0) - geodetic_to_itrs(lat, lon, 100.0)
    step = points[1] - points[0]
    east = rot.cross(north, up)
    assert math.degrees(math.atan2(step @ east / np.linalg.norm(east), step @ north / np.linalg.norm(north))) == \
        pytest.approx(60.0, abs=1e-4)


def test_the_start_end_form_is_the_same_strip():
    s = strip()
    end_lat, end_lon = s.geodetic(s.length_m)
    lat, lon = site_in_view(GEOMETRY, START, math.radians(20.0), math.radians(90.0))
    t = Strip.between(lat, lon, end_lat, end_lon, 100.0, SPEED)
    assert t.length_m == pytest.approx(s.length_m, abs=1e-3)
    for arc in (0.0, 17e3, 50e3):
        assert np.linalg.norm(t.point(t.theta_of(arc))[0] - s.point(s.theta_of(arc))[0]) < 1e-3


def test_the_aim_point_moves_at_the_scan_speed_and_the_boresight_is_on_it():
    s = strip()
    law = StripLaw(GEOMETRY, s, BORESIGHT, ALONG, START)
    for dt in (0.0, 3.0, 8.0):
        a = s.point(s.theta_of(SPEED * dt))[0]
        b = s.point(s.theta_of(SPEED * (dt + 0.1)))[0]
        assert np.linalg.norm(b - a) == pytest.approx(SPEED * 0.1, rel=1e-8)
        t = START + dt
        sight = np.asarray(GEOMETRY.dcm_EN(t)).T @ a - GEOMETRY.state_N(t)[0]
        q = law.attitude(t)
        boresight_N = rot.dcm_NB(q) @ BORESIGHT
        assert np.linalg.norm(rot.cross(boresight_N, sight / np.linalg.norm(sight))) < 1e-9
        # the detector line (boresight x along-track) is across the strip's ground direction
        tangent_E = s.point(s.theta_of(SPEED * dt + 1.0))[0] - s.point(s.theta_of(SPEED * dt - 1.0))[0]
        tangent_N = np.asarray(GEOMETRY.dcm_EN(t)).T @ tangent_E / np.linalg.norm(tangent_E)
        across_N = rot.dcm_NB(q) @ rot.cross(BORESIGHT, ALONG)
        assert abs(across_N @ tangent_N) < 1e-9


@pytest.mark.parametrize("azimuth", [0.0, 60.0, 170.0])
def test_the_rate_and_acceleration_are_the_attitude_s_derivatives(azimuth):
    law = StripLaw(GEOMETRY, strip(azimuth), BORESIGHT, ALONG, START)
    for t in (START, START + 5.0):
        exact, numeric = law.reference(t), reference(law.attitude, t, h=0.01)
        assert np.linalg.norm(exact.omega_RN_R) > math.radians(0.1)
        assert np.linalg.norm(exact.omega_RN_R - numeric.omega_RN_R) < 1e-9
        assert np.linalg.norm(exact.omega_dot_RN_R - numeric.omega_dot_RN_R) < 1e-7


def test_the_goal_is_the_first_point_at_the_scan_s_rate():
    s = strip()
    goal = strip_start_goal(GEOMETRY, s, BORESIGHT, ALONG)
    for t in (200.0, 300.0):
        q, w = goal(t)
        ref = StripLaw(GEOMETRY, s, BORESIGHT, ALONG, t).reference(t)
        assert rot.angle_between(q, ref.q_RN) < 1e-12 and np.linalg.norm(w - ref.omega_RN_R) < 1e-12


def test_the_tracking_demand_is_within_the_aeos_limits():
    rate, torque = tracking_demand(AEOS.spacecraft, GEOMETRY, strip(), BORESIGHT, ALONG, START)
    assert 0.0 < rate < math.radians(5.0) and 0.0 < torque < AEOS.spacecraft.body_torque_max


@pytest.mark.parametrize("make", [
    lambda: Strip.between(0.3, 0.2, 0.3, 0.2, 0.0, SPEED),                      # zero length
    lambda: Strip.from_azimuth(0.3, 0.2, 0.0, 0.0, 0.0, SPEED),
    lambda: Strip.from_azimuth(0.3, 0.2, 0.0, 2 * MAX_STRIP_LENGTH_M, 0.0, SPEED),
    lambda: Strip.from_azimuth(0.3, 0.2, 0.0, 10e3, 0.0, 0.0),                  # no scan speed
    lambda: Strip.from_azimuth(0.3, 0.2, 0.0, 10e3, 0.0, math.nan),
    lambda: Strip.between(0.3, 0.2, -0.3, 0.2 + math.pi, 0.0, SPEED),          # the antipode
])
def test_a_strip_without_a_path_or_a_speed_is_refused(make):
    with pytest.raises(ValueError):
        make()
