"""Simulator numerics without ROS: command validation, watchdog, limits, NaN halt."""
import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Command, ControlMode
from att_sim.models import rotations as rot
from att_sim.models import scenario
from att_sim.truth.simulation import Simulation


def command(mode, wheel, dipole=(0, 0, 0), body=(0, 0, 0)) -> Command:
    return Command(mode=mode, wheel_torques=np.asarray(wheel, float), dipole=np.asarray(dipole, float),
                   body_torque=np.asarray(body, float))


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
    assert sim.set_command(command(ControlMode.PLAN_TRACKING, [0.01, 0, 0])) is None
    refusal = sim.set_command(command(ControlMode.PLAN_TRACKING, wheel, dipole, body))
    assert refusal.code == ErrorCode.INVALID_COMMAND and words in refusal.message
    assert sim.wheel_cmd.tolist() == [0.01, 0, 0]          # the previous good command stays
    sim.advance(0.1)
    assert np.all(np.isfinite(sim.x))


def test_unknown_mode_is_rejected(sim):
    assert "mode 9" in sim.set_command(command(9, [])).message


def test_watchdog_zeroes_inputs(sim):
    sim.set_command(command(ControlMode.PLAN_TRACKING, [0.1, 0.1, 0.1]))
    sim.command_timeout = True
    sim.advance(1.0)
    assert np.allclose(sim.applied.wheel_torque, 0) and np.allclose(sim.x[4:7], 0)


def test_wheel_torque_is_limited(sim):
    """Within command_limit_factor (2) x the limit a command saturates; beyond it, it is refused."""
    limit = sim.sc.wheel_torque_max
    assert sim.set_command(command(ControlMode.PLAN_TRACKING, [1.9 * limit, -1.9 * limit, 0.0])) is None
    sim.advance(0.1)
    assert np.allclose(np.abs(sim.applied.wheel_torque[:2]), limit)
    assert sim.set_command(command(ControlMode.PLAN_TRACKING, [5.0, -5.0, 0.0])).code == ErrorCode.COMMAND_LIMIT


def test_non_finite_state_halts_propagation(sim):
    sim.body_cmd = np.array([np.nan, 0, 0])      # bypasses validation on purpose
    x_before = sim.x.copy()
    sim.advance(0.1)
    assert sim.halted and "non-finite" in sim.halt_reason
    assert np.array_equal(sim.x, x_before)
    assert sim.reset(rot.IDENTITY, [0, 0, 0], [], 0.0) is None and not sim.halted


def test_reset_validates(sim):
    assert "norm" in sim.reset([0, 0, 0, 2], [0, 0, 0], [], 0.0).message
    assert "NaN" in sim.reset(rot.IDENTITY, [np.nan, 0, 0], [], 0.0).message
    assert "wheels" in sim.reset(rot.IDENTITY, [0, 0, 0], [1.0], 0.0).message
    assert sim.reset(rot.IDENTITY, [0, 0, 0], [1e30, 0, 0], 0.0).code == ErrorCode.INVALID_RESET


def test_idle_mode_applies_nothing(sim):
    sim.set_command(command(ControlMode.IDLE, [0.1, 0.1, 0.1], [1, 1, 1], [0.1, 0, 0]))
    sim.advance(0.5)
    assert np.allclose(sim.x[4:7], 0) and np.allclose(sim.applied.body_torque, 0)


def test_an_environment_that_fails_halts_propagation_and_changes_nothing():
    """E.g. SGP4 failing on a decayed TLE: the step is not taken, the reason is kept."""
    from att_sim.models import world
    from att_sim.models.geomagnetic import GeomagneticField
    from att_sim.models.orbit import CircularOrbit

    class Decaying(CircularOrbit):
        def state(self, t):
            if t > 1.0:
                raise ValueError(f"orbit: SGP4 fails near t = {t:.0f} s: decayed")
            return super().state(t)

    s = scenario.load("swift_demo")
    e = world.Environment(None, Decaying(s.orbit), GeomagneticField("dipole"), None, s.spacecraft)
    sim = Simulation(s.spacecraft, environment=e, omega0=[0.01, 0, 0])
    sim.advance(0.5)
    sim.advance(0.5)
    x = sim.x.copy()
    sim.advance(0.5)
    assert sim.halted and "environment failed at t = 1.000 s" in sim.halt_reason and "decayed" in sim.halt_reason
    assert sim.t == 1.0 and np.array_equal(sim.x, x)
