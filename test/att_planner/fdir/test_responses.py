"""The responses as a pure function of the active faults: the healthy wheels, the excluded sensors,
the gyro's trust and safe mode, each recomputed from the faults by hand."""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import FaultStatus
from att_planner.fdir.responses import responses

PYRAMID = np.array([[1, -1, 0, 0], [0, 0, 1, -1], [1, 1, 1, 1]], float) / math.sqrt(2.0)
TRACKERS = ["st1", "st2"]


def fault(fault_id, component, index, response, active=True) -> FaultStatus:
    return FaultStatus(10.0, fault_id, component, index, "d", "e", response, active, 9.0)


def test_no_fault_flies_on_everything():
    r = responses([], PYRAMID, TRACKERS)
    assert r.healthy_wheels == (True,) * 4 and r.wheels_controllable and r.gyro_trusted
    assert r.excluded_sensors == frozenset() and not r.safe_mode and r.why == ()


def test_a_wheel_out_of_four_leaves_three_that_control():
    r = responses([fault("wheel_torque", "wheel", 2, "exclude_wheel")], PYRAMID, TRACKERS)
    assert r.healthy_wheels == (True, True, False, True) and r.wheels_controllable and not r.safe_mode


def test_two_wheels_out_of_four_cannot_control_and_ask_for_safe_mode():
    r = responses([fault("wheel_torque", "wheel", 0, "exclude_wheel"),
                   fault("tachometer_frozen", "wheel_tachometer", 1, "exclude_wheel")], PYRAMID, TRACKERS)
    assert r.healthy_wheels == (False, False, True, True) and not r.wheels_controllable
    assert r.safe_mode and r.why == ("the healthy wheels do not span the body",)


def test_sensors_are_excluded_by_name_and_a_cleared_fault_is_not():
    r = responses([fault("tracker_inconsistent", "star_tracker", 1, "exclude_sensor"),
                   fault("tracker_outage", "star_tracker", 0, "exclude_sensor", active=False),
                   fault("magnetometer_frozen", "magnetometer", 0, "exclude_sensor")], PYRAMID, TRACKERS)
    assert r.excluded_sensors == frozenset({"st2", "magnetometer"}) and not r.safe_mode


def test_a_gyro_fault_withdraws_the_gyro_and_a_report_does_nothing_else():
    r = responses([fault("gyro_axis_frozen", "gyro", 1, "safe_mode"), fault("rate_error", "rate", 0, "report")],
                  PYRAMID, TRACKERS)
    assert not r.gyro_trusted and r.safe_mode and r.why == ("gyro_axis_frozen",)
    assert r.healthy_wheels == (True,) * 4 and r.excluded_sensors == frozenset()


def test_indices_beyond_the_spacecraft_are_ignored():
    r = responses([fault("w", "wheel", 7, "exclude_wheel"), fault("s", "star_tracker", 5, "exclude_sensor")],
                  PYRAMID, TRACKERS)
    assert r.healthy_wheels == (True,) * 4 and r.excluded_sensors == frozenset()
