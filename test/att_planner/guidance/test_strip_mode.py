"""A strip as a pointing mode (``att_msgs/PointingMode`` kind ``strip``): the mode of a strip
(:func:`strip_mode`), through the wire and back, gives the law the in-process strip tracking flies
(:class:`StripLaw` of the same strip) to within 1e-6 rad over the scan, for a strip between two points
and one given by an azimuth; every field of a hostile strip mode is refused with 314 naming it; a
PlanManeuver ``end_pointing`` strip is refused (a slew onto a strip is ImageStrip's)."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from att_msgs_py import convert
from att_msgs_py.errors import ErrorCode, RequestError
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of, strip_mode
from att_planner.guidance.strip import MAX_SCAN_SPEED_M_S, Strip, StripLaw
from att_planner.service.moving_goal import goal_law
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

SWIFT = scen.load("swift_demo")
GEOMETRY = PointingGeometry.of(world.Environment.from_scenario(SWIFT))
SENSOR, ALONG_TRACK = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
LAT, LON = math.radians(20.0), math.radians(35.0)
STRIPS = {
    "between": Strip.between(LAT, LON, LAT + 0.01, LON + 0.015, 250.0, 6800.0),
    "azimuth": Strip.from_azimuth(LAT, LON, math.radians(-120.0), 80e3, 0.0, 7000.0),
}


@pytest.mark.parametrize("name", sorted(STRIPS))
def test_the_mode_of_a_strip_through_the_wire_is_the_strips_law(name):
    strip, scan_start = STRIPS[name], 123.4
    mode = convert.pointing_from_msg(convert.pointing_msg(strip_mode(strip, SENSOR, ALONG_TRACK, scan_start)))
    assert (mode.kind, mode.scan_start, mode.scan_speed) == ("strip", scan_start, strip.scan_speed_m_s)
    law = law_of(mode, GEOMETRY, scan_start, rot.IDENTITY)
    direct = StripLaw(GEOMETRY, strip, SENSOR, ALONG_TRACK, scan_start)
    assert law.strip.length_m == pytest.approx(strip.length_m, rel=1e-9)
    for t in np.linspace(scan_start - 10.0, scan_start + strip.duration_s, 7):
        assert rot.angle_between(law.attitude(t), direct.attitude(t)) < 1e-6
        assert np.linalg.norm(law.reference(t).omega_RN_R - direct.reference(t).omega_RN_R) < 1e-7


def hostile(**fields):
    return dataclasses.replace(strip_mode(STRIPS["between"], SENSOR, ALONG_TRACK, 100.0), **fields)


HOSTILE = {
    "start latitude nan": (dict(latitude=math.nan), "pointing.latitude"),
    "end latitude beyond the pole": (dict(end_latitude=2.0), "pointing.end_latitude"),
    "end longitude inf": (dict(end_longitude=math.inf), "pointing.end_longitude"),
    "altitude in orbit": (dict(altitude=400e3), "pointing.altitude"),
    "speed zero": (dict(scan_speed=0.0), "pointing.scan_speed"),
    "speed negative": (dict(scan_speed=-5.0), "pointing.scan_speed"),
    "speed absurd": (dict(scan_speed=10 * MAX_SCAN_SPEED_M_S), "pointing.scan_speed"),
    "speed nan": (dict(scan_speed=math.nan), "pointing.scan_speed"),
    "scan start nan": (dict(scan_start=math.nan), "pointing.scan_start"),
    "scan start inf": (dict(scan_start=-math.inf), "pointing.scan_start"),
    "yaw": (dict(yaw=0.3), "pointing.yaw"),
    "parallel axes": (dict(secondary_axis=np.array([0.0, -1.0, 0.0])), "pointing.secondary_axis"),
    "axis not unit": (dict(primary_axis=np.array([0.0, 2.0, 0.0])), "pointing.primary_axis"),
    "end is the start": (dict(end_latitude=LAT, end_longitude=LON), "pointing.end_latitude"),
    "longer than a pass": (dict(end_latitude=-LAT, end_longitude=LON + 0.5), "pointing.end_latitude"),
    "antipodal end": (dict(end_latitude=-LAT, end_longitude=LON - math.pi), "pointing.end_latitude"),
}


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_a_hostile_strip_mode_is_refused_naming_the_field(name):
    fields, field_name = HOSTILE[name]
    with pytest.raises(RequestError) as refused:
        law_of(hostile(**fields), GEOMETRY, 0.0, rot.IDENTITY)
    assert refused.value.code == ErrorCode.INVALID_POINTING and field_name in refused.value.message, \
        refused.value.message


def test_a_maneuvers_end_pointing_strip_is_refused_for_image_strip():
    with pytest.raises(RequestError) as refused:
        goal_law(hostile(), SWIFT, None, rot.IDENTITY)
    assert refused.value.code == ErrorCode.INVALID_POINTING and "ImageStrip" in refused.value.message
