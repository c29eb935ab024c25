"""Guidance against hand-checked and independently computed cases: the nadir reference
turns at the orbit rate about the orbit normal, a ground target's line of sight is skyfield's, the
Sun is on the primary axis, the two-vector alignment puts the primary exactly and the secondary as
close as it can, and every hostile pointing request is refused with 314 naming the field."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import PointingMode
from att_planner.guidance import reference
from att_planner.guidance.laws import PointingGeometry, two_vector_attitude
from att_planner.guidance.modes import law_of
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

SWIFT = scen.load("swift_demo")
LEO = scen.load("leo_observatory")
RNG = np.random.default_rng(15)


def sky_of(s) -> PointingGeometry:
    return PointingGeometry.of(world.Environment.from_scenario(s))


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def test_two_vector_alignment_puts_the_primary_exactly_and_the_secondary_as_close_as_it_can():
    for _ in range(50):
        p, s, P, S = (unit(RNG.normal(size=3)) for _ in range(4))
        R = rot.dcm_NB(two_vector_attitude(p, s, P, S))
        assert np.allclose(R @ p, P, atol=1e-12)
        # the secondary is as close as the primary allows: their angles to the primary differ by the gap
        best = abs(math.acos(np.clip(p @ s, -1, 1)) - math.acos(np.clip(P @ S, -1, 1)))
        assert math.acos(np.clip((R @ s) @ S, -1, 1)) == pytest.approx(best, abs=1e-9)
    with pytest.raises(ValueError, match="parallel"):
        two_vector_attitude([0, 0, 1], [1, 0, 0], [0, 1, 0], [0, -1, 0])     # directions antiparallel
    with pytest.raises(ValueError, match="body axes are parallel"):
        two_vector_attitude([0, 0, 1], [0, 0, 2], [0, 1, 0], [1, 0, 0])


def test_nadir_reference_turns_at_the_orbit_rate_about_the_orbit_normal():
    sky = sky_of(SWIFT)                                    # circular 450 km orbit
    law = law_of(PointingMode("nadir"), sky, 0.0, rot.IDENTITY)
    n = SWIFT.orbit.mean_motion
    for t in (0.0, 1234.5, 4000.0):
        ref = reference(law.attitude, t)
        r, v = sky.state_N(t)
        R = rot.dcm_NB(ref.q_RN)
        assert np.allclose(R @ [0, 0, 1], -unit(r), atol=1e-12)                  # body z on nadir
        assert np.allclose(R @ [1, 0, 0], unit(v), atol=1e-9)                   # body x along-track
        assert np.allclose(ref.omega_RN_R, [0.0, -n, 0.0], atol=1e-9)               # orbit normal is -y
        assert np.linalg.norm(ref.omega_dot_RN_R) < 1e-9


def test_nadir_yaw_turns_the_secondary_about_the_primary():
    sky = sky_of(SWIFT)
    plain = law_of(PointingMode("nadir"), sky, 0.0, rot.IDENTITY).attitude(100.0)
    yawed = law_of(PointingMode("nadir", yaw=math.radians(30)), sky, 0.0, rot.IDENTITY).attitude(100.0)
    assert np.allclose(rot.dcm_NB(yawed) @ [0, 0, 1], rot.dcm_NB(plain) @ [0, 0, 1], atol=1e-12)
    angle = math.acos(np.clip((rot.dcm_NB(yawed) @ [1, 0, 0]) @ (rot.dcm_NB(plain) @ [1, 0, 0]), -1, 1))
    assert angle == pytest.approx(math.radians(30), abs=1e-9)


def test_ground_target_line_of_sight_is_skyfields():
    """A ground point in Brazil seen from the leo_observatory TLE orbit, against skyfield's own
    WGS-84 position and its EarthSatellite (another path than the suite's ITRS table)."""
    from skyfield.api import wgs84

    from att_sim.models.ephemeris import de421
    from att_sim.models.epoch import skyfield_times

    lat, lon, alt = math.radians(-15.8), math.radians(-47.9), 1100.0
    sky = sky_of(LEO)
    mode = PointingMode("ground", primary_axis=np.array([0.0, 1.0, 0.0]), secondary_axis=np.array([0.0, 0.0, 1.0]),
                        secondary="orbit_normal", latitude=lat, longitude=lon, altitude=alt)
    law = law_of(mode, sky, 0.0, rot.IDENTITY)
    earth = de421()["earth"]
    site = wgs84.latlon(math.degrees(lat), math.degrees(lon), elevation_m=alt)
    for t in (0.0, 300.0, 1500.0):
        ts = skyfield_times(LEO.epoch, t)
        ground = (earth + site).at(ts).position.m - earth.at(ts).position.m
        expected = unit(ground - LEO.orbit_model.position(t))
        boresight = rot.dcm_NB(law.attitude(t)) @ [0, 1, 0]
        assert math.acos(np.clip(boresight @ expected, -1, 1)) < 2e-6        # rad: the ITRS table, TEME/GCRS


def test_sun_and_inertial_targets_and_holds():
    sky = sky_of(LEO)
    sun = law_of(PointingMode("sun", primary_axis=np.array([1.0, 0.0, 0.0]), secondary_axis=np.array([0.0, 1.0, 0.0]),
                              secondary="north"), sky, 0.0, rot.IDENTITY)
    assert np.allclose(rot.dcm_NB(sun.attitude(50.0)) @ [1, 0, 0], sky.sun_N(50.0), atol=1e-12)
    target = unit([1, 2, 3])
    law = law_of(PointingMode("inertial_target", primary_axis=np.array([0.0, 0.0, 1.0]), target_direction=target,
                              secondary="inertial", secondary_direction=np.array([1.0, 0.0, 0.0])), sky, 0.0,
                 rot.IDENTITY)
    ref = reference(law.attitude, 10.0)
    assert np.allclose(rot.dcm_NB(ref.q_RN) @ [0, 0, 1], target) and np.allclose(ref.omega_RN_R, 0.0, atol=1e-12)
    q_now = rot.from_axis_angle([1, 1, 0], 0.4)
    assert np.array_equal(law_of(PointingMode("inertial"), sky, 0.0, q_now).attitude(99.0), q_now)
    q_hold = rot.from_axis_angle([0, 1, 0], 1.0)
    assert np.allclose(law_of(PointingMode("inertial", attitude=q_hold), sky, 0.0, q_now).attitude(5.0), q_hold)


@pytest.mark.parametrize("fields, words", [
    (dict(kind="moon"), "pointing.kind 'moon'"),
    (dict(kind="nadir", primary_axis=np.zeros(3)), "pointing.primary_axis"),
    (dict(kind="nadir", secondary_axis=np.array([0.0, 0.0, 2.0])), "pointing.secondary_axis"),
    (dict(kind="nadir", secondary_axis=np.array([0.0, 0.0, 1.0])), "body axes are parallel"),
    (dict(kind="nadir", secondary="nadir"), "directions are parallel"),
    (dict(kind="nadir", yaw=7.0), "pointing.yaw"),
    (dict(kind="nadir", secondary="east"), "pointing.secondary 'east'"),
    (dict(kind="nadir", secondary="inertial"), "pointing.secondary_direction"),
    (dict(kind="ground", latitude=math.nan), "pointing.latitude"),
    (dict(kind="ground", latitude=2.0), "pointing.latitude"),
    (dict(kind="ground", altitude=1e6), "pointing.altitude"),
    (dict(kind="inertial_target"), "pointing.target_direction"),
    (dict(kind="inertial", attitude=np.array([0.0, 0.0, 0.0, 3.0])), "pointing.attitude"),
    (dict(kind="sun"), "needs the scenario's epoch"),
    (dict(kind="nadir\x1b"), "control, format"),
])
def test_hostile_pointing_requests_are_refused_naming_the_field(fields, words):
    with pytest.raises(RequestError) as err:
        law_of(PointingMode(**fields), sky_of(SWIFT), 0.0, rot.IDENTITY)
    assert err.value.code in (ErrorCode.INVALID_POINTING, ErrorCode.INVALID_TEXT) and words in err.value.message, \
        err.value.message
