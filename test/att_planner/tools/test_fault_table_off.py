"""A maneuver flown through a fault in process (att_planner.tools.fault_flight) on leo_pyramid, its fault
table on: a wheel seized mid-slew is isolated, the allocation goes to the three others, the rest of
the slew is re-planned on their envelope and completed with no zone entered; and a loop without a
fault table, or with one and no fault, flies exactly as before."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import FaultSource
from att_planner.fdir import table
from att_planner.tools import fault_flight
from att_planner.tools.closed_loop import ClosedLoop
from att_planner.tools.demo import zone_margins
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.config_faults import spec

PYRAMID = scen.load("leo_pyramid")


def test_a_fault_table_without_a_fault_changes_no_command():
    def commands(fault_table):
        loop = ClosedLoop(PYRAMID, seed=3, fault_table=fault_table)
        loop.run(30.0)
        return loop, loop.trace.arrays("wheel_torques", "dipole", "q_true")

    off, a = commands(None)
    on, b = commands(table.DEFAULT_TABLE)
    assert off.monitor is None and on.monitor is not None and on.monitor.history == []
    for name in a:
        assert np.array_equal(a[name], b[name]), name


@pytest.mark.slow
def test_a_wheel_seized_mid_slew_is_isolated_and_the_slew_re_planned_on_three_wheels():
    from att_planner.tools.bench import faults

    setup = faults.prepare(PYRAMID)
    loop = faults.loop_at_start(setup)
    at = setup.start + 0.4 * setup.plan.duration
    assert loop.sim.inject(spec("wheel", 1, "seized", t_s=at), FaultSource.SERVICE) is None
    flight = fault_flight.fly(loop, setup.plan, setup.maneuver, setup.start + setup.plan.duration + 900.0)
    first = loop.monitor.history[0]
    assert (first.component, first.index, first.response) == ("wheel", 1, "exclude_wheel")
    assert at < first.detected_at <= at + 5.0
    assert loop.controller.healthy == (True, False, True, True)
    after = loop.trace.arrays("t", "wheel_torques", "q_true")
    late = after["t"] > first.detected_at + 0.5
    assert np.all(after["wheel_torques"][late, 1] == 0.0)           # the seized wheel is asked nothing
    assert [r["verified"] for r in flight.replanner.replans] == [True]
    assert flight.result is not None and flight.result.success, flight.result
    assert math.degrees(rot.angle_between(loop.sim.x[:4], setup.maneuver["qf"])) < 0.1
    _, margins = zone_margins(PYRAMID, setup.maneuver, after["t"], after["q_true"])
    assert margins.min() > 0.0
