"""Hostile real-sky requests: every bad epoch, TLE, orbit and zone refused with its code
and a sentence naming the field (ROS-free, against the service logic), and over ROS one moving-zone
PlanManeuver whose plan comes back with its epoch and zones, signed over them."""
from __future__ import annotations

import copy
import math
from datetime import UTC, datetime

import numpy as np
import pytest

from att_msgs_py import convert, signing
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Zone
from att_planner.nodes.client import maneuver_request
from att_planner.service.real_sky import MAX_ZONES
from att_planner.service.requests import validate_schedule
from att_sim.models import rotations as rot
from att_sim.models.orbit import tle_checksum
from helpers.maneuver_requests import GOAL, INF, NAN, request, validate

TLE = ("1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    07",
       "2 28485  20.5600  60.0000 0005000  90.0000  10.0000 14.95764766    08")
# 72 min past the TLE epoch the Swift slew (sensor +x, identity to 135 deg about z) starts and ends
# ~45 deg beyond the Earth limb, the Sun 90 deg and more away; the Moon lies 21 deg off its
# eigenaxis path, inside its 23 deg zone: only a planner that avoids the Moon succeeds
EPOCH = datetime(2026, 12, 21, 1, 12, tzinfo=UTC)
X, Z = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
SUN, MOON = Zone("sun", "sun", X, math.radians(47)), Zone("moon", "moon", X, math.radians(23))
LIMB = Zone("earth", "earth_limb", X, math.radians(10))
ZONES = [SUN, MOON, LIMB]


def sky_request(epoch=EPOCH, zones=ZONES, tle=TLE, **fields):
    """The Swift slew among ``zones`` at ``epoch`` (a datetime, None, or raw (sec, nanosec)) in ``tle``."""
    if not isinstance(epoch, tuple):
        epoch = convert.epoch_parts(convert.epoch_msg(epoch))
    return request(**{"cones": [], "zones": list(zones), "epoch": epoch, "tle_line1": tle[0],
                      "tle_line2": tle[1], **fields})


def with_checksum(line: str) -> str:
    return line[:68] + str(tle_checksum(line))


LOW_TLE = (TLE[0], with_checksum(TLE[1][:52] + "16.50000000    0"))         # a ~140 km orbit
ZERO_EPOCH = (0, 0)


def zone(**fields) -> Zone:
    base = dict(name="z", body="sun", sensor_axis=X, half_angle=0.5, keep_in=False, direction=None)
    base.update(fields)
    return Zone(**base)


def inertial(direction, half_angle, keep_in=False, name="i") -> Zone:
    return Zone(name, "inertial", X, half_angle, keep_in, np.asarray(direction, float))


# name: (request fields, code, words the message must contain)
CASES = {
    # epoch
    "epoch nanosec 1e9": (dict(epoch=(1797811200, 1_000_000_000)), ErrorCode.INVALID_EPOCH, "epoch.nanosec"),
    "epoch nanosec negative": (dict(epoch=(1797811200, -1)), ErrorCode.INVALID_EPOCH, "epoch.nanosec = -1"),
    "epoch beyond int32": (dict(epoch=(2**31, 0)), ErrorCode.INVALID_EPOCH, "int32"),
    "no epoch, moving zone": (dict(epoch=ZERO_EPOCH, tle_line1="", tle_line2=""), ErrorCode.INVALID_EPOCH,
                              "zone 'sun' (body sun) moves with the sky"),
    "no epoch, a TLE": (dict(epoch=ZERO_EPOCH, zones=[]), ErrorCode.INVALID_EPOCH, "a TLE is given"),
    # TLE
    "TLE line 1 only": (dict(tle_line2=""), ErrorCode.INVALID_ORBIT, "tle_line2 is empty"),
    "TLE line 2 only": (dict(tle_line1=""), ErrorCode.INVALID_ORBIT, "tle_line1 is empty"),
    "TLE bad checksum": (dict(tle_line1=TLE[0][:68] + "8"), ErrorCode.INVALID_ORBIT, "checksum"),
    "TLE short line": (dict(tle_line2=TLE[1][:60]), ErrorCode.INVALID_ORBIT, "69 characters"),
    "TLE swapped lines": (dict(tle_line1=TLE[1], tle_line2=TLE[0]), ErrorCode.INVALID_ORBIT, "line number"),
    "TLE other satellite": (dict(tle_line2=with_checksum(TLE[1][:2] + "28486" + TLE[1][7:])), ErrorCode.INVALID_ORBIT,
                            "satellite numbers differ"),
    "TLE garbage field": (dict(tle_line2=with_checksum(TLE[1][:8] + " 2x.5600" + TLE[1][16:])),
                          ErrorCode.INVALID_ORBIT, "inclination"),
    "TLE with NUL": (dict(tle_line1=TLE[0][:10] + "\0" + TLE[0][11:]), ErrorCode.INVALID_TEXT, "tle_line1 contains"),
    "TLE with newline": (dict(tle_line2=TLE[1] + "\n"), ErrorCode.INVALID_TEXT, "tle_line2 contains"),
    "TLE too long": (dict(tle_line1=TLE[0] + " " * 20), ErrorCode.SIZE_LIMIT, "tle_line1 has 89 characters"),
    "TLE orbit too low": (dict(tle_line1=LOW_TLE[0], tle_line2=LOW_TLE[1]), ErrorCode.ORBIT_TOO_LOW,
                          "below the minimum 150 km"),
    # zones: fields
    "unknown body": (dict(zones=[zone(body="jupiter")]), ErrorCode.INVALID_ZONE, "zones[0] ('z').body 'jupiter'"),
    "body with NUL": (dict(zones=[zone(body="sun\0")]), ErrorCode.INVALID_TEXT, "zones[0].body contains"),
    "name with escape": (dict(zones=[SUN, zone(name="z\x1b[31m")]), ErrorCode.INVALID_TEXT, "zones[1].name"),
    "name too long": (dict(zones=[zone(name="z" * 129)]), ErrorCode.SIZE_LIMIT, "zones[0].name has 129"),
    "sensor axis zero": (dict(zones=[zone(sensor_axis=np.zeros(3))]), ErrorCode.INVALID_ZONE,
                         "zones[0] ('z').sensor_axis is the zero vector"),
    "sensor axis nan": (dict(zones=[zone(sensor_axis=[NAN, 0, 1])]), ErrorCode.INVALID_ZONE, "sensor_axis has NaN"),
    "half-angle 0": (dict(zones=[zone(half_angle=0.0)]), ErrorCode.INVALID_ZONE, "half_angle = 0.0 rad is outside"),
    "half-angle pi": (dict(zones=[zone(half_angle=math.pi)]), ErrorCode.INVALID_ZONE, "outside (0, pi)"),
    "half-angle nan": (dict(zones=[zone(half_angle=NAN)]), ErrorCode.INVALID_ZONE, "half_angle = nan"),
    "half-angle inf": (dict(zones=[zone(half_angle=INF)]), ErrorCode.INVALID_ZONE, "half_angle = inf"),
    "limb margin negative": (dict(zones=[zone(body="earth_limb", half_angle=-0.1)]), ErrorCode.INVALID_ZONE,
                             "beyond the Earth's limb"),
    "limb margin pi/2": (dict(zones=[zone(body="earth_limb", half_angle=math.pi / 2)]), ErrorCode.INVALID_ZONE,
                         "[0, pi/2)"),
    "inertial without direction": (dict(zones=[zone(body="inertial")]), ErrorCode.INVALID_ZONE,
                                   "needs a unit direction"),
    "inertial direction inf": (dict(zones=[inertial([0, INF, 0], 0.3)]), ErrorCode.INVALID_ZONE, "NaN or Inf"),
    "sun with a direction": (dict(zones=[zone(direction=Z)]), ErrorCode.INVALID_ZONE, "only an inertial zone"),
    "17 zones": (dict(zones=[SUN] * (MAX_ZONES + 1)), ErrorCode.SIZE_LIMIT, "17 zones given; at most 16"),
    "a million zones": (dict(zones=[SUN] * 1_000_000), ErrorCode.SIZE_LIMIT, "1000000 zones given"),
    # zones against the ends and each other
    "start in an inertial zone": (dict(zones=[inertial(X, 0.2, name="star")]), ErrorCode.ZONE_AT_END,
                                  "start attitude is inside keep-out zone star"),
    "goal outside a keep-in zone": (dict(zones=[inertial(X, math.radians(100), keep_in=True, name="antenna")]),
                                    ErrorCode.ZONE_AT_END, "goal attitude is outside keep-in zone antenna"),
    "start in the Earth limb": (dict(epoch=datetime(2026, 12, 21, tzinfo=UTC)), ErrorCode.ZONE_AT_END,
                                "start attitude is inside keep-out zone earth"),
    "keep-in inside keep-out": (dict(zones=[inertial(Z, 0.3, keep_in=True, name="in"), inertial(Z, 0.5, name="out")]),
                                ErrorCode.CONTRADICTORY_ZONES, "keep-in zone in lies entirely inside keep-out zone"),
    "keep-ins apart": (dict(zones=[inertial(Z, 0.3, True, "a"), inertial(-Z, 0.3, True, "b")]),
                       ErrorCode.CONTRADICTORY_ZONES, "do not meet"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_sky_request_is_refused_with_its_code_naming_the_field(name):
    fields, code, words = CASES[name]
    with pytest.raises(RequestError) as err:
        validate(sky_request(**fields))
    assert (err.value.code, words in err.value.message) == (code, True), err.value.message
    assert len(err.value.message) <= 400


@pytest.mark.parametrize("epoch, words", [
    ("2045-06-01T00:00:00Z", "outside the builtin_interfaces/Time span"),
    ("2051-01-01T00:00:00Z", "epoch must be an ISO 8601 UTC time"),           # the loader refuses it first
    ("1970-01-01T00:00:00Z", "the zero time that means 'no epoch'"),
])
def test_a_scenario_epoch_the_wire_cannot_carry_is_refused(tmp_path, monkeypatch, epoch, words):
    monkeypatch.setenv("ATT_CONFIG_PATH", str(tmp_path))
    (tmp_path / "late.yaml").write_text(f'/**:\n  ros__parameters:\n    epoch: "{epoch}"\n    spacecraft:\n'
                                        "      inertia_kg_m2: [1, 1, 1]\n      torque_max_Nm: 1.0\n"
                                        "      wheel_inertia_kg_m2: 0.01\n")
    with pytest.raises(RequestError) as err:
        validate(sky_request(epoch=None, tle=("", ""), spacecraft="late"))
    assert err.value.code in (ErrorCode.INVALID_EPOCH, ErrorCode.INVALID_SPACECRAFT), err.value.message
    assert words in err.value.message


def test_there_are_nearly_forty_distinct_hostile_sky_requests():
    assert len(CASES) >= 38


def test_the_client_refuses_a_nul_in_a_zone_or_tle_before_sending():
    with pytest.raises(ValueError, match=r"zones\[1\].name"):
        maneuver_request(rot.IDENTITY, GOAL, X, [], zones=[SUN, zone(name="a\0b")])
    with pytest.raises(ValueError, match="tle_line2"):
        maneuver_request(rot.IDENTITY, GOAL, X, [], tle=(TLE[0], TLE[1][:5] + "\0"))


# -- over ROS: one moving-zone request through the planner node --------------------------------

@pytest.fixture(scope="module")
def planner(ros_suite):
    with ros_suite("swift_demo", nodes=("planner",), name="sky_planner") as s:
        assert s.client.plan_client.wait_for_service(timeout_sec=60)
        yield s


@pytest.mark.ros
def test_a_moving_zone_plan_comes_back_with_its_epoch_and_zones_signed(planner):
    req = maneuver_request(rot.IDENTITY, GOAL, X, [], method="constrained_axis", time_budget=10.0, epoch=EPOCH,
                           zones=ZONES, tle=TLE)
    response = planner.client.plan(req)
    assert response.success, response.message
    plan = response.plan
    assert convert.from_epoch(plan.epoch) == EPOCH
    assert [(z.name, z.body, z.keep_in) for z in plan.zones] == [("sun", "sun", False), ("moon", "moon", False),
                                                                  ("earth", "earth_limb", False)]
    assert min(plan.verification.cone_margins) >= 0.0 and len(plan.verification.cone_margins) == 3
    public = signing.load_public_key(signing.default_key_dir() / signing.PUBLIC_NAME)
    assert signing.check(signing.payload(plan), plan.signature, plan.key_id, public) is None
    forged = copy.deepcopy(plan)
    forged.zones[1].half_angle = math.radians(5)                 # a smaller Moon zone than planned against
    assert signing.check(signing.payload(forged), forged.signature, forged.key_id, public) is not None
    no_epoch = maneuver_request(rot.IDENTITY, GOAL, X, [], zones=ZONES)
    refused = planner.client.plan(no_epoch)
    assert refused.error_code == ErrorCode.INVALID_EPOCH and "moves with the sky" in refused.message
    assert planner.suite.alive()["planner"]


def schedule(**fields):
    """validate_schedule of two targets on the wheeled olivares_staffetti spacecraft, ``fields`` replaced."""
    args = dict(names=["a", "b"], targets=[rot.from_axis_angle([0, 0, 1], 1.0), rot.from_axis_angle([1, 0, 0], 1.0)],
                q_start=rot.IDENTITY, q_end=None, spacecraft="olivares_staffetti", time_budget=5.0, request_frame="",
                epoch=convert.epoch_parts(convert.epoch_msg(EPOCH)), zones=[], tle=TLE)
    args.update(fields)
    return validate_schedule(args.pop("names"), args.pop("targets"), args.pop("q_start"), args.pop("q_end"),
                             args.pop("spacecraft"), args.pop("time_budget"), frame_id="eci",
                             default_spacecraft="olivares_staffetti", default_budget=5.0, **args)


def test_schedule_requests_get_the_same_sky_checks():
    target_dir = rot.dcm_NB(rot.from_axis_angle([0, 0, 1], 1.0)) @ X
    cases = [(dict(zones=[inertial(target_dir, 0.2, name="star")]), ErrorCode.ZONE_AT_END,
              "targets[0] ('a') is inside keep-out zone star"),
             (dict(epoch=ZERO_EPOCH, tle=("", ""), zones=[SUN]), ErrorCode.INVALID_EPOCH, "moves with the sky"),
             (dict(tle=(TLE[0], "")), ErrorCode.INVALID_ORBIT, "tle_line2 is empty"),
             (dict(zones=[zone(body="pluto")]), ErrorCode.INVALID_ZONE, "body 'pluto'")]
    for fields, code, words in cases:
        with pytest.raises(RequestError) as err:
            schedule(**fields)
        assert (err.value.code, words in err.value.message) == (code, True), err.value.message
    valid = schedule(zones=[Zone("sun", "sun", Z, math.radians(20))])
    assert valid.problem.epoch == EPOCH and valid.problem.sky is not None and valid.problem.zones[0].name == "sun"
