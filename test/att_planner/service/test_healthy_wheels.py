"""A maneuver request's ``healthy_wheels``: the plan made for the envelope of those wheels (their axes
only, the per-axis torque bound within their torque box) and signed for the whole spacecraft's
configuration; a set of the wrong length or that cannot control the attitude refused (164)."""
from __future__ import annotations

import math
import time

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_planner.fdir.envelope import envelope
from att_planner.service.requests import ManeuverRequest, validate_maneuver
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

PYRAMID = scen.load("leo_pyramid")


def validate(healthy, wheel_speeds=()):
    request = ManeuverRequest(PYRAMID.frame_id, rot.IDENTITY, rot.from_axis_angle([0, 0, 1], math.radians(30)),
                              np.array([1.0, 0.0, 0.0]), [], spacecraft="leo_pyramid", healthy_wheels=list(healthy),
                              wheel_speeds=list(wheel_speeds))
    return validate_maneuver(request, frame_id=PYRAMID.frame_id, default_spacecraft="leo_pyramid",
                             default_method="eigenaxis_smooth", default_budget=5.0)


def test_the_plan_is_made_for_the_healthy_wheels_envelope_and_named_for_the_whole_spacecraft():
    sc = PYRAMID.spacecraft
    every = validate([])
    assert every.problem.spacecraft.digest == every.spacecraft_digest == sc.digest
    three = validate([True, False, True, True], wheel_speeds=[10.0, 20.0, 30.0, 40.0])
    planned = three.problem.spacecraft
    assert planned.wheel_axes.shape == (3, 3)
    assert np.array_equal(planned.wheel_axes, sc.wheel_axes[:, [0, 2, 3]])
    box = envelope(sc, [True, False, True, True]).torque_box_Nm
    assert planned.body_torque_max == pytest.approx(min(sc.body_torque_max, box)) and box < sc.body_torque_max
    assert np.array_equal(three.problem.wheel_speeds, [10.0, 30.0, 40.0])     # the healthy ones' speeds
    assert three.spacecraft_digest == sc.digest != planned.digest
    assert three.problem.deadline <= time.monotonic() + 5.0


@pytest.mark.parametrize("healthy, words", [([True, True, True], "expected 4 values"),
                                            ([True] * 70, "found 70"),
                                            ([True, False, False, True], "cannot be controlled"),
                                            ([False] * 4, "cannot be controlled")])
def test_a_wheel_set_of_the_wrong_length_or_that_cannot_control_the_attitude_is_refused(healthy, words):
    with pytest.raises(RequestError) as err:
        validate(healthy)
    assert err.value.code == ErrorCode.INVALID_WHEEL_SET and words in err.value.message
    assert err.value.message.startswith("healthy_wheels: expected")
