"""The allocation on the healthy wheels: a four-wheel pyramid continues on any three, the healthy set
producing the commanded body torque, the failed wheel commanded zero; checked against an independent
least-norm solve on the healthy columns."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.control import wheels
from att_sim.models.dynamics import Spacecraft

PYRAMID = np.array([[1, -1, 0, 0], [0, 0, 1, -1], [1, 1, 1, 1]], float) / math.sqrt(2.0)


def pyramid(torque_max=1.0) -> Spacecraft:
    return Spacecraft(np.diag([3000.0, 4500.0, 6000.0]), PYRAMID, 0.2, wheel_torque_max=torque_max,
                      wheel_speed_max=600.0, body_torque_max=0.25)


@pytest.mark.parametrize("failed", [0, 1, 2, 3])
def test_three_of_four_wheels_produce_the_commanded_torque(failed):
    healthy = np.arange(4) != failed
    A = wheels.healthy_allocation(PYRAMID, healthy)
    rng = np.random.default_rng(failed)
    for tau in rng.normal(0.0, 0.1, (20, 3)):
        u = A @ tau
        assert u[failed] == 0.0
        assert np.allclose(PYRAMID @ u, tau, atol=1e-12)
        u_ref = np.zeros(4)
        u_ref[healthy] = np.linalg.lstsq(PYRAMID[:, healthy], tau, rcond=None)[0]   # independent solve
        assert np.allclose(u, u_ref, atol=1e-12)


def test_all_healthy_is_the_pseudo_inverse():
    assert np.allclose(wheels.healthy_allocation(PYRAMID, np.ones(4, bool)), np.linalg.pinv(PYRAMID), atol=1e-14)


def test_two_wheels_cannot_span_the_body():
    A = wheels.healthy_allocation(PYRAMID, [True, False, True, False])
    tau = np.array([0.1, 0.05, -0.02])
    assert not np.allclose(PYRAMID @ (A @ tau), tau)               # least squares only
    assert np.all(A[[1, 3]] == 0.0)


def test_wheel_command_on_the_healthy_set_puts_the_torque_on_the_body_and_none_on_the_failed_wheel():
    sc = pyramid()
    healthy = np.array([True, True, False, True])
    omega = np.array([[1e-3, -2e-3, 5e-4]])
    speeds = np.array([[100.0, -50.0, 80.0, 20.0]])
    tau = np.array([[0.05, -0.02, 0.03]])
    u = wheels.wheel_command(sc, tau, omega, speeds, null_space_speed=10.0, null_space_gain=0.1, healthy=healthy)
    assert u[0, 2] == 0.0
    h_w = PYRAMID @ (sc.wheel_inertia * speeds[0])                 # every wheel's momentum, the failed one's too
    body = -PYRAMID @ u[0] - np.cross(omega[0], h_w)               # what the wheels put on the body
    assert np.allclose(body, tau[0], atol=1e-12)


def test_the_healthy_mask_scales_the_whole_demand_to_the_limit():
    sc = pyramid(torque_max=0.01)
    healthy = np.array([False, True, True, True])
    tau = np.array([[0.5, 0.0, 0.0]])
    u = wheels.wheel_torques(sc, tau, np.zeros((1, 3)), np.zeros((1, 4)), healthy=healthy)
    free = wheels.healthy_allocation(PYRAMID, healthy) @ tau[0]
    assert u[0, 0] == 0.0 and np.abs(u).max() == pytest.approx(0.01)
    assert np.allclose(-u[0] / np.abs(u[0]).max(), free / np.abs(free).max())   # the direction kept


def test_no_mask_is_unchanged():
    sc = pyramid()
    args = (np.array([[0.05, -0.02, 0.03]]), np.array([[1e-3, 0, 0]]), np.array([[10.0, 20.0, 30.0, 40.0]]))
    assert np.array_equal(wheels.wheel_torques(sc, *args), wheels.wheel_torques(sc, *args, healthy=None))
    assert np.allclose(wheels.wheel_torques(sc, *args), wheels.wheel_torques(sc, *args, healthy=np.ones(4, bool)),
                       atol=1e-15)
