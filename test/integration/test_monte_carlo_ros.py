"""One dispersed run of a campaign flown in process (att-mc's way) and through the nodes (the
simulator given ``campaign`` and ``run_seed``): the same cores, so the same truth from t = 0 and the
same flight, to within what the scheduling of separate processes changes."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from att_msgs_py import convert
from att_msgs_py.log import read_log
from att_msgs_py.topics import CONTROLLER_STATUS, SENSOR_TRUTH, STATE
from att_planner.nodes.client import maneuver_request
from att_planner.tools.monte_carlo.run import checked, loop_for
from att_sim.models import rotations as rot
from att_sim.truth import dispersions as disp

pytestmark = pytest.mark.ros

DATA = Path(__file__).resolve().parents[1] / "data"
CAMPAIGN = DATA / "campaigns" / "short.yaml"


def test_a_dispersed_run_flies_the_same_in_process_and_through_the_nodes(ros_suite, monkeypatch):
    monkeypatch.setenv("ATT_CONFIG_PATH", str(DATA / "config"))
    setup = checked(disp.load_campaign(CAMPAIGN))
    seed = disp.run_seed(setup.campaign.seed, 2)
    truth, _ = disp.seed_truth(setup.campaign, setup.scenario, seed, setup.maneuver["q0"])
    m = setup.maneuver
    params = {"simulator": {"real_time_factor": 0.0, "campaign": str(CAMPAIGN), "run_seed": seed}}
    with ros_suite("swift_short", params=params, name="monte_carlo_ros") as s:
        response = s.client.plan(maneuver_request(m["q0"], m["qf"], m["sensor"], m["cones"], method=m["method"],
                                                  time_budget=m["time_budget"]))
        assert response.success, response.message
        result = s.client.execute(response.plan.plan_id)
        assert result.success, result.message
        s.stop()
    log = read_log(s.mcap)
    state = log[STATE]
    # the simulator node flew the run's dispersed truth from t = 0, with the run's sensor draws
    assert state["header.stamp"][0] == 0.0
    assert state["attitude"][0] == pytest.approx(truth.q0, abs=1e-12)
    assert state["body_rate"][0] == pytest.approx(truth.omega0, abs=1e-15)
    loop = loop_for(setup, truth)
    truths = []
    loop.tap = lambda topic, t, message: truths.append(message) if topic == SENSOR_TRUTH else None
    # the same plan started from the same state in process: the maneuver's time origin t0 is the
    # controller's latest state when the goal came (its first tracking status says how far past t0)
    plan = convert.plan_from_msg(response.plan)
    status = log[CONTROLLER_STATUS]
    first = np.flatnonzero(status["plan_id"] == plan.plan_id)[0]
    t0 = status["header.stamp"][first] - status["plan_progress"][first] * plan.duration
    loop.run(t0 + loop.step - loop.sim.t)               # the last tick steps the controller on the state at t0
    assert log[SENSOR_TRUTH]["gyro_bias"][0] == pytest.approx(truths[0].gyro_bias, abs=1e-15)
    local = loop.fly(plan)
    assert local.success, local.message
    # the truth at the end of the hold and the flown path: the same to well within the tracker's noise
    a = loop.trace.arrays()
    t_end = min(a["t"][-1], state["header.stamp"][-1])
    # (the node counts its time in steps, the loop adds them up: the same instants to within rounding)
    q_ros = state["attitude"][np.searchsorted(state["header.stamp"], a["t"][a["t"] <= t_end] - 1e-6)]
    apart = rot.angle_between(q_ros, a["q_true"][a["t"] <= t_end])
    tracker = setup.scenario.sensors.star_trackers[0].cross_boresight
    assert math.degrees(apart.max()) * 3600 < 3 * math.degrees(tracker) * 3600, math.degrees(apart.max()) * 3600
    assert abs(result.final_attitude_error - local.final_attitude_error) < 3 * tracker
