"""The controller flying on measurements (``state_source: estimate``, no ROS): the state it composes,
what it refuses, how it keeps the loop safe when the estimate cannot be flown, the magnetometer's
blanking and the friction it compensates."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import (
    AttitudeEstimate,
    ControlMode,
    Health,
    MagnetometerMeasurement,
    WheelSpeedMeasurement,
)
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.control.measured_state import MeasuredState
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario
from helpers.signed_plans import context, issue

SWIFT = scenario.load("swift_demo")
CONFIG = ControllerConfig(control_period=0.05, settle_time=5.0)
GOAL = rot.from_axis_angle([0, 0, 1], 0.5)


def controller(friction=None) -> Controller:
    measured = MeasuredState(SWIFT.spacecraft, SWIFT.sensors, "eci", "body")
    return Controller(context(), CONFIG, body_frame_id="body", measured=measured, friction=friction)


def estimate(t: float, health=Health.CONVERGED, q=rot.IDENTITY, omega=(0.0, 0.0, 0.0)) -> AttitudeEstimate:
    return AttitudeEstimate(t=t, q=np.asarray(q, float), omega=np.asarray(omega, float), gyro_bias=np.zeros(3),
                            attitude_covariance=np.eye(3) * 1e-10, bias_covariance=np.eye(3) * 1e-14,
                            health=int(health), frame_id="eci", body_frame_id="body")


def wheels(t: float, speeds=(10.0, -20.0, 30.0)) -> WheelSpeedMeasurement:
    return WheelSpeedMeasurement(t, np.asarray(speeds, float), "body")


def test_the_state_is_the_estimate_with_the_measured_wheels_made_inertial_and_the_clean_field():
    core = controller()
    refused = core.accept_estimate(estimate(0.0)).refused
    assert refused is not None and refused.code == ErrorCode.NO_STATE          # no wheel speed yet
    core.measured.on_wheel_speeds(wheels(0.0))
    core.measured.on_magnetometer(MagnetometerMeasurement(0.0, np.array([2e-5, 0, 1e-5]), np.eye(3), "body"))
    omega = np.array([0.01, 0.02, -0.03])
    assert core.accept_estimate(estimate(0.05, omega=omega)).refused is None
    s = core.state
    assert np.allclose(s.omega, omega) and np.allclose(s.wheel_speeds, np.array([10.0, -20.0, 30.0]) + omega)
    assert np.allclose(s.field_body, [2e-5, 0, 1e-5])
    assert core.estimate_health == Health.CONVERGED


def test_the_rate_is_advanced_from_the_gyro_interval_s_mean_to_the_stamp_by_the_last_command():
    """A constant command about a principal axis from rest: the gyro's mean rate over the interval
    ending at the stamp is the true rate half an interval earlier; advanced with the command's
    acceleration (Euler's equation recomputed here) it is the true rate at the stamp. No advance
    on the first estimate, after a gap or without a command."""
    core = controller()
    sc = SWIFT.spacecraft
    core.measured.on_wheel_speeds(wheels(0.0, speeds=(0.0, 0.0, 0.0)))
    torque_B = np.array([0.0, 0.0, 0.05])                     # on the body, about its principal z axis
    u = -np.linalg.pinv(sc.wheel_axes) @ torque_B              # the motor torques giving it (no spin yet)
    assert np.allclose(-sc.wheel_axes @ u, torque_B)
    alpha = torque_B / np.diag(sc.inertia)
    dt = 0.2
    assert core.accept_estimate(estimate(1.0)).refused is None
    assert np.array_equal(core.state.omega, np.zeros(3))       # the first estimate: nothing to advance from
    core.measured.record_command(1.0, u, np.zeros(3))
    mean = alpha * (dt / 2.0)                                  # the mean rate over [1.0, 1.2] from rest
    core.measured.on_wheel_speeds(wheels(1.2, speeds=-(sc.wheel_axes.T @ (alpha * dt))))   # the wheels spun up
    assert core.accept_estimate(estimate(1.2, omega=mean)).refused is None
    relative = -(sc.wheel_axes.T @ (alpha * dt))
    h_B = sc.wheel_axes @ (sc.wheel_inertia * (relative + sc.wheel_axes.T @ mean))
    euler = np.linalg.solve(sc.inertia, torque_B - np.cross(mean, sc.inertia @ mean + h_B))
    np.testing.assert_allclose(core.state.omega, mean + dt / 2.0 * euler, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(core.state.omega, alpha * dt, rtol=1e-6)         # the true rate at the stamp
    # the wheels' inertial spin is made with the advanced rate
    np.testing.assert_allclose(core.state.wheel_speeds, relative + sc.wheel_axes.T @ core.state.omega, atol=1e-15)
    # a gap longer than an interval, or a command older than it: the estimate's own rate
    assert core.accept_estimate(estimate(1.2 + 2.0, omega=mean)).refused is None
    assert np.array_equal(core.state.omega, mean)
    core.measured.record_command(3.2, u, np.zeros(3))
    core.measured.command = (1.0, u, np.zeros(3))
    assert core.accept_estimate(estimate(3.4, omega=mean)).refused is None
    assert np.array_equal(core.state.omega, mean)


@pytest.mark.parametrize("bad, code", [
    (dict(health=7), ErrorCode.INVALID_STATE),
    (dict(q=(0.0, 0.0, 0.0, 2.0)), ErrorCode.INVALID_ATTITUDE),
    (dict(omega=(math.nan, 0.0, 0.0)), ErrorCode.INVALID_STATE),
])
def test_a_bad_estimate_is_refused(bad, code):
    core = controller()
    core.measured.on_wheel_speeds(wheels(0.0))
    outcome = core.accept_estimate(estimate(0.05, **bad))
    assert outcome.refused is not None and outcome.refused.code in (code, ErrorCode.INVALID_STATE)
    assert core.state is None


@pytest.mark.parametrize("m", [
    WheelSpeedMeasurement(0.0, np.array([1.0, 2.0]), "body"),
    WheelSpeedMeasurement(0.0, np.array([1.0, math.nan, 2.0]), "body"),
    WheelSpeedMeasurement(0.0, np.array([1e5, 0.0, 0.0]), "body"),
    WheelSpeedMeasurement(math.inf, np.zeros(3), "body"),
    WheelSpeedMeasurement(0.0, np.zeros(3), "wheel_frame"),
])
def test_hostile_wheel_speeds_are_refused(m):
    core = controller()
    with pytest.raises(RequestError) as err:
        core.measured.on_wheel_speeds(m)
    assert err.value.code == ErrorCode.INVALID_MEASUREMENT and core.measured.wheel_speeds is None


def test_a_maneuver_starts_on_a_converged_estimate_only_and_ends_safe_when_it_is_lost():
    core = controller()
    core.measured.on_wheel_speeds(wheels(0.0, (0.0, 0.0, 0.0)))
    plan, payload = issue(plan_eigenaxis_smooth(ManeuverProblem(SWIFT.spacecraft, rot.IDENTITY, GOAL)), context())
    assert core.receive_plan(plan, payload) is None
    core.accept_estimate(estimate(0.0, Health.PROPAGATING))
    refused = core.start(plan)
    assert refused is not None and refused.code == ErrorCode.ESTIMATE_UNHEALTHY
    core.accept_estimate(estimate(0.05))
    assert core.start(plan) is None and core.mode == ControlMode.PLAN_TRACKING
    assert core.accept_estimate(estimate(0.1, Health.PROPAGATING)).ended is None      # blind: keep flying
    outcome = core.accept_estimate(estimate(0.15, Health.DIVERGED))
    assert outcome.ended is not None and outcome.ended.error_code == ErrorCode.ABORTED
    assert "diverged" in outcome.ended.message and core.mode == ControlMode.SAFE
    assert core.due() and np.all(np.isfinite(core.step().command.wheel_torques))       # rate damping


def test_magnetorquer_modes_wait_for_a_converged_estimate_and_fall_to_safe_without_one():
    core = controller()
    core.measured.on_wheel_speeds(wheels(0.0))
    core.accept_estimate(estimate(0.0, Health.INITIALISING))
    code, _, _ = core.set_mode(ControlMode.MAGNETORQUER_PD)
    assert code == ErrorCode.ESTIMATE_UNHEALTHY and core.mode == ControlMode.IDLE
    core.accept_estimate(estimate(0.05))
    assert core.set_mode(ControlMode.MAGNETORQUER_PD)[0] == ErrorCode.OK
    note = core.accept_estimate(estimate(0.1, Health.DIVERGED)).note
    assert core.mode == ControlMode.SAFE and "safe mode" in note


def test_the_coils_are_off_over_each_control_period_that_ends_at_a_magnetometer_sample():
    core = controller()
    core.measured.on_wheel_speeds(wheels(0.0))
    core.measured.on_magnetometer(MagnetometerMeasurement(0.0, np.array([2e-5, 1e-5, -1e-5]), np.eye(3), "body"))
    core.accept_estimate(estimate(0.0))
    core.set_mode(ControlMode.MAGNETORQUER_PD)
    on = [True]
    for k in range(1, 40):                  # 2 s at 20 Hz; the swift_demo magnetometer samples at 2 Hz
        t = 0.05 * k
        core.accept_estimate(estimate(t, omega=(0.0, 0.0, 0.01)))
        assert core.due()
        on.append(bool(np.any(core.step().command.dipole != 0)))
    off = [round(0.05 * k, 2) for k, o in enumerate(on) if not o]
    assert off == [0.45, 0.95, 1.45, 1.95]          # the period ending at each 0.5 s sample
    # a sample taken while the coils were on is not used; one after an off period is
    core.measured.on_magnetometer(MagnetometerMeasurement(1.45, np.array([9e-5, 0, 0]), np.eye(3), "body"))
    assert core.measured.field_B[0] == pytest.approx(2e-5)
    core.measured.on_magnetometer(MagnetometerMeasurement(1.5, np.array([3e-5, 0, 0]), np.eye(3), "body"))
    assert core.measured.field_B[0] == pytest.approx(3e-5)


def test_expected_friction_is_added_to_every_wheel_command():
    friction = SWIFT.actuators.wheels.friction
    plain, compensating = controller(), controller(friction)
    for core in (plain, compensating):
        core.measured.on_wheel_speeds(wheels(0.0, (100.0, -50.0, 0.0)))
        core.accept_estimate(estimate(0.0, omega=(0.001, 0.0, 0.0)))
        core.set_mode(ControlMode.SAFE)
        assert core.due()
    difference = compensating.step().command.wheel_torques - plain.step().command.wheel_torques
    relative = np.array([100.0, -50.0, 0.0])
    assert np.allclose(difference, friction(relative), atol=1e-15) and difference[0] > 0 > difference[1]


def test_an_intruders_estimates_while_the_estimator_pauses_are_never_flown():
    """The estimator paused (in the graph, silent) while an intruder publishes converged estimates of
    a rate that does not exist, at 1 kHz for 3 s: the controller never composes a state from them
    (no safe-mode damping of a phantom rate); the estimator's next estimate is flown."""
    estimator, intruder = b"estimator-gid", b"intruder-gid"
    core = controller()
    core.gate.hold.live = lambda: {estimator, intruder}
    core.measured.on_wheel_speeds(wheels(0.0, (0.0, 0.0, 0.0)))
    assert core.accept_estimate(estimate(0.0), wall=0.0, source=estimator).refused is None
    core.step()
    for k in range(3000):
        outcome = core.accept_estimate(estimate(0.001 * (k + 1), omega=(0.02, 0.0, 0.0)), wall=0.001 * (k + 1),
                                       source=intruder)
        assert outcome.refused is not None and "second publisher" in outcome.refused.message
    assert core.state.t == 0.0 and not np.any(core.state.omega)
    assert core.accept_estimate(estimate(0.05), wall=3.1, source=estimator).refused is None
    assert core.due() and np.allclose(core.step().command.wheel_torques, 0.0) and core.mode == ControlMode.IDLE
