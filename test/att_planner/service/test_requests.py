"""Request validation: 30+ distinct bad requests, each refused with its code and a sentence."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_planner.service.requests import MAX_CONES
from att_sim.models import rotations as rot
from helpers.maneuver_requests import INF, NAN, request, validate

BAD_REQUESTS = {
    # attitudes
    "nan initial": (dict(q_initial=[NAN, 0, 0, 1]), ErrorCode.INVALID_ATTITUDE, "initial_attitude"),
    "inf final": (dict(q_final=[0, 0, INF, 1]), ErrorCode.INVALID_ATTITUDE, "final_attitude"),
    "zero quaternion": (dict(q_initial=[0, 0, 0, 0]), ErrorCode.INVALID_ATTITUDE, "zero quaternion"),
    "norm 2": (dict(q_final=[0, 0, 0, 2.0]), ErrorCode.INVALID_ATTITUDE, "norm 2"),
    "norm 0.99": (dict(q_initial=[0, 0, 0, 0.99]), ErrorCode.INVALID_ATTITUDE, "tolerance"),
    "wrong frame": (dict(frame_id="map"), ErrorCode.INVALID_FRAME, "'map'"),
    "body frame": (dict(frame_id="body"), ErrorCode.INVALID_FRAME, "inertial frame"),
    # sensor axis and cones
    "zero sensor": (dict(sensor_axis=[0, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "zero vector"),
    "nan sensor": (dict(sensor_axis=[NAN, 1, 0]), ErrorCode.INVALID_SENSOR_AXIS, "NaN"),
    "long sensor": (dict(sensor_axis=[2, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS, "unit vector"),
    "zero cone": (dict(cones=[([0, 0, 0], 0.5, "c")]), ErrorCode.INVALID_CONE, "cones[0]"),
    "nan cone": (dict(cones=[([NAN, 0, 1], 0.5, "c")]), ErrorCode.INVALID_CONE, "NaN"),
    "cone not unit": (dict(cones=[([0, 0, 3], 0.5, "c")]), ErrorCode.INVALID_CONE, "unit vector"),
    "half-angle 0": (dict(cones=[([0, 0, 1], 0.0, "c")]), ErrorCode.INVALID_CONE, "half_angle"),
    "half-angle negative": (dict(cones=[([0, 0, 1], -0.2, "c")]), ErrorCode.INVALID_CONE, "half_angle"),
    "half-angle 90": (dict(cones=[([0, 0, 1], math.pi / 2, "c")]), ErrorCode.INVALID_CONE, "half_angle"),
    "half-angle nan": (dict(cones=[([0, 0, 1], NAN, "c")]), ErrorCode.INVALID_CONE, "half_angle"),
    "start in cone": (dict(sensor_axis=[0.5, 0.866, 0]), ErrorCode.SENSOR_IN_CONE,
                      "start sensor direction is inside cone 'sun'"),
    "goal in cone": (dict(q_final=rot.from_axis_angle([0, 0, 1], math.radians(60))), ErrorCode.SENSOR_IN_CONE,
                     "goal sensor direction is inside cone 'sun'"),
    "too many cones": (dict(cones=[([0, 0, 1], 0.1, "c")] * (MAX_CONES + 1)), ErrorCode.SIZE_LIMIT, "at most"),
    "thousands of cones": (dict(cones=[([0, 0, 1], 0.1, "c")] * 5000), ErrorCode.SIZE_LIMIT, "5000 cones"),
    "semi-free target nan": (dict(semi_free=True, sensor_target=[NAN, 0, 0]), ErrorCode.INVALID_SENSOR_AXIS,
                             "sensor_target"),
    "semi-free target in cone": (dict(semi_free=True, sensor_target=[0.5, 0.866, 0]), ErrorCode.SENSOR_IN_CONE,
                                 "sensor_target"),
    # spacecraft
    "unknown spacecraft": (dict(spacecraft="no_such_craft"), ErrorCode.UNKNOWN_SPACECRAFT, "no_such_craft"),
    "path traversal name": (dict(spacecraft="../../etc/passwd"), ErrorCode.UNKNOWN_SPACECRAFT, "configuration name"),
    # method and options
    "unknown method": (dict(method="teleport"), ErrorCode.UNKNOWN_METHOD, "teleport"),
    "unknown option": (dict(option_names=["warp"], option_values=[1.0]), ErrorCode.INVALID_OPTION, "warp"),
    "option out of range": (dict(option_names=["samples"], option_values=[5.0]), ErrorCode.INVALID_OPTION, "outside"),
    "option absurd size": (dict(option_names=["samples"], option_values=[1e9]), ErrorCode.INVALID_OPTION, "outside"),
    "option not integer": (dict(option_names=["samples"], option_values=[100.5]), ErrorCode.INVALID_OPTION, "integer"),
    "option nan": (dict(option_names=["samples"], option_values=[NAN]), ErrorCode.INVALID_OPTION, "outside"),
    "option lists differ": (dict(option_names=["samples", "x"], option_values=[100.0]), ErrorCode.INVALID_OPTION,
                            "option_values"),
    "millions of options": (dict(option_names=["samples"] * 1_000_000, option_values=[100.0] * 1_000_000),
                            ErrorCode.SIZE_LIMIT, "at most"),
    # budget
    "negative budget": (dict(time_budget=-1.0), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
    "nan budget": (dict(time_budget=NAN), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
    "huge budget": (dict(time_budget=1e6), ErrorCode.INVALID_TIME_BUDGET, "time_budget"),
}


@pytest.mark.parametrize("name", sorted(BAD_REQUESTS))
def test_bad_request_is_rejected_with_code_and_sentence(name):
    fields, code, words = BAD_REQUESTS[name]
    with pytest.raises(RequestError) as err:
        validate(request(**fields))
    assert err.value.code == code
    assert words in err.value.message


def test_there_are_more_than_thirty_distinct_bad_requests():
    assert len(BAD_REQUESTS) >= 30


def test_bad_spacecraft_configs_are_rejected(tmp_path, monkeypatch):
    monkeypatch.setenv("ATT_CONFIG_PATH", str(tmp_path))
    cases = {
        "not_spd": ("inertia_kg_m2: [1, 0, 0, 0, -1, 0, 0, 0, 1]", "positive definite"),
        "asymmetric": ("inertia_kg_m2: [1, 0.5, 0, 0, 1, 0, 0, 0, 1]", "symmetric"),
        "triangle": ("inertia_kg_m2: [1, 1, 5]", "triangle inequality"),
        "zero_torque": ("inertia_kg_m2: [1, 1, 1]\n      torque_max_Nm: 0.0", "torque_max_Nm"),
        "neg_wheel": ("inertia_kg_m2: [1, 1, 1]\n      torque_max_Nm: 1.0\n      wheel_torque_max_Nm: -1",
                      "wheel_torque_max_Nm"),
    }
    for name, (body, words) in cases.items():
        body += "\n      wheel_inertia_kg_m2: 0.01"       # the scenario loader's own checks pass
        (tmp_path / f"{name}.yaml").write_text(f"/**:\n  ros__parameters:\n    spacecraft:\n      {body}\n")
        with pytest.raises(RequestError) as err:
            validate(request(spacecraft=name))
        assert err.value.code == ErrorCode.INVALID_SPACECRAFT and words in err.value.message, name


def test_near_unit_quaternion_is_normalised_within_tolerance():
    valid = validate(request(q_initial=[0, 0, 0, 1.0005], cones=[]))
    assert np.linalg.norm(valid.problem.q_initial) == pytest.approx(1.0, abs=1e-15)
