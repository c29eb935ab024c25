"""The shipped fault table on the real closed loop (simulator, estimator and controller cores of the
LEO observatory, the demo slew flown on the estimate): no fault reported, the wheel residual well
under its threshold and the tracker innovations' d² distributed as the chi-square the gate assumes."""
from __future__ import annotations

import numpy as np
import pytest

from att_planner.fdir import table
from att_planner.fdir.monitor import FaultMonitor
from att_planner.fdir.tap import MonitorTap
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process
from att_planner.tools.demo import maneuver_from_scenario
from att_sim.models import scenario as scen


@pytest.mark.slow
def test_the_default_table_is_quiet_through_the_demo_slew():
    leo = scen.load("leo_observatory")
    loop = ClosedLoop(leo)
    monitor = FaultMonitor(table.read(), leo.spacecraft, leo.sensors, leo.body_frame_id)
    innovations = []

    class Keep:                                   # the estimator's innovations, kept as the tap takes them
        def take_innovations(self):
            taken = loop.estimator.take_innovations()
            innovations.extend(taken)
            return taken

    loop.tap = MonitorTap(monitor, Keep(), loop.controller.friction)
    residual = []
    (wheels,) = [d for fault_id, d in monitor.detectors["wheels"] if fault_id == "wheel_torque"]
    m = maneuver_from_scenario(leo)
    plan = plan_in_process(leo, m["q0"], m["qf"], m["sensor"], m["cones"], m["zones"], m["method"])
    loop.run(10.0)
    assert loop.execute(plan) is None
    end = loop.sim.t + plan.duration + 120.0
    while loop.sim.t < end:
        loop.tick()
        r = wheels.residual_torque(wheels.last_t) if wheels.last_t is not None else None
        if r is not None:
            residual.append(np.abs(r).max())
    assert loop.tap.reports == [] and monitor.active == {}
    assert max(residual) < 0.5 * table.read().faults["wheel_torque"].threshold_Nm
    d2 = np.array([i.d2 for i in innovations])
    assert len(d2) > 1000 and 2.0 < d2.mean() < 4.0        # chi-square with 3 degrees of freedom: mean 3
