"""The shipped fault table on the LEO observatory's closed loop (simulator, estimator and controller
cores, flown on the estimate), the truth's own hardware faults injected (``Simulation.inject``), the
exclusions fed back to the estimator each step: each fault isolated to its component and unit alone,
within 5 s (wheels, gyro) or 30 s (the others), the estimator continuing on the healthy tracker."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import FaultSource, Health
from att_planner.fdir import table
from att_planner.fdir.monitor import FaultMonitor
from att_planner.fdir.tap import MonitorTap
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process
from att_planner.tools.demo import maneuver_from_scenario
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.config_faults import spec

ARCSEC = math.pi / 180.0 / 3600.0
LEO = scen.load("leo_observatory")
STEP = math.radians(0.01)                       # rad/s: a gyro bias step


def fly(fault, at: float, plan=None, after: float = 35.0):
    """The loop with the truth fault ``fault`` (component, index, kind, parameters) from sim time
    ``at`` (``plan`` flown from 10 s); the loop and its monitor."""
    loop = ClosedLoop(LEO)
    monitor = FaultMonitor(table.read(), LEO.spacecraft, LEO.sensors, LEO.body_frame_id)
    loop.tap = MonitorTap(monitor, loop.estimator, loop.controller.friction)
    component, index, kind, parameters = fault
    assert loop.sim.inject(spec(component, index, kind, t_s=at, **parameters), FaultSource.SERVICE) is None
    if plan is not None:
        loop.run(10.0)
        assert loop.execute(plan) is None
    while loop.sim.t < at + after:
        loop.tick()
        loop.estimator.excluded = set(monitor.responses().excluded_sensors)
    return loop, monitor


# name: (truth fault, isolated component, index, latency s); the hold with st1 blinded by the Earth
HOLD = {"tracker 1 outage": (("star_tracker", 1, "outage", {}), "star_tracker", 1, 30.0),
        "gyro axis 0 stuck": (("gyro", 0, "axis_stuck", {}), "gyro", 0, 5.0),
        "gyro axis 2 stuck": (("gyro", 2, "axis_stuck", {}), "gyro", 2, 5.0),
        "gyro axis 2 bias step": (("gyro", 2, "bias_step", {"bias_rad_s": STEP}), "gyro", 2, 5.0),
        "tachometer 1 stuck": (("wheel", 1, "tachometer_stuck", {}), "wheel_tachometer", 1, 5.0),
        "magnetometer stuck": (("magnetometer", 0, "stuck", {}), "magnetometer", 0, 30.0)}
# 140 s into the demo slew, both trackers in view
SLEW = {"tracker 0 bias jump": (("star_tracker", 0, "bias_jump", {"bias_rad": (2e-4, -2e-4, 0.0)}),
                                "star_tracker", 0, 30.0),
        "wheel 0 seized": (("wheel", 0, "seized", {}), "wheel", 0, 5.0),
        "wheel 2 friction x5": (("wheel", 2, "friction", {"factor": 5.0}), "wheel", 2, 5.0),
        "gyro axis 0 bias step": (("gyro", 0, "bias_step", {"bias_rad_s": STEP}), "gyro", 0, 5.0)}


def isolated(monitor, component, index, at, latency):
    first = monitor.history[0]
    assert (first.component, first.index) == (component, index), monitor.history
    assert at < first.detected_at <= at + latency, first
    assert {(s.component, s.index) for s in monitor.history} == {(component, index)}, monitor.history


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(HOLD))
def test_a_fault_in_a_hold_is_isolated(name):
    fault, component, index, latency = HOLD[name]
    _, monitor = fly(fault, 100.0)
    isolated(monitor, component, index, 100.0, latency)


@pytest.fixture(scope="module")
def demo_plan():
    m = maneuver_from_scenario(LEO)
    return plan_in_process(LEO, m["q0"], m["qf"], m["sensor"], m["cones"], m["zones"], m["method"])


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SLEW))
def test_a_fault_mid_slew_is_isolated(name, demo_plan):
    fault, component, index, latency = SLEW[name]
    loop, monitor = fly(fault, 150.0, demo_plan)
    isolated(monitor, component, index, 150.0, latency)
    if component == "star_tracker":                    # flown on st2 alone: the estimate stays on the truth
        assert loop.estimator.excluded == {"st1"}
        x, truth = loop.estimator.state, loop.sim.x
        q_true = rot.propagate_constant_rate(truth[:4], truth[4:7], x.t - loop.sim.t)   # at the estimate's instant
        assert rot.angle_between(x.q_BN, q_true) < 30.0 * ARCSEC


@pytest.mark.slow
def test_a_jump_of_the_lone_tracker_is_isolated_before_the_estimate_is_lost():
    """In the hold st1 is blinded by the Earth: st2 alone feeds the estimator, whose gate rejects a
    jump's measurements and drops the estimate at the fifth. tracker_step isolates st2 first, so the
    estimate is never lost and stays on the truth (gyro and vectors)."""
    jump = ("star_tracker", 1, "bias_jump", {"bias_rad": (2e-4, -2e-4, 0.0)})
    loop, monitor = fly(jump, 100.0)
    isolated(monitor, "star_tracker", 1, 100.0, 1.0)
    health = loop.trace.arrays("t", "health")
    after = health["t"] > 100.0
    assert after.any() and not np.any(health["health"][after] == Health.DIVERGED)
    assert loop.estimator.excluded == {"st2"}
    x, truth = loop.estimator.state, loop.sim.x
    q_true = rot.propagate_constant_rate(truth[:4], truth[4:7], x.t - loop.sim.t)
    assert rot.angle_between(x.q_BN, q_true) < math.radians(0.05)
