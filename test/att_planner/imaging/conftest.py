"""The imaging tests' shared planner: five sites placed on aeos's ground track, a 600 s horizon."""
from __future__ import annotations

import math

import pytest

from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry
from att_planner.imaging import access, sites, slews, timeline
from att_planner.zones import FittedZones
from att_sim.models import scenario as scen
from att_sim.models import world

SCENARIO = scen.load("aeos")
ENVIRONMENT = world.Environment.from_scenario(SCENARIO)


@pytest.fixture(scope="session")
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


