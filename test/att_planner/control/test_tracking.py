"""The plan-tracking law (no ROS): feedforward plus quaternion PD through the wheels."""
import math

import numpy as np
import pytest

from att_msgs_py.types import Command, ControlMode
from att_planner.control import tracking
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim import rotations as rot
from att_sim import scenario
from att_sim.simulation import Simulation


@pytest.fixture
def sim():
    s = scenario.load("swift_demo")
    return Simulation(s.spacecraft, s.orbit)


def test_tracking_law_flies_an_eigenaxis_plan_with_wheels(sim):
    """Feedforward + PD through the wheels, commands at 10 Hz: ends at the goal."""
    goal = rot.from_axis_angle([0.3, -0.5, 1.0], 1.5)
    plan = plan_eigenaxis_smooth(ManeuverProblem(sim.sc, rot.IDENTITY, goal))
    dt = 0.1
    for _ in range(int((plan.duration + 30) / dt)):
        ref = tracking.plan_reference(plan, sim.t)
        tau = tracking.tracking_torque(sim.x[:4], sim.x[4:7], ref, kp=1.0, kd=16.0)
        u = tracking.wheel_torques(sim.sc, tau, sim.x[4:7], sim.x[7:])
        sim.set_command(Command(ControlMode.PLAN_TRACKING, u))
        sim.advance(dt)
    assert rot.angle_between(sim.x[:4], goal) < math.radians(0.05)
    assert np.linalg.norm(sim.x[4:7]) < 1e-4
