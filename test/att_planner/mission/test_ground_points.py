"""The ground points of a mission of ground sites (the review's ground track, the map's fixes):
geodetic coordinates of ITRS points, where a line of sight meets the WGS-84 ellipsoid, and the
boresight of a site's tracking law landing on the site."""
import math

import numpy as np
import pytest

from att_planner.guidance.laws import geodetic_to_itrs
from att_planner.mission import config as mc
from att_planner.mission.ground import geodetic_of, geodetic_up, ground_points, ground_track


@pytest.mark.parametrize("lat, lon, alt", [(0.0, 0.0, 0.0), (28.63, -106.09, 1440.0), (-89.9, 170.0, 800e3),
                                           (51.05, -114.07, 797e3), (-33.9, 18.4, -30.0)])
def test_geodetic_of_inverts_geodetic_to_itrs(lat, lon, alt):
    p = geodetic_to_itrs(math.radians(lat), math.radians(lon), alt)
    got = geodetic_of(p[None])
    assert np.degrees(got[0][0]) == pytest.approx(lat, abs=1e-7)    # Bowring: mm at 800 km
    assert np.degrees(got[1][0]) == pytest.approx(lon, abs=1e-12)
    assert got[2][0] == pytest.approx(alt, abs=0.01)


def test_a_line_down_the_geodetic_normal_meets_the_point_below_and_one_away_misses():
    lat, lon = math.radians(40.0), math.radians(-105.0)
    up = geodetic_up(lat, lon)
    r = geodetic_to_itrs(lat, lon, 800e3)
    points = ground_points(np.array([r, r, r]), np.array([-up, up, np.cross(up, [0.0, 0.0, 1.0])]))
    assert points[0] == pytest.approx(geodetic_to_itrs(lat, lon, 0.0), abs=1e-3)
    assert np.isnan(points[1]).all() and np.isnan(points[2]).all()   # away from the Earth; along the horizon


def test_the_boresight_of_a_site_s_law_lands_on_the_site():
    m = mc.load("aeos_orbit")
    site = m.targets()["chihuahua"]
    t = np.linspace(440.0, 520.0, 5)                                  # its pass, 58-84 deg high
    g = ground_track(site.track.environment, t, site.track.attitudes(t), m.sensor_axis)
    # the line of sight ends 1440 m above the ellipsoid: its ellipsoid point is within alt x tan(off-nadir)
    assert g["bore_lat"] == pytest.approx(28.63, abs=0.01) and g["bore_lon"] == pytest.approx(-106.09, abs=0.01)
    assert np.all(np.abs(g["sub_lat"] - 28.63) < 6.0) and np.all(g["sub_alt"] > 790e3)
