"""Truth dynamics: conservation laws, quaternion norm, momentum exchange with wheels."""
import numpy as np
import pytest

from att_sim import dynamics as dyn
from att_sim import rotations as rot
from att_sim.environment import OrbitParams

ORBIT_PERIOD = OrbitParams().period


def test_torque_free_conserves_energy_and_momentum_over_ten_orbits():
    sc = dyn.Spacecraft(inertia=np.diag([27.0, 17.0, 25.0]))
    x = dyn.initial_state(sc, rot.from_axis_angle([1, 2, 3], 0.7), [0.01, -0.02, 0.015])
    e0, h0 = dyn.kinetic_energy(sc, x), dyn.angular_momentum_inertial(sc, x)
    dt = 1.0
    steps = int(10 * ORBIT_PERIOD / dt)
    inputs = dyn.Inputs()
    for _ in range(steps):
        x = dyn.step(sc, x, inputs, dt)
    assert abs(dyn.kinetic_energy(sc, x) - e0) / e0 < 1e-9
    assert np.linalg.norm(dyn.angular_momentum_inertial(sc, x) - h0) / np.linalg.norm(h0) < 1e-9
    assert abs(np.linalg.norm(x[:4]) - 1.0) < 1e-12


def test_spinning_wheels_torque_free_conserve_energy_and_momentum():
    sc = dyn.Spacecraft(inertia=np.diag([10.0, 12.0, 14.0]), wheel_inertia=0.05)
    x = dyn.initial_state(sc, rot.IDENTITY, [0.01, -0.02, 0.03], wheel_speed=[100.0, -50.0, 20.0])
    e0, h0 = dyn.kinetic_energy(sc, x), dyn.angular_momentum_inertial(sc, x)
    for _ in range(5000):
        x = dyn.step(sc, x, dyn.Inputs(wheel_torque=np.zeros(3)), 0.05)
    assert abs(dyn.kinetic_energy(sc, x) - e0) / e0 < 1e-9
    assert np.linalg.norm(dyn.angular_momentum_inertial(sc, x) - h0) / np.linalg.norm(h0) < 1e-9


def test_wheels_exchange_momentum_without_changing_the_total():
    sc = dyn.Spacecraft(inertia=np.diag([10.0, 12.0, 14.0]), wheel_inertia=0.02, wheel_torque_max=0.5)
    x = dyn.initial_state(sc, rot.IDENTITY, [0.01, 0.0, -0.01])
    h0 = dyn.angular_momentum_inertial(sc, x)
    for k in range(2000):
        u = 0.05 * np.array([np.sin(0.01 * k), np.cos(0.02 * k), 0.3])
        x = dyn.step(sc, x, dyn.Inputs(wheel_torque=u), 0.05)
    assert np.linalg.norm(dyn.angular_momentum_inertial(sc, x) - h0) < 1e-10 * 1e3


def test_wheel_only_slew_turns_the_body_by_the_momentum_exchange_angle():
    """Spin the z wheel up then down (zero total momentum): the body turns by −I_w ∫Ω dt / J_z."""
    jz, iw = 20.0, 0.05
    sc = dyn.Spacecraft(inertia=np.diag([15.0, 18.0, jz]), wheel_inertia=iw, wheel_torque_max=1.0)
    x = dyn.initial_state(sc)
    dt, integral = 0.01, 0.0
    for k in range(2000):
        u = np.array([0.0, 0.0, 0.2 if k < 1000 else -0.2])
        x_new = dyn.step(sc, x, dyn.Inputs(wheel_torque=u), dt)
        integral += 0.5 * (x[9] + x_new[9]) * dt
        x = x_new
    expected = -iw * integral / jz
    axis, angle = rot.to_axis_angle(x[:4])
    assert abs(x[9]) < 1e-9 and np.linalg.norm(x[4:7]) < 1e-12
    assert axis[2] * angle == pytest.approx(expected, rel=1e-6)
    assert abs(expected) > 0.5           # a real slew, not a rounding error


def test_saturated_wheel_cannot_accelerate_further():
    sc = dyn.Spacecraft(inertia=np.eye(3) * 5, wheel_inertia=0.01, wheel_torque_max=0.1, wheel_speed_max=100.0)
    x = dyn.initial_state(sc, wheel_speed=[0.0, 0.0, 100.0])
    u = dyn.effective_wheel_torque(sc, x[7:], [0.1, 0.1, 0.1])
    assert u.tolist() == [0.1, 0.1, 0.0]
    assert dyn.effective_wheel_torque(sc, x[7:], [0, 0, -0.1])[2] == -0.1


def test_bang_bang_eigenaxis_profile_reaches_the_goal():
    sc = dyn.Spacecraft(inertia=np.eye(3), body_torque_max=1.0)
    half = np.sqrt(np.pi)
    traj = dyn.simulate_profile(sc, dyn.initial_state(sc), [0, half, 2 * half], [[0, 0, 1], [0, 0, -1], [0, 0, 0]])
    assert rot.angle_between(traj.q[-1], rot.from_axis_angle([0, 0, 1], np.pi)) < 1e-5
    assert np.linalg.norm(traj.omega[-1]) < 1e-12
