"""Wheel health: a seized wheel, a wheel off, friction ×k and a stuck tachometer each isolated to the
right wheel within 5 s of sim time, on the LEO observatory's tachometer noise and drive imperfections;
no verdict in 2000 s of fault-free noise."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.fdir import table
from att_planner.fdir.wheel_health import WheelTorqueDetector

DT = 0.05                     # s: the tachometer's 20 Hz
PYRAMID = np.array([[1, -1, 0, 0], [0, 0, 1, -1], [1, 1, 1, 1]], float) / math.sqrt(2.0)   # 4 wheels, 45 deg


def friction(leo, speeds, k=1.0):
    d = leo.actuators.wheels
    return k * (d.coulomb_friction_Nm * np.tanh(speeds / d.friction_speed_rad_s) + d.viscous_friction_Nm_s * speeds)


def fly(leo, duration_s, fault=None, fault_at=math.inf, wheel=2, seed=1):
    """A four-wheel pyramid slewing on sinusoidal torques; the detector fed the commanded torques, the
    tachometer's noisy quantized speeds and the expected friction. The verdicts."""
    rng = np.random.default_rng(seed)
    d, tach, I_w = leo.actuators.wheels, leo.sensors.wheel_tachometer, leo.wheel_inertia_kg_m2
    e = table.read().faults["wheel_torque"]                      # the shipped table's entry
    det = WheelTorqueDetector(4, I_w, e.threshold_Nm, e.persistence_s, e.window_s, wheel_axes=PYRAMID)
    speeds = np.array([150.0, -80.0, 60.0, -120.0])     # rad/s relative to the body (the body at rest)
    phase = np.array([0.0, 1.3, 2.1, 4.0])
    frozen = None
    verdicts = []
    for k in range(int(round(duration_s / DT))):
        t = (k + 1) * DT
        u = 0.12 * np.sin(2 * math.pi * t / 90.0 + phase)
        applied = np.round((u + rng.normal(0.0, d.torque_noise_Nm, 4)) / d.torque_quantization_Nm) \
            * d.torque_quantization_Nm
        drag = friction(leo, speeds)
        faulty = t > fault_at
        if faulty and fault == "off":
            applied[wheel] = 0.0
        if faulty and fault == "friction":
            drag[wheel] = friction(leo, speeds[wheel], k=4.0)
        speeds = speeds + (applied - drag) / I_w * DT
        if faulty and fault == "seized":
            speeds[wheel] = 0.0
        measured = np.round((speeds + rng.normal(0.0, tach.noise_rad_per_s, 4)) / tach.quantization_rad_per_s) \
            * tach.quantization_rad_per_s
        if faulty and fault == "tachometer":
            frozen = measured[wheel] if frozen is None else frozen
            measured[wheel] = frozen
        verdicts += det.update(t, measured, u, friction(leo, measured), np.zeros(3))
    return verdicts


@pytest.mark.parametrize("fault", ["seized", "off", "friction", "tachometer"])
@pytest.mark.parametrize("fault_at", [100.0, 131.0])
def test_a_wheel_fault_is_isolated_to_its_wheel_within_5_s(leo, fault, fault_at):
    verdicts = fly(leo, fault_at + 10.0, fault, fault_at, wheel=2)
    assert verdicts, f"{fault} at {fault_at} s not detected"
    first = verdicts[0]
    assert (first.component, first.index, first.detector) == ("wheel", 2, "wheel_torque"), first
    assert [v.index for v in verdicts] == [2]
    assert fault_at < first.t <= fault_at + 5.0, first
    assert "N m" in first.evidence and first.active


def test_no_verdict_on_2000_s_of_fault_free_noise(leo):
    assert fly(leo, 2000.0, seed=7) == []


def test_the_residual_is_the_undelivered_torque():
    """Independent recomputation: a wheel delivering a fraction of its command shows the rest as
    the residual torque, on noiseless speeds."""
    det = WheelTorqueDetector(1, 0.2, threshold_Nm=1.0, persistence_s=0.0, window_s=1.0)
    speed = 10.0
    for k in range(80):
        t = (k + 1) * 0.05
        speed += 0.7 * 0.1 / 0.2 * 0.05                 # 70 % of 0.1 N m delivered
        det.update(t, [speed], [0.1])
    assert det.residual_torque(4.0)[0] == pytest.approx(-0.03, rel=1e-9)


def test_a_wheel_needs_inertia():
    with pytest.raises(ValueError, match="wheel_inertia_kg_m2 > 0"):
        WheelTorqueDetector(3, 0.0, 0.01, 0.5, 1.0)
