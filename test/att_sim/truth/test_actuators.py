"""Imperfect actuators of the truth: wheel friction is internal (the momentum of body and
wheels is kept) and slows a free wheel as its law says; the drive quantises, adds noise, and a
power-limited motor cannot speed a fast wheel up with full torque; magnetorquers quantise and are
misaligned; every hostile datasheet value is refused naming the field."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import Command, ControlMode
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot
from att_sim.models.actuator_specs import ActuatorSpecs, MagnetorquerSpec, WheelDriveSpec, actuators_from_params
from att_sim.models.environment import OrbitParams
from att_sim.truth.actuators import Magnetorquers, WheelDrive
from att_sim.truth.simulation import Simulation

SC = dyn.Spacecraft(inertia=np.diag([100.0, 100.0, 100.0]), wheel_inertia=0.01, wheel_torque_max=0.12,
                    wheel_speed_max=630.0, dipole_max=10.0)
FRICTION = WheelDriveSpec(coulomb_friction=0.002, viscous_friction=1e-5, friction_speed=0.5)


def simulation(spec: WheelDriveSpec, wheel_speed0=(300.0, -200.0, 0.0)) -> Simulation:
    return Simulation(SC, OrbitParams(), wheel_speed0=wheel_speed0, actuators=ActuatorSpecs(wheels=spec), seed=3)


def test_friction_slows_a_free_wheel_by_its_law_and_keeps_the_total_momentum():
    sim = simulation(FRICTION)
    h0 = dyn.angular_momentum_N(SC, sim.x)
    speed0 = dyn.relative_wheel_speed(SC, sim.x[7:], sim.x[4:7])
    for _ in range(200):                        # 10 s idle
        sim.advance(0.05)
    speed = dyn.relative_wheel_speed(SC, sim.x[7:], sim.x[4:7])
    # |Δν| ≈ ∫ f(ν) dt / I_w (+ the body's share of the exchange, J ≫ I_w): 10 s × (0.002 + 1e-5 ν) / 0.01
    expected = 10.0 * (0.002 + 1e-5 * np.abs(speed0[:2])) / 0.01
    assert np.abs(speed0[:2]) - np.abs(speed[:2]) == pytest.approx(expected, rel=0.02)
    assert abs(speed[2]) < 1e-4                  # the idle wheel only sees the body turn a little
    assert np.allclose(dyn.angular_momentum_N(SC, sim.x), h0, atol=1e-9)   # friction is internal
    assert np.linalg.norm(sim.x[4:7]) > 1e-4                                       # the body took it


def test_drive_quantises_and_adds_its_noise_once_per_step():
    drive = WheelDrive(WheelDriveSpec(torque_quantization=1e-3), np.random.default_rng(0))
    assert np.allclose(drive.hold(np.array([0.0123, -0.0456, 0.0004])), [0.012, -0.046, 0.0])
    noisy = WheelDrive(WheelDriveSpec(torque_noise=2e-4), np.random.default_rng(1))
    samples = np.array([noisy.hold(np.full(3, 0.05)) for _ in range(4000)])
    assert np.allclose(samples.mean(axis=0), 0.05, atol=2e-5) and np.all(np.abs(samples.std(axis=0) / 2e-4 - 1) < 0.05)


def test_a_power_limited_motor_cannot_speed_a_fast_wheel_up_with_full_torque():
    drive = WheelDrive(WheelDriveSpec(power_max=60.0), np.random.default_rng(2))
    u = np.array([0.12, 0.12, -0.12, 0.12])
    speed = np.array([100.0, 600.0, 600.0, -600.0])
    # slow wheel: full torque; fast wheel sped up: 60 W / 600 rad/s; braking: full torque
    assert np.allclose(drive.motor(u, speed), [0.12, 0.1, -0.12, 0.12])
    sim = simulation(WheelDriveSpec(power_max=60.0), wheel_speed0=(600.0, 0.0, 0.0))
    sim.set_command(Command(mode=ControlMode.PLAN_TRACKING, wheel_torques=np.array([0.12, 0.12, 0.0])))
    sim.advance(0.05)
    assert sim.applied.wheel_torque[0] == pytest.approx(0.1, rel=1e-9) and sim.applied.wheel_torque[1] == 0.12


def test_magnetorquers_quantise_and_are_misaligned():
    coils = Magnetorquers(MagnetorquerSpec(quantization=0.01, misalignment=math.radians(0.5)),
                          np.random.default_rng(4))
    m = coils(np.array([1.234, -0.005, 2.0]))
    assert not np.allclose(coils.transfer, np.eye(3))
    assert np.allclose(m, coils.transfer @ np.array([1.23, -0.0, 2.0]))
    assert np.degrees(np.arccos(m @ [1.23, 0, 2.0] / np.linalg.norm(m) / np.linalg.norm([1.23, 0, 2.0]))) < 3.0
    sim = Simulation(SC, OrbitParams(), actuators=ActuatorSpecs(magnetorquers=MagnetorquerSpec(quantization=0.5)))
    sim.set_command(Command(mode=ControlMode.MAGNETORQUER_PD, wheel_torques=np.zeros(3),
                            dipole=np.array([1.3, 20.0, -0.2])))
    sim.advance(0.05)
    assert np.allclose(sim.applied.dipole, [1.5, 10.0, 0.0])     # saturated at 10, then quantised


def test_no_actuator_datasheet_means_the_ideal_actuators_bit_for_bit():
    ideal = Simulation(SC, OrbitParams(), q0=rot.from_axis_angle([1, 0, 0], 0.3), omega0=(0.01, 0, 0))
    again = Simulation(SC, OrbitParams(), q0=rot.from_axis_angle([1, 0, 0], 0.3), omega0=(0.01, 0, 0),
                       actuators=ActuatorSpecs())
    for sim in (ideal, again):
        sim.set_command(Command(mode=ControlMode.PLAN_TRACKING, wheel_torques=np.array([0.01, -0.02, 0.03])))
        for _ in range(50):
            sim.advance(0.05)
    assert np.array_equal(ideal.x, again.x)


@pytest.mark.parametrize("values, field", [
    ({"wheels": {"coulomb_friction_Nm": -0.1}}, "actuators.wheels.coulomb_friction_Nm"),
    ({"wheels": {"friction_speed_rad_s": 0.0}}, "actuators.wheels.friction_speed_rad_s"),
    ({"wheels": {"power_max_W": "lots"}}, "actuators.wheels.power_max_W"),
    ({"wheels": {"stiction": 1.0}}, "actuators.wheels.stiction: expected one of the keys"),
    ({"magnetorquers": {"misalignment_deg": 45.0}}, "actuators.magnetorquers.misalignment_deg"),
    ({"thrusters": {}}, "actuators.thrusters: expected one of the keys"),
    ("wheels", "actuators: expected a valid dictionary"),
])
def test_a_bad_actuator_datasheet_is_refused_naming_the_field(values, field):
    with pytest.raises(ValueError) as err:
        actuators_from_params(values)
    assert field in str(err.value)


def test_stacked_drives_and_coils_give_each_run_what_it_gets_alone():
    """The drives and coils of three runs stacked (a batch) against each one alone, built again from
    the same streams: held torques (one run's watchdog tripped: its command unchanged, nothing
    drawn), the power envelope and the friction law per run, the dipoles."""
    specs = [WheelDriveSpec(coulomb_friction=0.002 * (1 + k), viscous_friction=1e-5, friction_speed=0.5,
                            torque_quantization=1e-4, torque_noise=2e-4, power_max=(60.0, math.inf, 40.0)[k],
                            torque_scale=(1.0 + 0.1 * k, 1.0, 0.9)) for k in range(3)]
    coil_specs = [MagnetorquerSpec(quantization=0.01 * (k + 1), misalignment=math.radians(0.5)) for k in range(3)]

    def units():
        return ([WheelDrive(s, np.random.default_rng(k), 3) for k, s in enumerate(specs)],
                [Magnetorquers(s, np.random.default_rng(10 + k)) for k, s in enumerate(coil_specs)])
    drives, coils = units()
    alone_drives, alone_coils = units()
    rng = np.random.default_rng(3)
    u, speed, m = rng.uniform(-0.12, 0.12, (3, 3)), rng.uniform(-600, 600, (3, 3)), rng.uniform(-5, 5, (3, 3))
    u[0, 0], speed[0, 0] = 0.12, 600.0              # run 0 speeds a fast wheel up: 60 W / 600 rad/s
    stacked = WheelDrive.stack(drives)
    held = stacked.hold(u, [True, False, True])
    net = stacked(held, speed)
    dipoles = Magnetorquers.stack(coils)(m)
    for i, (drive, coil) in enumerate(zip(alone_drives, alone_coils)):
        one = drive.hold(u[i:i + 1]) if i != 1 else u[i:i + 1]
        np.testing.assert_allclose(held[i], one[0], rtol=1e-12, atol=0)
        motor = drive.motor(one, speed[i:i + 1])[0]
        expected = motor - specs[i].friction(speed[i])
        np.testing.assert_allclose(net[i], expected, rtol=1e-12, atol=1e-18)
        np.testing.assert_allclose(dipoles[i], coil(m[i:i + 1])[0], rtol=1e-12, atol=1e-18)
    assert stacked.motor(held, speed)[0, 0] == pytest.approx(0.1)     # the envelope clipped it
