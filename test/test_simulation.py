"""Simulator numerics without ROS: command validation, watchdog, limits, NaN halt, control laws."""
import math

import numpy as np
import pytest

from att_planner import tracking
from att_planner.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim import rotations as rot
from att_sim import scenario
from att_sim.simulation import MODE_IDLE, MODE_PLAN_TRACKING, Simulation


@pytest.fixture
def sim():
    s = scenario.load("swift_demo")
    return Simulation(s.spacecraft, s.orbit)


@pytest.mark.parametrize("wheel, dipole, body, words", [
    ([np.nan, 0, 0], [0, 0, 0], [0, 0, 0], "wheel_torques"),
    ([0, 0, 0], [0, np.inf, 0], [0, 0, 0], "dipole"),
    ([0, 0, 0], [0, 0, 0], [0, 0, -np.inf], "body_torque"),
    ([0, 0], [0, 0, 0], [0, 0, 0], "3 wheels"),
])
def test_bad_commands_are_rejected_and_never_integrated(sim, wheel, dipole, body, words):
    assert sim.set_command(MODE_PLAN_TRACKING, [0.01, 0, 0], [0, 0, 0], [0, 0, 0]) is None
    error = sim.set_command(MODE_PLAN_TRACKING, wheel, dipole, body)
    assert words in error
    assert sim.wheel_cmd.tolist() == [0.01, 0, 0]          # the previous good command stays
    sim.advance(0.1)
    assert np.all(np.isfinite(sim.x))


def test_unknown_mode_is_rejected(sim):
    assert "mode 9" in sim.set_command(9, [], [0, 0, 0], [0, 0, 0])


def test_watchdog_zeroes_inputs(sim):
    sim.set_command(MODE_PLAN_TRACKING, [0.1, 0.1, 0.1], [0, 0, 0], [0, 0, 0])
    sim.command_timeout = True
    sim.advance(1.0)
    assert np.allclose(sim.applied.wheel_torque, 0) and np.allclose(sim.x[4:7], 0)


def test_wheel_torque_is_limited(sim):
    sim.set_command(MODE_PLAN_TRACKING, [5.0, -5.0, 0.0], [0, 0, 0], [0, 0, 0])
    sim.advance(0.1)
    assert np.allclose(np.abs(sim.applied.wheel_torque[:2]), sim.sc.wheel_torque_max)


def test_non_finite_state_halts_propagation(sim):
    sim.body_cmd = np.array([np.nan, 0, 0])      # bypasses validation on purpose
    x_before = sim.x.copy()
    sim.advance(0.1)
    assert sim.halted and "non-finite" in sim.halt_reason
    assert np.array_equal(sim.x, x_before)
    assert sim.reset(rot.IDENTITY, [0, 0, 0], [], 0.0) is None and not sim.halted


def test_reset_validates(sim):
    assert "norm" in sim.reset([0, 0, 0, 2], [0, 0, 0], [], 0.0)
    assert "NaN" in sim.reset(rot.IDENTITY, [np.nan, 0, 0], [], 0.0)
    assert "wheels" in sim.reset(rot.IDENTITY, [0, 0, 0], [1.0], 0.0)


def test_tracking_law_flies_an_eigenaxis_plan_with_wheels(sim):
    """Feedforward + PD through the wheels, commands at 10 Hz: ends at the goal."""
    goal = rot.from_axis_angle([0.3, -0.5, 1.0], 1.5)
    plan = plan_eigenaxis_smooth(ManeuverProblem(sim.sc, rot.IDENTITY, goal))
    dt = 0.1
    for _ in range(int((plan.duration + 30) / dt)):
        ref = tracking.reference(plan.t, plan.q, plan.omega, plan.torque, plan.interpolation, sim.t)
        tau = tracking.tracking_torque(sim.x[:4], sim.x[4:7], ref, kp=1.0, kd=16.0)
        u = tracking.wheel_torques(sim.sc, tau, sim.x[4:7], sim.x[7:])
        sim.set_command(MODE_PLAN_TRACKING, u, [0, 0, 0], [0, 0, 0])
        sim.advance(dt)
    assert rot.angle_between(sim.x[:4], goal) < math.radians(0.05)
    assert np.linalg.norm(sim.x[4:7]) < 1e-4


def test_idle_mode_applies_nothing(sim):
    sim.set_command(MODE_IDLE, [0.1, 0.1, 0.1], [1, 1, 1], [0.1, 0, 0])
    sim.advance(0.5)
    assert np.allclose(sim.x[4:7], 0) and np.allclose(sim.applied.body_torque, 0)


def test_tuned_gains_file_is_loaded_by_the_controller_node(tmp_path):
    """att-tune writes controller.ros__parameters.{kp, kd, m_max}; --params-file loads them."""
    import time

    from att_planner.launch import Suite, isolated_env
    from att_planner.tune_cli import write_gains

    gains = tmp_path / "controller_gains.yaml"
    write_gains(str(gains), 123456.5, 98765432.25, 7.5)
    suite = Suite(isolated_env(), tmp_path)
    suite.start("controller", {"scenario": "bruni_celani"}, params_files=(gains,))
    try:
        end = time.monotonic() + 60
        while time.monotonic() < end and "magnetorquer gains" not in suite.log_text("controller"):
            time.sleep(0.2)
    finally:
        suite.stop()
    assert "kp=123456 kd=9.87654e+07 m_max=7.5" in suite.log_text("controller")
