"""Plans from where the running simulator's spacecraft is now: the tests of a module share one
spacecraft and run in any order, so each plans from the latest state it hears."""
from __future__ import annotations

from att_msgs.msg import SpacecraftState
from att_msgs_py import convert, qos, topics
from att_msgs_py.types import State
from att_planner.nodes.client import maneuver_request
from att_sim.models import rotations as rot
from helpers.waiting import wait_until

SENSOR = [1.0, 0.0, 0.0]


def latest_state(client, timeout: float = 10.0) -> State:
    """The first state ``client`` hears from the simulator within ``timeout`` s of wall time."""
    got = []
    sub = client.create_subscription(SpacecraftState, topics.STATE, got.append, qos.STREAM_QOS)
    try:
        wait_until(lambda: got, timeout, "a state from the simulator", node=client)
        return convert.state_from_msg(got[-1])
    finally:
        client.destroy_subscription(sub)


def plan_from_here(client, angle: float, axis=(0, 0, 1), **kw):
    """An eigenaxis_smooth slew of ``angle`` rad about body ``axis`` from the latest state, planned
    by the planner node (``kw``: more request fields): (the plan message, its goal attitude)."""
    q0 = latest_state(client).q
    goal = rot.multiply(q0, rot.from_axis_angle(axis, angle))
    response = client.plan(maneuver_request(q0, goal, SENSOR, [], method="eigenaxis_smooth", **kw))
    assert response.success, response.message
    return response.plan, goal
