"""Access windows of imaging sites against an independent recomputation: the orbit propagated here
from Vallado's J2 secular rates, the sites placed and their horizons turned by skyfield (WGS-84,
GCRS→altazimuth), the elevation read from skyfield's altazimuth frame on a 1 s grid."""
from __future__ import annotations

import math

import numpy as np
import pytest
from skyfield.api import wgs84

from att_planner.imaging import access, sites
from att_sim.models import scenario as scen
from att_sim.models import world
from att_sim.models.epoch import skyfield_times

AEOS = scen.load("aeos")
MU, RE, J2 = 3.986004418e14, 6378.137e3, 1.08262668e-3


def orbit_here(t: np.ndarray) -> np.ndarray:
    """GCRS position of aeos's e = 0 orbit: a = 7171 km, i = 97.8°, Ω = u = 0 at t = 0, drifting at
    the J2 secular rates (Vallado 2013, eq. 9-41)."""
    a, i = 7_171_000.0, math.radians(97.8)
    n, k = math.sqrt(MU / a**3), J2 * (RE / a) ** 2
    raan = -1.5 * n * k * math.cos(i) * t
    u = (0.75 * n * k * (4 - 5 * math.sin(i) ** 2) + n * (1 + 0.75 * k * (2 - 3 * math.sin(i) ** 2))) * t
    x, y = a * np.cos(u), a * np.sin(u)
    return np.stack([np.cos(raan) * x - np.sin(raan) * math.cos(i) * y,
                     np.sin(raan) * x + np.cos(raan) * math.cos(i) * y, math.sin(i) * y], axis=-1)


def elevation_deg(site: sites.ImagingSite, t: np.ndarray) -> np.ndarray:
    times = skyfield_times(AEOS.epoch, t)
    place = wgs84.latlon(site.lat_deg, site.lon_deg, site.alt_m)
    seen = orbit_here(t).T - place.at(times).position.m                   # GCRS, site to spacecraft
    local = np.einsum("ijk,jk->ik", place.rotation_at(times), seen)      # north, east, up
    return np.degrees(np.arcsin(local[2] / np.linalg.norm(local, axis=0)))


@pytest.fixture(scope="module")
def windows():
    env = world.Environment.from_scenario(AEOS)
    s = sites.uniform(300, 7)
    return s, access.access_windows(env, s, 0.0, AEOS.orbit_model.period)


def test_the_orbit_here_is_the_scenarios():
    t = np.linspace(0.0, 6000.0, 61)
    assert np.abs(orbit_here(t) - AEOS.orbit_model.position(t)).max() < 1e-3


def test_the_minimum_elevation_is_bsk_rls():
    assert access.MIN_ELEVATION_DEG == pytest.approx(57.99, abs=0.01)


def test_every_second_a_site_is_high_enough_lies_in_one_of_its_windows(windows):
    s, w = windows
    assert len(w) > 10
    shortest = int(np.argmin(w.close_s - w.open_s))
    chosen = sorted({int(w.site[shortest]), *map(int, w.site[:4]), *np.flatnonzero(~w.accessible())[:2]})
    t = np.arange(0.0, w.t1_s, 1.0)
    for i in chosen:
        e = elevation_deg(s.sites[i], t)
        mine = w.site == i
        inside = np.zeros(len(t), bool)
        for a, b in zip(w.open_s[mine], w.close_s[mine]):
            assert b >= a
            inside |= (t >= a - access.TOLERANCE_S) & (t <= b + access.TOLERANCE_S)
            # the edges lie inside the window, within the tolerance of its true edges
            assert elevation_deg(s.sites[i], np.array([a, b])).min() >= access.MIN_ELEVATION_DEG - 1e-6
            beyond = access.TOLERANCE_S + 1e-3
            if a > w.t0_s:
                assert elevation_deg(s.sites[i], np.array([a - beyond]))[0] < access.MIN_ELEVATION_DEG
            if b < w.t1_s:
                assert elevation_deg(s.sites[i], np.array([b + beyond]))[0] < access.MIN_ELEVATION_DEG
        assert np.all(inside[e >= access.MIN_ELEVATION_DEG]), (i, t[(e >= access.MIN_ELEVATION_DEG) & ~inside])


def test_a_pass_shorter_than_the_coarse_step_is_found():
    env = world.Environment.from_scenario(AEOS)
    s = sites.uniform(300, 7)
    fine = access.access_windows(env, s, 0.0, 3000.0, step_s=1.0)
    coarse = access.access_windows(env, s, 0.0, 3000.0, step_s=60.0)
    assert np.any(fine.close_s - fine.open_s < 60.0)
    assert np.array_equal(fine.site, coarse.site)
    assert np.abs(fine.open_s - coarse.open_s).max() <= access.TOLERANCE_S
    assert np.abs(fine.close_s - coarse.close_s).max() <= access.TOLERANCE_S


@pytest.mark.parametrize("args, words", [((0.0, 0.0), "t0_s < t1_s"), ((0.0, math.nan), "t0_s < t1_s"),
                                         ((0.0, 10.0, 95.0), "min_elevation_deg"),
                                         ((0.0, 10.0, 58.0, 1.0, 2.0), "tolerance_s < step_s")])
def test_a_bad_horizon_or_grid_is_refused(args, words):
    with pytest.raises(ValueError, match=words):
        access.access_windows(world.Environment.from_scenario(AEOS), sites.uniform(3, 0), *args)
