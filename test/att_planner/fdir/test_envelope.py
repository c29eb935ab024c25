"""The reduced envelope: the torque and momentum box of the healthy wheels, recomputed independently
by searching the corners of the box for the wheel that reaches its limit first."""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from att_planner.fdir.envelope import envelope, planning_spacecraft
from att_sim.models.dynamics import Spacecraft

PYRAMID = np.array([[1, -1, 0, 0], [0, 0, 1, -1], [1, 1, 1, 1]], float) / math.sqrt(2.0)


def craft() -> Spacecraft:
    return Spacecraft(np.diag([3000.0, 4500.0, 6000.0]), PYRAMID, 0.2, wheel_torque_max=0.3, wheel_speed_max=600.0,
                      body_torque_max=0.25)


def corner_box(G, healthy, limit):
    """The largest V with every corner V·s (s in {±1}³) allocated within ``limit``: by least squares."""
    worst = 0.0
    for s in itertools.product((-1.0, 1.0), repeat=3):
        u = np.linalg.lstsq(G[:, healthy], np.array(s), rcond=None)[0]
        worst = max(worst, np.abs(u).max())
    return limit / worst


@pytest.mark.parametrize("failed", [None, 0, 1, 2, 3])
def test_the_box_of_the_healthy_wheels(failed):
    sc = craft()
    healthy = np.arange(4) != (failed if failed is not None else -1)
    env = envelope(sc, healthy)
    assert env.controllable
    assert env.torque_box_Nm == pytest.approx(corner_box(PYRAMID, healthy, 0.3), rel=1e-12)
    assert env.momentum_box_Nms == pytest.approx(corner_box(PYRAMID, healthy, 0.2 * 600.0), rel=1e-12)
    for k in range(3):                               # one axis alone: the wheel most loaded by e_k
        e = np.eye(3)[k]
        u = np.linalg.lstsq(PYRAMID[:, healthy], e, rcond=None)[0]
        assert env.torque_axis_Nm[k] == pytest.approx(0.3 / np.abs(u).max(), rel=1e-12)
    assert np.all(env.torque_axis_Nm >= env.torque_box_Nm - 1e-12)


def test_losing_a_wheel_shrinks_the_box():
    sc = craft()
    full, three = envelope(sc, np.ones(4, bool)), envelope(sc, [True, True, False, True])
    assert three.torque_box_Nm < full.torque_box_Nm and three.momentum_box_Nms < full.momentum_box_Nms


def test_two_wheels_leave_no_envelope_and_no_plan():
    sc = craft()
    env = envelope(sc, [True, False, True, False])
    assert not env.controllable and env.torque_box_Nm == 0.0
    with pytest.raises(ValueError, match="span the body"):
        planning_spacecraft(sc, [True, False, True, False])


def test_the_planning_spacecraft_keeps_the_healthy_axes_and_the_smaller_bound():
    sc = craft()
    healthy = [True, True, False, True]
    planned = planning_spacecraft(sc, healthy)
    assert planned.n_wheels == 3 and np.array_equal(planned.wheel_axes, PYRAMID[:, [0, 1, 3]])
    assert planned.body_torque_max == pytest.approx(min(0.25, envelope(sc, healthy).torque_box_Nm))
