"""The attitude and rate that look at a ground site: the closed form against an independent
recomputation (the pointing law's attitude, central differences of it), the site placed in view
where it was asked for, the ground velocity kept by the secondary axis."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import PointingMode
from att_planner.guidance import reference
from att_planner.guidance.ground_arrival import ground_motion, itrs_to_geodetic, site_in_view
from att_planner.guidance.laws import PointingGeometry, geodetic_to_itrs
from att_planner.guidance.modes import law_of
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world
from att_sim.models.geomagnetic import EARTH_ROTATION_RATE


@pytest.fixture(scope="module", params=["leo_observatory", "swift_demo"])
def geometry(request):
    """The real sky's Earth rotation (skyfield's ITRS) and the epoch-free one (R_3(ω_E t))."""
    return PointingGeometry.of(world.Environment.from_scenario(scen.load(request.param)))


@pytest.mark.parametrize("secondary", ["velocity", "ground_velocity", "orbit_normal"])
def test_the_closed_form_is_the_laws_attitude_and_its_differentiated_rate(geometry, secondary):
    lat, lon = site_in_view(geometry, 300.0, math.radians(20.0))
    mode = PointingMode("ground", primary_axis=np.array([0.0, 1.0, 0.0]), secondary_axis=np.array([0.0, 0.0, 1.0]),
                        secondary=secondary, latitude=lat, longitude=lon, altitude=250.0, yaw=0.3)
    law = law_of(mode, geometry, 0.0, rot.IDENTITY)
    motion = ground_motion(geometry, lat, lon, 250.0, law.primary_B, law.secondary_B, law.secondary_N, law.yaw)
    for t in (150.0, 290.0, 300.0, 330.0):
        q, omega = motion(t)
        ref = reference(law.attitude, t, h=0.01)
        assert rot.angle_between(q, ref.q_RN) < 1e-12
        # 0.7 deg/s through the pass: the closed form and the differences agree to 1e-9 rad/s
        assert np.abs(omega - ref.omega_RN_R).max() < 1e-9, (omega, ref.omega_RN_R)


@pytest.mark.parametrize("off_nadir_deg, azimuth_deg", [(0.0, 0.0), (20.0, 0.0), (28.0, 180.0), (28.0, 90.0)])
def test_a_site_in_view_is_on_the_ground_where_it_was_asked_for(geometry, off_nadir_deg, azimuth_deg):
    t = 200.0
    lat, lon = site_in_view(geometry, t, math.radians(off_nadir_deg), math.radians(azimuth_deg))
    r, v = geometry.state_N(t)
    site_N = np.asarray(geometry.dcm_EN(t)).T @ geodetic_to_itrs(lat, lon, 0.0)
    sight = (site_N - r) / np.linalg.norm(site_N - r)
    nadir = -r / np.linalg.norm(r)
    assert math.degrees(math.acos(np.clip(sight @ nadir, -1, 1))) == pytest.approx(off_nadir_deg, abs=1e-6)
    if off_nadir_deg:
        along = v - (v @ nadir) * nadir
        sideways = sight - (sight @ nadir) * nadir
        azimuth = math.atan2(sideways @ np.cross(nadir, along / np.linalg.norm(along)), sideways @ along)
        assert math.degrees(azimuth) % 360 == pytest.approx(azimuth_deg, abs=1e-6)


def test_geodetic_coordinates_round_trip():
    for lat, lon, alt in [(0.3, -2.0, 150.0), (-1.2, 0.5, 3000.0), (1.5, 3.0, -20.0)]:
        assert np.allclose(itrs_to_geodetic(geodetic_to_itrs(lat, lon, alt)), (lat, lon, alt), atol=1e-9)


def test_a_line_of_sight_that_misses_the_earth_is_refused(geometry):
    with pytest.raises(ValueError, match="misses the Earth"):
        site_in_view(geometry, 0.0, math.radians(80.0))


def test_the_ground_velocity_is_the_velocity_over_the_turning_earth(geometry):
    """v − ω_E k × r differs from the inertial velocity by the Earth's rotation: a yaw about nadir
    of a fraction of a degree (20.56° orbit) to a few degrees (87°), the angle between the two
    horizontal directions."""
    law = law_of(PointingMode("nadir", secondary="ground_velocity"), geometry, 0.0, rot.IDENTITY)
    reference_law = law_of(PointingMode("nadir"), geometry, 0.0, rot.IDENTITY)
    r, v = geometry.state_N(100.0)
    g = v - EARTH_ROTATION_RATE * np.cross(np.asarray(geometry.dcm_EN(100.0))[2], r)
    g -= (g @ r) / (r @ r) * r
    body_x = rot.dcm_NB(law.attitude(100.0)) @ np.array([1.0, 0.0, 0.0])
    assert np.allclose(body_x, g / np.linalg.norm(g), atol=1e-12)
    v_horizontal = v - (v @ r) / (r @ r) * r
    expected = math.acos(g @ v_horizontal / np.linalg.norm(g) / np.linalg.norm(v_horizontal))
    yaw = rot.angle_between(law.attitude(100.0), reference_law.attitude(100.0))
    assert yaw == pytest.approx(expected, abs=1e-9) and 0.2 < math.degrees(yaw) < 5.0
