"""The plan-tracking law (no ROS): feedforward plus quaternion PD through the wheels."""
import math

import numpy as np
import pytest

from att_msgs_py.types import Command, ControlMode
from att_planner.control import tracking, wheels
from att_planner.guidance import Reference
from att_planner.methods.eigenaxis import plan_eigenaxis, plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario
from att_sim.truth.simulation import Simulation


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
        u = wheels.wheel_torques(sim.sc, tau[None], sim.x[4:7][None], sim.x[7:][None])[0]
        sim.set_command(Command(ControlMode.PLAN_TRACKING, u))
        sim.advance(dt)
    assert rot.angle_between(sim.x[:4], goal) < math.radians(0.05)
    assert np.linalg.norm(sim.x[4:7]) < 1e-4


def test_rotation_vector_rate_is_the_derivative_of_the_log():
    """φ̇ of exp(φ) ⊗ exp(ω dt) by a central difference, against J_r⁻¹(φ) ω (and ω at φ = 0)."""
    phi, omega, dt = np.array([0.9, -0.4, 1.3]), np.array([0.02, 0.05, -0.01]), 1e-4
    log = []
    for d in (-dt, dt):
        axis, angle = rot.to_axis_angle(rot.multiply(rot.exp_map(phi), rot.exp_map(omega * d)))
        log.append(axis * angle)
    assert np.allclose((log[1] - log[0]) / (2 * dt), tracking.rotation_vector_rate(phi, omega), atol=1e-9)
    assert np.allclose(tracking.rotation_vector_rate(np.zeros(3), omega), omega)


def test_a_three_knot_bang_bang_plan_is_tracked_as_it_flies(sim):
    """A rest-to-rest eigenaxis slew about a principal axis has knots at 0, t_f/2 and t_f only: the
    reference attitude follows φ = ½ α t² between them (a slerp would lead by up to 10°), and the
    closed loop stays within 0.05° of it (commands held 0.1 s across the torque switch)."""
    angle, T, J = math.radians(135.0), sim.sc.body_torque_max, sim.sc.inertia[2, 2]
    plan = plan_eigenaxis(ManeuverProblem(sim.sc, rot.IDENTITY, rot.from_axis_angle([0, 0, 1], angle)))
    assert len(plan.t) == 3
    alpha, tf = T / J, plan.duration
    for t in np.linspace(0.0, tf, 23):
        phi = 0.5 * alpha * t**2 if t <= tf / 2 else angle - 0.5 * alpha * (tf - t) ** 2
        ref = tracking.plan_reference(plan, t)
        assert rot.angle_between(ref.q_RN, rot.from_axis_angle([0, 0, 1], phi)) < 1e-9
    dt, worst = 0.1, 0.0
    for _ in range(int(tf / dt)):
        ref = tracking.plan_reference(plan, sim.t)
        worst = max(worst, rot.angle_between(sim.x[:4], ref.q_RN))
        tau = tracking.tracking_torque(sim.x[:4], sim.x[4:7], ref, kp=1.0, kd=16.0)
        u = wheels.wheel_torques(sim.sc, tau[None], sim.x[4:7][None], sim.x[7:][None])[0]
        sim.set_command(Command(ControlMode.PLAN_TRACKING, u))
        sim.advance(dt)
    assert worst < math.radians(0.05)


def test_the_reference_rate_is_rotated_into_body_axes():
    """120° off a reference turning at 0.1 rad/s: the law's rate error is ω_BN_B − [BR] ω_RN_R and its
    feedforward [BR] τ_R, against an independent recomputation with scipy's rotation matrices
    ([NB], [NR]); a body turning with the reference at a fixed offset has no rate error (the
    unrotated form ω_BN_B − ω_RN_R, right only to first order in the attitude error, is 0.17 rad/s off)."""
    from scipy.spatial.transform import Rotation

    q_RN = rot.from_axis_angle([0.2, -0.7, 0.4], 0.9)
    q_BN = rot.multiply(q_RN, rot.from_axis_angle([1.0, 0.3, -0.5], np.radians(120.0)))
    omega_RN_R, torque_R = np.array([0.06, -0.05, 0.06]), np.array([0.02, 0.01, -0.03])
    ref = Reference(q_RN, omega_RN_R, np.zeros(3), torque_R)
    dcm_BR = Rotation.from_quat(q_BN).as_matrix().T @ Rotation.from_quat(q_RN).as_matrix()
    q_BR = Rotation.from_matrix(dcm_BR.T).as_quat()                      # B relative to R, [x, y, z, w]
    e = q_BR[:3] * np.sign(q_BR[3])
    kp, kd = 1.0, 16.0
    for omega_BN_B in (np.array([0.01, 0.02, -0.03]), dcm_BR @ omega_RN_R):
        expected = dcm_BR @ torque_R - 2.0 * kp * e - kd * (omega_BN_B - dcm_BR @ omega_RN_R)
        assert np.allclose(tracking.tracking_torque(q_BN, omega_BN_B, ref, kp, kd), expected, rtol=0, atol=1e-12)
    locked = dcm_BR @ omega_RN_R                                          # turning with R: ω_BR = 0
    feedback = tracking.tracking_torque(q_BN, locked, ref, kp, kd, feedforward=False)
    assert np.allclose(feedback, -2.0 * kp * e, rtol=0, atol=1e-12)
    assert np.linalg.norm(locked - omega_RN_R) > 0.1                      # what the unrotated form would damp


@pytest.mark.parametrize("interpolation", ["linear", "zoh"])
def test_the_feedforward_held_over_a_step_is_the_plan_s_mean_torque_over_it(interpolation):
    """The mean torque over a control step, against a fine midpoint sum of the plan's torque at each
    instant (plan_reference), for steps inside one knot interval, across knots, from before the
    plan's start and past its end (zero there)."""
    from att_msgs_py.types import Interpolation, Plan

    rng = np.random.default_rng(4)
    t = np.array([0.0, 0.3, 0.35, 1.0, 1.7])
    torque = rng.normal(size=(t.size, 3))
    q = np.tile(rot.IDENTITY, (t.size, 1))
    plan = Plan(t=t, torque=torque, q=q, omega=np.zeros((t.size, 3)), interpolation=Interpolation(interpolation))

    def at(x):
        return tracking.plan_reference(plan, x).torque_R if 0.0 <= x < t[-1] else np.zeros(3)

    for t0, hold in [(0.1, 0.1), (0.25, 0.2), (0.2, 1.0), (-0.1, 0.25), (1.6, 0.2), (1.8, 0.2)]:
        n = 20_000
        fine = np.mean([at(t0 + (k + 0.5) * hold / n) for k in range(n)], axis=0)
        np.testing.assert_allclose(tracking.mean_torque(plan, t0, t0 + hold), fine, atol=2e-4)
        if 0.0 <= t0 < t[-1]:
            ref = tracking.plan_reference(plan, t0, hold)
            np.testing.assert_allclose(ref.torque_R, tracking.mean_torque(plan, t0, t0 + hold))
            assert np.array_equal(ref.q_RN, tracking.plan_reference(plan, t0).q_RN)
