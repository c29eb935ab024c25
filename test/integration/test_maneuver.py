"""End to end: nodes as processes on an isolated domain, a maneuver planned over the service,
executed on the simulator, and the recorded MCAP checked by replay."""
from __future__ import annotations

import json
import math
from contextlib import ExitStack
from pathlib import Path

import numpy as np
import pytest

from att_msgs_py import convert
from att_msgs_py.errors import ErrorCode
from att_msgs_py.log import read_log
from att_msgs_py.topics import COMMAND, PLANS, STATE
from att_msgs_py.types import Cone, Stage, Status
from att_planner.cones import margins
from att_planner.nodes.client import maneuver_request
from att_sim.models import rotations as rot

pytestmark = pytest.mark.ros

SENSOR = np.array([1.0, 0.0, 0.0])
CONES = [Cone([0.5, 0.866, 0.0], math.radians(47), "sun"), Cone([0.0, 0.0, -1.0], math.radians(33), "earth"),
         Cone([0.1795, 0.3109, 0.9333], math.radians(23), "moon")]
GOAL = rot.from_axis_angle([0, 0, 1], math.radians(135))
LAYOUT = Path(__file__).parents[2] / "docs" / "foxglove_layout.json"


class RunningSuite:
    """The module's nodes, started again for the next test when one stopped them (the recorded test
    stops them to read the finalised log): every test finds them running, in whatever order."""

    def __init__(self, ros_suite):
        self.ros_suite, self.stack, self.current = ros_suite, None, None

    def get(self):
        if self.current is None or self.current.exit_codes:
            self.close()
            self.stack = ExitStack()
            self.current = self.stack.enter_context(
                self.ros_suite("swift_demo", params={"simulator": {"real_time_factor": 0.0}}, name="integration_test"))
        return self.current

    def close(self) -> None:
        if self.stack is not None:
            self.stack, self.current, stack = None, None, self.stack
            stack.close()


@pytest.fixture(scope="module")
def running(ros_suite):
    nodes = RunningSuite(ros_suite)
    yield nodes
    nodes.close()


@pytest.fixture
def suite(running):
    return running.get()


def test_bad_request_is_refused_and_the_next_good_one_is_served(suite):
    client = suite.client
    bad = client.plan(maneuver_request([0, 0, 0, 0], GOAL, SENSOR, CONES))
    assert not bad.success and bad.error_code == ErrorCode.INVALID_ATTITUDE and "initial_attitude" in bad.message
    inside = client.plan(maneuver_request(rot.IDENTITY, GOAL, [0.5, 0.866, 0.0], CONES))
    assert inside.error_code == ErrorCode.SENSOR_IN_CONE and "sun" in inside.message
    good = client.plan(maneuver_request(rot.IDENTITY, rot.from_axis_angle([0, 0, 1], 0.3), SENSOR, [],
                                        method="eigenaxis_smooth"))
    assert good.success, good.message
    assert all(suite.suite.alive().values())


def test_a_quick_answer_is_the_first_stage_and_every_stage_is_reported(suite):
    """A 50 ms budget: the verified first plan (graph_smooth), the default method not run; a 20 s
    budget: the default method's plan, quicker than the first plan it was seeded with."""
    client = suite.client
    quick = client.plan(maneuver_request(rot.IDENTITY, GOAL, SENSOR, CONES, time_budget=0.05))
    assert quick.success and quick.stage == Stage.FIRST, quick.message
    first, method = (convert.stage_from_msg(s) for s in quick.stages)
    assert (first.name, first.method, first.verified) == (Stage.FIRST, "graph_smooth", True)
    assert quick.plan.method == "graph_smooth" and quick.plan.status == Status.BUDGET_EXPIRED
    assert first.duration == pytest.approx(quick.plan.duration) and 0 < first.seconds < 1.0
    assert method.name == Stage.METHOD and method.status == "" and not method.verified
    best = client.plan(maneuver_request(rot.IDENTITY, GOAL, SENSOR, CONES, time_budget=20))
    assert best.success and best.stage == Stage.METHOD, best.message
    first, method = (convert.stage_from_msg(s) for s in best.stages)
    assert first.verified and method.verified and method.method == best.plan.method == "smooth_collocation"
    assert method.duration == pytest.approx(best.plan.duration) and method.duration < first.duration


@pytest.mark.slow                                   # 22 s on the 2-core machine
def test_maneuver_is_planned_executed_and_recorded(suite):
    client = suite.client
    response = client.plan(maneuver_request(rot.IDENTITY, GOAL, SENSOR, CONES, time_budget=60))
    assert response.success, response.message
    plan = response.plan
    assert plan.verification.min_cone_margin >= 0 and plan.verification.final_attitude_error < math.radians(1)
    result = client.execute(plan.plan_id)
    assert result.success, result.message
    assert result.final_attitude_error < math.radians(0.5)
    codes = suite.stop()          # flush and finalise the log before replaying it
    assert all(code == 0 for code in codes.values()), codes
    log = read_log(suite.mcap)
    state = log[STATE]
    assert len(state) > 100 and len(log[COMMAND]) > 50 and len(log[PLANS]) >= 1
    assert state["header.stamp"][-1] > plan.duration
    m = margins(state["attitude"], SENSOR, CONES)
    assert m.min() >= 0.0, f"recorded path enters a cone by {np.degrees(-m.min()):.3f} deg"
    assert rot.angle_between(state["attitude"][-1], GOAL) < math.radians(0.5)
    assert np.linalg.norm(state["body_rate"][-1]) < 1e-3
    # the shipped Foxglove layout opens this log: every topic it references holds messages in it
    from mcap.reader import make_reader
    with open(suite.mcap, "rb") as fh:
        summary = make_reader(fh).get_summary()
    counts = {summary.channels[c].topic: n for c, n in summary.statistics.channel_message_counts.items()}
    config = json.loads(LAYOUT.read_text())["configById"]
    referenced = {path.split(".")[0] for panel in config.values() for path in
                  [*panel.get("topics", {}), *(p["value"] for p in panel.get("paths", [])), panel.get("topicPath", "")]
                  if path}
    assert len(referenced) >= 5
    assert {t: counts.get(t, 0) for t in referenced if not counts.get(t)} == {}
