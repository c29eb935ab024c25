"""Hostile ImageTarget and ImageStrip requests: every field NaN/Inf or out of its range, a strip of
zero length, an absurd scan speed, a site below the instrument's minimum elevation or never in view
within the planning window, refused with a code and a sentence naming the field (ROS-free: the
service core the planner node calls). Over the node's wire: test_planner_requests.py, on its planner
fixture."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_planner.guidance.ground_arrival import site_in_view
from att_planner.guidance.laws import PointingGeometry
from att_planner.service.imaging import (
    MAX_SCAN_SPEED_M_S,
    ImageStripRequest,
    ImageTargetRequest,
    validate_image_strip,
    validate_image_target,
)
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

SWIFT = scen.load("swift_demo")
GEOMETRY = PointingGeometry.of(world.Environment.from_scenario(SWIFT))
SENSOR, ALONG = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
NAN, INF = math.nan, math.inf
LAT, LON = (math.degrees(a) for a in site_in_view(GEOMETRY, 70.0, math.radians(20.0), math.radians(90.0)))
DEFAULTS = dict(frame_id=SWIFT.frame_id, default_spacecraft=SWIFT.name, default_method="graph_smooth",
                default_budget=10.0, min_elevation_deg=45.0)


def target(**kw) -> ImageTargetRequest:
    fields = dict(frame_id="", q_initial=rot.IDENTITY, sensor_axis=SENSOR, along_track_axis=ALONG,
                  latitude_deg=LAT, longitude_deg=LON, dwell_s=10.0)
    return ImageTargetRequest(**{**fields, **kw})


def strip(**kw) -> ImageStripRequest:
    fields = dict(frame_id="", q_initial=rot.IDENTITY, sensor_axis=SENSOR, along_track_axis=ALONG,
                  start_latitude_deg=LAT, start_longitude_deg=LON, by_azimuth=True, azimuth_deg=45.0, length_m=30e3)
    return ImageStripRequest(**{**fields, **kw})


TARGET_CASES = {
    "latitude nan": (dict(latitude_deg=NAN), ErrorCode.INVALID_SITE, "latitude_deg = nan"),
    "latitude 90.5": (dict(latitude_deg=90.5), ErrorCode.INVALID_SITE, "latitude_deg = 90.5 is outside [-90, 90]"),
    "latitude -inf": (dict(latitude_deg=-INF), ErrorCode.INVALID_SITE, "latitude_deg = -inf"),
    "longitude 181": (dict(longitude_deg=181.0), ErrorCode.INVALID_SITE, "longitude_deg = 181.0"),
    "altitude in orbit": (dict(altitude_m=400e3), ErrorCode.INVALID_SITE, "altitude_m = 400000.0"),
    "altitude nan": (dict(altitude_m=NAN), ErrorCode.INVALID_SITE, "altitude_m = nan"),
    "dwell negative": (dict(dwell_s=-1.0), ErrorCode.INVALID_SITE, "dwell_s = -1.0"),
    "dwell inf": (dict(dwell_s=INF), ErrorCode.INVALID_SITE, "dwell_s = inf"),
    "sensor axis zero": (dict(sensor_axis=np.zeros(3)), ErrorCode.INVALID_SENSOR_AXIS, "sensor_axis"),
    "along-track on the boresight": (dict(along_track_axis=SENSOR), ErrorCode.INVALID_SENSOR_AXIS,
                                     "along_track_axis is parallel to sensor_axis"),
    "attitude nan": (dict(q_initial=np.array([NAN, 0, 0, 1.0])), ErrorCode.INVALID_ATTITUDE, "initial_attitude"),
    "rest-to-rest method": (dict(method="eigenaxis_smooth"), ErrorCode.INVALID_OPTION, "end_pointing"),
    "wheel speeds nan": (dict(wheel_speeds=[NAN, 0.0, 0.0]), ErrorCode.INVALID_WHEEL_SPEEDS, "wheel_speeds"),
    "the far side of the Earth": (dict(latitude_deg=-LAT, longitude_deg=LON - 180.0 if LON > 0 else LON + 180.0),
                                  ErrorCode.SITE_NOT_VISIBLE, "rises to"),
}

STRIP_CASES = {
    "start latitude nan": (dict(start_latitude_deg=NAN), ErrorCode.INVALID_SITE, "start_latitude_deg = nan"),
    "start latitude -91": (dict(start_latitude_deg=-91.0), ErrorCode.INVALID_SITE, "start_latitude_deg = -91.0"),
    "start longitude inf": (dict(start_longitude_deg=INF), ErrorCode.INVALID_SITE, "start_longitude_deg = inf"),
    "end latitude 100": (dict(by_azimuth=False, end_latitude_deg=100.0), ErrorCode.INVALID_SITE,
                         "end_latitude_deg = 100.0"),
    "end longitude nan": (dict(by_azimuth=False, end_latitude_deg=LAT, end_longitude_deg=NAN),
                          ErrorCode.INVALID_SITE, "end_longitude_deg = nan"),
    "zero length, end on the start": (dict(by_azimuth=False, end_latitude_deg=LAT, end_longitude_deg=LON),
                                      ErrorCode.INVALID_SITE, "end_latitude_deg, end_longitude_deg"),
    "the end on another continent": (dict(by_azimuth=False, end_latitude_deg=-LAT, end_longitude_deg=LON - 120.0
                                          if LON > 0 else LON + 120.0), ErrorCode.INVALID_SITE, "deg of arc"),
    "the end 30 deg away": (dict(by_azimuth=False, end_latitude_deg=LAT, end_longitude_deg=LON - 30.0 if LON > 0
                                 else LON + 30.0), ErrorCode.INVALID_SITE, "outside [1, 2e+06] m"),
    "zero length": (dict(length_m=0.0), ErrorCode.INVALID_SITE, "length_m = 0.0"),
    "length nan": (dict(length_m=NAN), ErrorCode.INVALID_SITE, "length_m = nan"),
    "a continent": (dict(length_m=5e6), ErrorCode.INVALID_SITE, "length_m = 5000000.0"),
    "azimuth inf": (dict(azimuth_deg=INF), ErrorCode.INVALID_SITE, "azimuth_deg = inf"),
    "unused end nan": (dict(end_latitude_deg=NAN), ErrorCode.INVALID_SITE, "end_latitude_deg = nan"),
    "unused azimuth nan": (dict(by_azimuth=False, end_latitude_deg=LAT + 0.1, end_longitude_deg=LON, azimuth_deg=NAN),
                           ErrorCode.INVALID_SITE, "azimuth_deg = nan"),
    "speed negative": (dict(scan_speed_m_s=-7000.0), ErrorCode.INVALID_SITE, "scan_speed_m_s = -7000.0"),
    "speed nan": (dict(scan_speed_m_s=NAN), ErrorCode.INVALID_SITE, "scan_speed_m_s = nan"),
    "speed absurd": (dict(scan_speed_m_s=1e6), ErrorCode.INVALID_SITE, f"outside [0, {MAX_SCAN_SPEED_M_S:g}]"),
    "speed a snail's": (dict(scan_speed_m_s=1e-3), ErrorCode.INVALID_SITE, "longer than the"),
    "altitude -1 km": (dict(altitude_m=-1000.0), ErrorCode.INVALID_SITE, "altitude_m = -1000.0"),
    "along-track zero": (dict(along_track_axis=np.zeros(3)), ErrorCode.INVALID_SENSOR_AXIS, "along_track_axis"),
    "unknown spacecraft": (dict(spacecraft="no_such"), ErrorCode.UNKNOWN_SPACECRAFT, "spacecraft"),
    "the far side of the Earth": (dict(start_latitude_deg=-LAT,
                                       start_longitude_deg=LON - 180.0 if LON > 0 else LON + 180.0),
                                  ErrorCode.SITE_NOT_VISIBLE, "rises to"),
}


@pytest.mark.parametrize("case", TARGET_CASES)
def test_a_bad_image_target_is_refused_naming_its_field(case):
    change, code, words = TARGET_CASES[case]
    with pytest.raises(RequestError) as refused:
        validate_image_target(target(**change), **DEFAULTS)
    assert refused.value.code == code and words in refused.value.message, refused.value.message


@pytest.mark.parametrize("case", STRIP_CASES)
def test_a_bad_image_strip_is_refused_naming_its_field(case):
    change, code, words = STRIP_CASES[case]
    with pytest.raises(RequestError) as refused:
        validate_image_strip(strip(**change), **DEFAULTS, rate_max=math.radians(5.0))
    assert refused.value.code == code and words in refused.value.message, refused.value.message


def test_good_requests_are_accepted():
    assert validate_image_target(target(), **DEFAULTS).duration == 10.0
    valid = validate_image_strip(strip(), **DEFAULTS, rate_max=math.radians(5.0))
    assert valid.strip.length_m == pytest.approx(30e3) and 6000.0 < valid.strip.scan_speed_m_s < 8000.0


def test_a_scan_faster_than_the_body_can_turn_is_refused():
    """20 km/s across the track asks about 1.8 deg/s of swift_demo: refused under a 1 deg/s bound."""
    with pytest.raises(RequestError) as refused:
        validate_image_strip(strip(scan_speed_m_s=MAX_SCAN_SPEED_M_S), **DEFAULTS, rate_max=math.radians(1.0))
    assert refused.value.code == ErrorCode.INVALID_SITE
    assert "scan_speed_m_s: scanning the strip at 20000 m/s from any start where" in refused.value.message
    assert "asks a body rate of" in refused.value.message
    assert "beyond the bound of 1.00 deg/s" in refused.value.message
