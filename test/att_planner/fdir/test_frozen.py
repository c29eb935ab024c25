"""Stuck readings: a gyro axis (within 5 s), a tachometer (within 5 s) and the magnetometer (within
30 s) isolated, on the LEO observatory's noise and quantization; nothing in 2000 s of healthy noise."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.fdir.frozen import FrozenDetector

ARCSEC = math.pi / 180.0 / 3600.0


def gyro_samples(leo, duration_s, stuck_axis=None, stuck_at=math.inf, seed=3):
    """Rate samples (t, ω_m) of the gyro: a slow slew, angle random walk, the angle increments quantized."""
    g = leo.sensors.gyro
    dt = 1.0 / g.rate_Hz
    arw = g.arw_deg_per_sqrt_h * math.pi / 180.0 / 60.0          # rad/√s
    q = g.quantization_arcsec * ARCSEC
    rng = np.random.default_rng(seed)
    angle, counted, held = np.zeros(3), np.zeros(3), None
    for k in range(int(round(duration_s * g.rate_Hz))):
        t = (k + 1) * dt
        omega = 1e-3 * np.sin(2 * math.pi * t / 300.0 + np.array([0.0, 1.0, 2.0]))
        angle = angle + omega * dt + rng.normal(0.0, arw * math.sqrt(dt), 3)
        now = np.round(angle / q) * q
        rate = (now - counted) / dt
        counted = now
        if t > stuck_at:
            held = rate[stuck_axis] if held is None else held
            rate[stuck_axis] = held
        yield t, rate


def run(detector, samples):
    out = []
    for t, values in samples:
        out += detector.update(t, values)
    return out


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_stuck_gyro_axis_is_isolated_within_5_s(leo, axis):
    det = FrozenDetector("gyro", "gyro_frozen", 3, 1e-9, 2.0, "rad/s")
    verdicts = run(det, gyro_samples(leo, 230.0, axis, 222.2))
    assert [(v.component, v.index) for v in verdicts] == [("gyro", axis)]
    assert 222.2 < verdicts[0].t <= 227.2 and "unchanged" in verdicts[0].evidence


def test_a_healthy_gyro_is_never_stuck(leo):
    assert run(FrozenDetector("gyro", "gyro_frozen", 3, 1e-9, 2.0, "rad/s"), gyro_samples(leo, 2000.0)) == []


def tachometer_samples(leo, duration_s, stuck=None, stuck_at=math.inf, seed=5):
    tach = leo.sensors.wheel_tachometer
    rng = np.random.default_rng(seed)
    held = None
    for k in range(int(round(duration_s * tach.rate_Hz))):
        t = (k + 1) / tach.rate_Hz
        speeds = np.array([100.0, -40.0, 0.0]) + 5.0 * np.sin(t / 50.0)     # a wheel at rest among them
        measured = np.round((speeds + rng.normal(0.0, tach.noise_rad_per_s, 3)) / tach.quantization_rad_per_s) \
            * tach.quantization_rad_per_s
        if t > stuck_at:
            held = measured[stuck] if held is None else held
            measured[stuck] = held
        yield t, measured


def test_a_stuck_tachometer_is_isolated_within_5_s(leo):
    det = FrozenDetector("wheel_tachometer", "tachometer_frozen", 3, 1e-6, 2.0, "rad/s")
    verdicts = run(det, tachometer_samples(leo, 120.0, stuck=2, stuck_at=100.0))
    assert [(v.component, v.index) for v in verdicts] == [("wheel_tachometer", 2)]
    assert 100.0 < verdicts[0].t <= 105.0


def test_healthy_tachometers_are_never_stuck(leo):
    det = FrozenDetector("wheel_tachometer", "tachometer_frozen", 3, 1e-6, 2.0, "rad/s")
    assert run(det, tachometer_samples(leo, 2000.0)) == []


def magnetometer_samples(leo, duration_s, stuck_at=math.inf, seed=9):
    m = leo.sensors.magnetometer
    rng = np.random.default_rng(seed)
    held = None
    for k in range(int(round(duration_s * m.rate_Hz))):
        t = (k + 1) / m.rate_Hz
        phase = 2 * math.pi * t / 5700.0                              # the field turns once an orbit
        field_nT = 30_000.0 * np.array([math.cos(phase), math.sin(phase), 0.5])
        measured = np.round((field_nT + rng.normal(0.0, m.noise_nT, 3)) / m.quantization_nT) * m.quantization_nT
        if t > stuck_at:
            held = measured if held is None else held
            measured = held
        yield t, measured


def test_a_stuck_magnetometer_is_isolated_within_30_s(leo):
    det = FrozenDetector("magnetometer", "magnetometer_frozen", 3, 0.1, 10.0, "nT", single_unit=True)
    verdicts = run(det, magnetometer_samples(leo, 160.0, stuck_at=130.3))
    assert [(v.component, v.index) for v in verdicts] == [("magnetometer", 0)]    # the unit, once
    assert 130.3 < verdicts[0].t <= 160.3


def test_a_healthy_magnetometer_is_never_stuck(leo):
    det = FrozenDetector("magnetometer", "magnetometer_frozen", 3, 0.1, 10.0, "nT", single_unit=True)
    assert run(det, magnetometer_samples(leo, 2000.0)) == []


def test_the_persistence_counts_from_the_last_change():
    """Independent recomputation: a channel unchanged from t = 1 s is declared at the first sample at
    or after 1 s + persistence."""
    det = FrozenDetector("gyro", "gyro_frozen", 1, 1e-9, 2.0, "rad/s")
    out = run(det, [(0.5, [1.0]), (1.0, [2.0])] + [(1.0 + 0.25 * k, [2.0]) for k in range(1, 12)])
    assert [(v.t, v.since) for v in out] == [(3.0, 1.0)]
