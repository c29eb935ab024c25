"""The imaging timeline: the along-track axis from the star trackers, and a short horizon over sites
placed on the ground track planned by both policies with verified slews, each image inside its
window and the zones clear."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry
from att_planner.imaging import access, sites, slews, timeline
from att_planner.zones import FittedZones
from att_sim.models import scenario as scen
from att_sim.models import world

SCENARIO = scen.load("aeos")
ENVIRONMENT = world.Environment.from_scenario(SCENARIO)


def test_the_along_track_axis_puts_the_aeos_trackers_fore_and_aft():
    axes = [z.sensor_axis for z in SCENARIO.zones]
    assert np.allclose(timeline.along_track_axis([0.0, 0.0, 1.0], axes), [1.0, 0.0, 0.0])
    assert np.allclose(timeline.along_track_axis([0.0, 0.0, 1.0], []), [0.0, 1.0, 0.0])   # next_axis


@pytest.fixture(scope="module")
def planner():
    geometry = PointingGeometry.of(ENVIRONMENT)
    rows = []
    for k, (t, off, az) in enumerate([(200.0, 15.0, 90.0), (215.0, 20.0, -90.0), (300.0, 10.0, 90.0),
                                      (320.0, 25.0, -90.0), (330.0, 5.0, 0.0)]):
        lat, lon = site_in_view(geometry, t, math.radians(off), math.radians(az))
        rows.append(sites.ImagingSite(name=f"s{k}", lat_deg=math.degrees(lat), lon_deg=math.degrees(lon),
                                      priority=0.2 * k))
    targets = sites.SiteSet("test", tuple(rows))
    windows = access.access_windows(ENVIRONMENT, targets, 0.0, 600.0)
    limits = slews.Limits.of(SCENARIO.spacecraft, math.radians(5.0), 50.0)
    zones = FittedZones(SCENARIO.zones, ENVIRONMENT.sky, 600.0)
    return timeline.Planner(ENVIRONMENT, SCENARIO.spacecraft, targets, windows, [0.0, 0.0, 1.0], limits, zones)


@pytest.mark.parametrize("policy", timeline.POLICIES)
def test_a_short_horizon_is_planned_with_verified_slews_and_images_inside_their_windows(planner, policy):
    plan = planner.plan(policy)
    w = planner.windows
    assert len(plan.images) >= 3 and plan.cpu_s > 0.0
    assert len({i.site for i in plan.images}) == len(plan.images)                    # each site once
    for image in plan.images:
        assert w.site[image.window] == image.site
        assert w.open_s[image.window] <= image.time_s and image.time_s + image.dwell_s <= w.close_s[image.window]
        assert image.time_s >= image.arrival_s + timeline.SETTLE_S - 1e-9
    for leg in plan.legs:
        assert leg.check.refusal is None and leg.check.final_attitude_error < math.radians(0.05)
    times = [leg.slew.t0_s for leg in plan.legs]
    assert times == sorted(times) and plan.worst_zone_margin > 0.0
    with pytest.raises(ValueError, match="policy"):
        planner.plan("random")
