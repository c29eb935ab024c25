"""The in-process loop on leo_pyramid with the fault table on and no fault flies exactly as without
one. A wheel seized mid-slew, isolated and the slew re-planned on three wheels
(:mod:`att_planner.tools.fault_flight`): test_bench_faults (the study's case) and, through the
nodes, test/integration/test_fault_recovery.py."""
from __future__ import annotations

import numpy as np

from att_planner.fdir import table
from att_planner.tools.closed_loop import ClosedLoop
from att_sim.models import scenario as scen

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
