"""The responses acted on (att_planner.fdir.recovery.act) on the leo_pyramid controller and estimator:
the allocation on the healthy wheels in every command (the batched tracking law included), the
estimator's exclusions, safe mode with its actuation on what is left; and nothing changed without a
fault."""
from __future__ import annotations

import numpy as np
import pytest

from att_msgs_py.types import ControlMode
from att_planner.control.controller import step_controllers
from att_planner.fdir import recovery
from att_planner.fdir.responses import Responses
from att_planner.tools.closed_loop import ClosedLoop
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

PYRAMID = scen.load("leo_pyramid")
ALL = (True, True, True, True)


def responses(healthy=ALL, excluded=(), safe=False, controllable=True, gyro=True):
    return Responses(tuple(healthy), controllable, frozenset(excluded), gyro, safe, ("x",) if safe else ())


@pytest.fixture
def loop():
    loop = ClosedLoop(PYRAMID, q0=rot.IDENTITY)
    loop.run(5.0)
    return loop


def test_no_fault_changes_nothing(loop):
    ctl = loop.controller
    ended = recovery.act(responses(), ctl, loop.estimator)
    assert ended is None and ctl.healthy is None and ctl.safe_actuation is None
    assert loop.estimator.excluded == set()


def test_a_failed_wheel_is_commanded_nothing_and_the_others_make_the_torque(loop):
    ctl = loop.controller
    ctl.hold_q_RN, ctl.mode = rot.from_axis_angle(np.array([1.0, 0, 0]), 0.2), ControlMode.PLAN_TRACKING
    ctl.next_control = -np.inf
    healthy_torques = step_controllers([ctl])[0].command.wheel_torques
    recovery.act(responses((True, False, True, True)), ctl, loop.estimator)
    assert ctl.healthy == (True, False, True, True)
    u = step_controllers([ctl])[0].command.wheel_torques
    assert u[1] == 0.0 and np.abs(u).max() > 0
    sc = ctl.spacecraft
    body = -(sc.wheel_axes @ u)                    # the torque the wheels put on the body, the same demand
    assert np.linalg.norm(body - (-(sc.wheel_axes @ healthy_torques))) < 0.05 * np.linalg.norm(body) + 1e-9
    assert not np.allclose(u, healthy_torques)


def test_excluded_sensors_reach_the_estimator(loop):
    recovery.act(responses(excluded=("st1", "magnetometer")), loop.controller, loop.estimator)
    assert loop.estimator.excluded == {"st1", "magnetometer"}
    recovery.act(responses(), loop.controller, loop.estimator)
    assert loop.estimator.excluded == set()


def test_safe_mode_switches_the_controller_and_puts_its_torque_on_the_coils_without_wheels(loop):
    ctl = loop.controller
    recovery.act(responses((True, False, False, True), safe=True, controllable=False), ctl, loop.estimator)
    assert ctl.mode == ControlMode.SAFE and ctl.safe_actuation is not None
    ctl.next_control = -np.inf
    out = step_controllers([ctl])[0]
    assert np.all(out.command.wheel_torques == 0.0)
    assert "cross_product" in out.status.message


def test_safe_mode_with_the_gyro_distrusted_damps_with_b_dot(loop):
    ctl = loop.controller
    ctl.safe_zones = None                          # no zones known: the laws on what is left
    recovery.act(responses(safe=True, gyro=False), ctl, loop.estimator)
    for _ in range(2):                             # B-dot needs two fields
        ctl.next_control = -np.inf
        out = step_controllers([ctl])[0]
    assert "b_dot" in out.status.message and np.all(out.command.wheel_torques == 0.0)


def test_safe_mode_on_healthy_wheels_is_the_controllers_own_law(loop):
    ctl = loop.controller
    ctl.safe_zones = None                          # no zones known: the controller's own law
    recovery.act(responses((True, True, False, True), safe=True), ctl, loop.estimator)
    ctl.next_control = -np.inf
    out = step_controllers([ctl])[0]
    assert ctl.mode == ControlMode.SAFE and "what is left" not in (out.status.message or "")
    assert out.command.wheel_torques[2] == 0.0


@pytest.mark.parametrize("gyro", [True, False])
def test_safe_mode_with_the_scenarios_zones_flies_among_them_on_the_healthy_wheels(loop, gyro):
    ctl = loop.controller
    assert ctl.safe_zones is not None and ctl.safe_zones.names == [z.name for z in PYRAMID.zones]
    recovery.act(responses((True, True, False, True), safe=True, gyro=gyro), ctl, loop.estimator)
    assert ctl.safe_actuation.keeper is not None and ctl.safe_actuation.keeper.zones is ctl.safe_zones
    ctl.next_control = -np.inf
    out = step_controllers([ctl])[0]
    assert "among_zones" in out.status.message and out.command.wheel_torques[2] == 0.0
    assert np.all(out.command.dipole == 0.0)
    keeper = ctl.safe_actuation.keeper
    recovery.act(responses((True, True, False, True), safe=True, gyro=not gyro), ctl, loop.estimator)
    assert ctl.safe_actuation.keeper is keeper                   # the momentum and the target are kept
