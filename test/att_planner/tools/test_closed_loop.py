"""The demo maneuver flown on measurements, in process (the cores the nodes run): the Sun blinds the
star tracker in the middle of the slew, the filter propagates on the gyro, its covariance grows,
it re-converges when the tracker sees again; the pointing after the maneuver is within 3× the
tracker's 1σ and every zone keeps its margin, as with the truth in the loop."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import Health, TrackerStatus
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process
from att_planner.tools.demo import maneuver_from_scenario, zone_margins
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

SWIFT = scen.load("swift_demo")


@pytest.fixture(scope="module")
def demo_plan():
    m = maneuver_from_scenario(SWIFT)
    return m, plan_in_process(SWIFT, m["q0"], m["qf"], m["sensor"], m["cones"], m["zones"], m["method"])


def flown(demo_plan, source: str):
    m, plan = demo_plan
    loop = ClosedLoop(SWIFT, overrides={"controller": {"state_source": source}})
    loop.run(10.0)
    result = loop.fly(plan)
    return loop, result, loop.trace.arrays()


@pytest.mark.slow
def test_the_demo_flies_on_the_estimate_through_a_sun_blinding_of_its_tracker(demo_plan):
    m, plan = demo_plan
    loop, result, a = flown(demo_plan, "estimate")
    assert result.success, result.message
    t, health = a["t"], a["health"]
    # the epoch-free swift_demo's Sun is an inertial exclusion direction: status EXCLUDED
    blind = a["tracker_status"] == TrackerStatus.EXCLUDED
    assert blind.sum() * 0.05 > 20.0                                     # over 20 s blinded by the Sun
    first, last = t[blind][0], t[blind][-1]
    sigma = np.sqrt(np.trace(a["attitude_covariance"], axis1=1, axis2=2))
    before = sigma[(t > first - 5) & (t < first)].mean()
    worst = sigma[(t >= first) & (t <= last + 0.2)].max()
    after = sigma[t > last + 10].max()
    assert worst > 3 * before and after < 1.5 * before                  # grew while blind, shrank after
    assert np.all(health[(t > first + 2.5) & (t < last)] == Health.PROPAGATING)
    assert np.all(health[t > last + 5] == Health.CONVERGED)
    # the estimation error stays within the filter's own 3 sigma (body-frame error against its covariance)
    error = np.array([2 * rot.error_vector(qt, qe) for qt, qe in zip(a["q_true"], a["q_est"])])
    nees = np.einsum("ki,kij,kj->k", error, np.linalg.inv(a["attitude_covariance"]), error)
    assert np.mean(nees < 14.16) > 0.99                                  # chi-square, 3 dof, 99.7 %
    tracker = SWIFT.sensors.star_trackers[0]
    final = rot.angle_between(a["q_true"][-1], m["qf"])
    assert final < 3 * max(tracker.cross_boresight, tracker.about_boresight), math.degrees(final) * 3600
    _, margins = zone_margins(SWIFT, m, t, a["q_true"])
    assert margins.min() > 0.0
    assert not loop.refusals


@pytest.mark.slow
def test_with_the_truth_in_the_loop_the_same_plan_flies_as_before(demo_plan):
    m, _ = demo_plan
    _, result, a = flown(demo_plan, "truth")
    assert result.success and np.all(np.isnan(a["attitude_covariance"]))
    assert rot.angle_between(a["q_true"][-1], m["qf"]) < math.radians(0.01)
