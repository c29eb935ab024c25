"""Momentum management: the cross-product law's torque, the pyramid's null space, the
distribution of a torque over four wheels, and a closed loop that dumps the wheels' momentum while
pointing (and keeps it without dumping)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import ControlMode, PointingMode
from att_planner.control import momentum, wheels
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.control.plan_checks import PlanContext
from att_planner.guidance.laws import PointingGeometry
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world
from att_sim.truth.simulation import Simulation
from helpers.signed_plans import KEY

PYRAMID = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]], float).T / math.sqrt(3.0)
SC = dyn.Spacecraft(inertia=np.diag([100.0, 120.0, 140.0]), wheel_axes=PYRAMID, wheel_inertia=0.01,
                    wheel_torque_max=0.1, wheel_speed_max=600.0, dipole_max=10.0)
RNG = np.random.default_rng(1515)


def test_the_cross_product_law_takes_the_excess_momentum_out_across_the_field():
    for _ in range(20):
        h, b = RNG.normal(size=3), RNG.normal(size=3) * 3e-5
        m = momentum.desaturation_dipole(h, np.zeros(3), b, 1e-3, math.inf)
        across = h - (h @ b) / (b @ b) * b
        assert np.allclose(np.cross(m, b), -1e-3 * across, atol=1e-15)      # m × B = −k Δh⊥
    m = momentum.desaturation_dipole([5.0, 0, 0], [0, 0, 0], [0, 3e-5, 0], 1e-3, 10.0)
    assert np.max(np.abs(m)) == pytest.approx(10.0) and m[2] > 0            # scaled down, direction kept
    assert not np.any(momentum.desaturation_dipole([1.0, 2, 3], [0, 0, 0], [0, 0, 0], 1e-3, 10.0))


def test_the_pyramids_null_space_moves_the_wheels_and_not_the_body():
    N = momentum.null_space(SC)
    assert N.shape == (4, 1) and np.allclose(PYRAMID @ N, 0, atol=1e-12) and np.allclose(N.T @ N, np.eye(1))
    speeds = np.array([10.0, -30.0, 50.0, 5.0])
    u = momentum.null_space_torques(SC, speeds, 100.0, 0.05)
    assert np.allclose(PYRAMID @ u, 0.0, atol=1e-15)                        # no body torque
    assert np.sign((N.T @ u)[0]) == np.sign(100.0 - (N.T @ speeds)[0])     # toward the bias
    three = dyn.Spacecraft(inertia=np.eye(3) * 100, wheel_inertia=0.01)
    assert momentum.null_space(three).size == 0 and not np.any(momentum.null_space_torques(three, [1, 2, 3], 5, 1))


def test_four_wheels_share_a_torque_and_keep_its_direction_at_saturation():
    demand = np.array([0.02, -0.03, 0.01])
    u = wheels.wheel_torques(SC, demand[None], np.zeros((1, 3)), np.zeros((1, 4)))[0]
    assert np.allclose(-PYRAMID @ u, demand, atol=1e-15)
    big = wheels.wheel_torques(SC, 20 * demand[None], np.zeros((1, 3)), np.zeros((1, 4)))[0]
    assert np.max(np.abs(big)) == pytest.approx(SC.wheel_torque_max)
    produced = -PYRAMID @ big
    assert np.allclose(np.cross(produced, demand), 0.0, atol=1e-12) and produced @ demand > 0


@pytest.mark.parametrize("dumping", [True, False])
def test_pointing_dumps_the_wheels_momentum_with_the_magnetorquers(dumping):
    """Holding inertially on a 4-wheel pyramid carrying 0.4 N m s, 20 min in the tilted dipole (the
    10 A m² coils take out at most 3e-4 N m): with dumping the wheels' body momentum falls below
    half, the pointing error stays arcseconds; without it the momentum stays."""
    swift = scen.load("swift_demo")
    sim = Simulation(SC, swift.orbit, wheel_speed0=np.array([40.0, 15.0, -30.0, 5.0]))
    h0 = float(np.linalg.norm(PYRAMID @ (SC.wheel_inertia * sim.x[7:])))
    sky = PointingGeometry.of(world.Environment.circular(SC, swift.orbit))
    config = ControllerConfig(control_period=0.5, tracking_kp=1.0, tracking_kd=25.0, dumping_gain=5e-3,
                              null_space_gain=0.02, null_space_speed=50.0)
    core = Controller(PlanContext(SC, "pyramid", "eci", KEY.public_key()), config, body_frame_id="body",
                      guidance_sky=sky)
    errors = []
    for k in range(2400):
        core.accept_state(sim.state("eci", "body"), wall=sim.t)
        if k == 1:
            assert core.set_mode(ControlMode.POINTING, PointingMode("inertial"), dumping)[0] == 0
        if core.due():
            out = core.step()
            assert sim.set_command(out.command) is None
            errors.append(out.status.attitude_error)
        sim.advance(0.5)
    h = float(np.linalg.norm(PYRAMID @ (SC.wheel_inertia * sim.x[7:])))
    assert max(errors[10:]) < math.radians(0.01)
    assert (h < 0.5 * h0) if dumping else (h > 0.9 * h0), (h, h0)
    null = (momentum.null_space(SC).T @ sim.x[7:])[0]
    assert null == pytest.approx(50.0, abs=5.0)                            # the null-space speed at its bias
    assert rot.angle_between(sim.x[:4], rot.IDENTITY) < math.radians(0.01)
