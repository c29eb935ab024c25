"""A planner request is held to its size caps before any field is read: 100,000 zones (about 10 MB
on the wire) are refused as SIZE_LIMIT in a fraction of the CPU time reading them would take, and a
request at the caps is read as before."""
from __future__ import annotations

import time

import numpy as np
import pytest

from att_msgs.msg import Zone
from att_msgs.srv import PlanManeuver
from att_msgs_py import limits
from att_msgs_py.errors import ErrorCode, RequestError
from att_planner.nodes.planner_node import maneuver_from_msg


def _request(n_zones: int) -> PlanManeuver.Request:
    req = PlanManeuver.Request()
    req.initial_attitude.w = req.final_attitude.w = 1.0
    req.sensor_axis.x = 1.0
    req.zones = [Zone(name=f"z{i}", body="sun", half_angle=0.3) for i in range(n_zones)]
    return req


def test_a_hundred_thousand_zones_are_refused_before_they_are_read():
    req = _request(100_000)
    start = time.process_time()
    with pytest.raises(RequestError) as refused:
        maneuver_from_msg(req)
    cpu = time.process_time() - start
    assert refused.value.code == ErrorCode.SIZE_LIMIT
    assert refused.value.message == f"zones has 100000 entries; at most {limits.MAX_ZONES}"
    assert cpu < 1.0                         # the budget + 1 s answer; reading them all takes seconds


def test_a_request_at_the_caps_is_read_field_by_field():
    req = _request(limits.MAX_ZONES)
    req.wheel_speeds = [0.5] * limits.MAX_WHEELS
    read = maneuver_from_msg(req)
    assert len(read.zones) == limits.MAX_ZONES and read.zones[3].name == "z3" and read.zones[3].body == "sun"
    np.testing.assert_array_equal(read.q_initial, [0, 0, 0, 1])
    assert read.wheel_speeds == [0.5] * limits.MAX_WHEELS


@pytest.mark.parametrize("service", ["ImageTarget", "ImageStrip"])
def test_an_imaging_request_s_zones_are_capped_then_read(service):
    """The imaging requests' zones: 100,000 refused by their count (SIZE_LIMIT naming the field), the
    cap's 16 read into the request the service core validates."""
    from att_msgs import srv
    from att_planner.nodes.planner_node import _image_common

    table = {"ImageTarget": limits.IMAGE_TARGET, "ImageStrip": limits.IMAGE_STRIP}[service]
    req = getattr(srv, service).Request()
    req.zones = [Zone(name=f"z{i}", body="sun", half_angle=0.3) for i in range(100_000)]
    err = limits.issue(req, table)
    assert err is not None and err.code == ErrorCode.SIZE_LIMIT
    assert err.message == f"zones has 100000 entries; at most {limits.MAX_ZONES}"
    req.zones = req.zones[:limits.MAX_ZONES]
    assert limits.issue(req, table) is None
    read = _image_common(req)["zones"]
    assert len(read) == limits.MAX_ZONES and read[5].name == "z5" and read[5].half_angle == pytest.approx(0.3)
