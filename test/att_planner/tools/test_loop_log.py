"""The log of an in-process closed loop holds the faults the truth started, on their own topic,
stamped at their onset, as the recorder writes them from the simulator node."""
from __future__ import annotations

from dataclasses import replace

import pytest

from att_msgs_py import convert, topics
from att_msgs_py.log import read_log
from att_planner.tools.closed_loop import ClosedLoop
from att_planner.tools.loop_log import open_loop_log
from att_sim.models import scenario as scen
from att_sim.models.config_faults import spec


def test_an_in_process_loop_logs_the_faults_the_truth_started(tmp_path):
    faults = (spec("wheel", 1, "seized", t_s=0.5), spec("gyro", 2, "bias_step", bias_rad_s=1e-3, t_s=1.0))
    loop = ClosedLoop(replace(scen.load("swift_demo"), faults=faults))
    log, loop.tap = open_loop_log(tmp_path / "run.mcap")
    loop.run(2.0)
    log.close()
    got = read_log(tmp_path / "run.mcap", topics=[topics.SIM_FAULTS], keep_messages=[topics.SIM_FAULTS])
    events = [convert.fault_event_from_msg(m) for m in got[topics.SIM_FAULTS].messages]
    assert [(e.component, e.index, e.kind, e.source) for e in events] == [("wheel", 1, "seized", "scenario"),
                                                                          ("gyro", 2, "bias_step", "scenario")]
    assert [e.t for e in events] == [pytest.approx(0.5), pytest.approx(1.0)]
    assert events[1].bias_rad_s == 1e-3
