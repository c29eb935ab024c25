"""Hostile fault injection requests to the simulator, refused with a code and a sentence naming the field.

Each case drives :meth:`~att_sim.truth.simulation.Simulation.request_fault` with the fields of an
``att_msgs/InjectFault`` request, one made wrong, on the swift_demo spacecraft (3 wheels, a gyro,
a magnetometer, one star tracker, a tachometer) with fault injection allowed: it must be refused
with its code and a sentence naming the field, schedule nothing, and the next steps must match a
twin that never saw it. A scenario without ``allow_fault_injection`` refuses even a valid request.
The ROS case (the service on a running simulator) is in test/att_sim/truth/test_simulator_faults.py.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from att_msgs.srv import InjectFault
from att_msgs_py import limits
from att_msgs_py.errors import ErrorCode
from att_sim.models import scenario
from att_sim.truth.simulation import Simulation

SWIFT = replace(scenario.load("swift_demo"), allow_fault_injection=True)
INVALID, TEXT, SIZE = ErrorCode.INVALID_FAULT, ErrorCode.INVALID_TEXT, ErrorCode.SIZE_LIMIT
NAN, INF = float("nan"), float("inf")
GOOD = dict(component="wheel", index=1, kind="seized", factor=0.0, bias_rad=np.zeros(0), bias_rad_s=0.0, t_s=1.0)


def make_sim(allowed: bool = True) -> Simulation:
    sim = Simulation.for_scenario(replace(SWIFT, allow_fault_injection=allowed), omega0=(0.0, 0.01, 0.0))
    sim.wheel_cmd = np.array([0.01, 0.02, 0.0])
    return sim


HOSTILE = {
    # component, kind and index
    "component unknown": (dict(component="thruster"), INVALID, "component: expected one of wheel, star_tracker"),
    "component empty": (dict(component=""), INVALID, "component: expected one of"),
    "component in capitals": (dict(component="WHEEL"), INVALID, "found 'WHEEL'"),
    "kind of another component": (dict(kind="outage"), INVALID, "kind: expected one of seized, off, friction"),
    "kind unknown": (dict(kind="exploded"), INVALID, "found 'exploded'"),
    "wheel beyond the wheels": (dict(index=3), INVALID, "index: expected below 3 (the spacecraft has 3 wheels)"),
    "wheel 2**31 - 1": (dict(index=2**31 - 1), INVALID, "index: expected below 3"),
    "index negative": (dict(index=-1), INVALID, "index: expected a whole number >= 0; found -1"),
    "index a float": (dict(index=1.5), INVALID, "index: expected a whole number"),
    "index a bool": (dict(index=True), INVALID, "index: expected a whole number"),
    "gyro axis 3": (dict(component="gyro", kind="axis_stuck", index=3), INVALID, "below 3 (the spacecraft has 3 gyro"),
    "second star tracker": (dict(component="star_tracker", kind="outage", index=1), INVALID,
                            "below 1 (the spacecraft has 1 star trackers)"),
    "coil axis 5": (dict(component="magnetorquer", kind="coil_open", index=5), INVALID, "below 3"),
    # time
    "onset negative": (dict(t_s=-1.0), INVALID, "t_s"),
    "onset NaN": (dict(t_s=NAN), INVALID, "t_s"),
    "onset infinite": (dict(t_s=INF), INVALID, "t_s"),
    "onset 1e12 s": (dict(t_s=1e12), INVALID, "t_s: expected a finite sim time"),
    # parameters
    "friction factor NaN": (dict(kind="friction", factor=NAN), INVALID, "factor"),
    "friction factor negative": (dict(kind="friction", factor=-2.0), INVALID, "factor: expected a friction multiplier"),
    "friction factor 1e6": (dict(kind="friction", factor=1e6), INVALID, "(0, 1000]"),
    "friction without factor": (dict(kind="friction"), INVALID, "factor: expected a value for a friction fault"),
    "factor for a seizure": (dict(factor=2.0), INVALID, "factor: expected none for a seized fault"),
    "bias for a wheel": (dict(bias_rad_s=0.1), INVALID, "bias_rad_s: expected none for a seized fault"),
    "tracker bias of 2 numbers": (dict(component="star_tracker", kind="bias_jump", index=0,
                                       bias_rad=np.array([1e-3, 0.0])), INVALID, "bias_rad: expected 3 finite"),
    "tracker bias NaN": (dict(component="star_tracker", kind="bias_jump", index=0,
                              bias_rad=np.array([NAN, 0.0, 0.0])), INVALID, "bias_rad"),
    "tracker bias of 4 rad": (dict(component="star_tracker", kind="bias_jump", index=0,
                                   bias_rad=np.array([4.0, 0.0, 0.0])), INVALID, "norm in (0, 3.14159] rad"),
    "tracker bias missing": (dict(component="star_tracker", kind="bias_jump", index=0), INVALID,
                             "bias_rad: expected a value"),
    "gyro step of 5 rad/s": (dict(component="gyro", kind="bias_step", index=0, bias_rad_s=5.0), INVALID,
                             "bias_rad_s: expected a non-zero step of at most 1 rad/s"),
    "gyro step infinite": (dict(component="gyro", kind="bias_step", index=0, bias_rad_s=INF), INVALID, "bias_rad_s"),
    # text
    "component with a newline": (dict(component="wheel\n[ERROR] forged"), TEXT, "component"),
    "kind with ESC": (dict(kind="\x1b[31mseized"), TEXT, "kind"),
    "kind of 300 characters": (dict(kind="s" * 300), SIZE, "kind"),
    "component not a string": (dict(component=None), TEXT, "component"),
}


@pytest.mark.parametrize("fields, code, words", HOSTILE.values(), ids=HOSTILE.keys())
def test_a_hostile_fault_request_is_refused_and_changes_nothing(fields, code, words):
    sim, twin = make_sim(), make_sim()
    refusal = sim.request_fault(**{**GOOD, **fields})
    assert refusal is not None and refusal.code == code and words in refusal.message, refusal
    assert sim.faults.pending == [] and sim.faults.started == []
    for _ in range(30):
        sim.advance(0.05)
        twin.advance(0.05)
    assert np.array_equal(sim.x, twin.x)


def test_a_valid_request_is_scheduled_and_starts_at_its_onset_or_at_once():
    sim = make_sim()
    assert sim.request_fault(**GOOD) is None
    assert sim.request_fault(**{**GOOD, "index": 0, "kind": "friction", "factor": 3.0, "t_s": 0.0}) is None
    sim.advance(0.05)
    [first] = sim.faults.take_events()
    assert (first.kind, first.index, first.factor, first.t, first.source) == ("friction", 0, 3.0, 0.0, "service")
    for _ in range(20):
        sim.advance(0.05)
    [seized] = sim.faults.take_events()
    assert seized.kind == "seized" and seized.t == pytest.approx(1.0)
    held = sim.x[8]
    sim.advance(0.05)
    assert sim.x[8] == held


def test_without_allow_fault_injection_even_a_valid_request_is_refused():
    sim = make_sim(allowed=False)
    refusal = sim.request_fault(**GOOD)
    assert refusal.code == ErrorCode.FAULT_INJECTION_DISABLED and "allow_fault_injection" in refusal.message
    assert sim.faults.pending == []


def test_an_oversized_request_is_refused_before_it_is_read():
    request = InjectFault.Request(component="wheel", kind="k" * 1000, bias_rad=[0.0] * 1000)
    err = limits.issue(request, limits.INJECT_FAULT)
    assert err is not None and err.code == SIZE and "kind has 1000" in err.message


def test_there_are_enough_distinct_hostile_fault_requests():
    assert len(HOSTILE) >= 30
