"""Wheel health: a seized wheel, a wheel off, friction ×k and a stuck tachometer each isolated to the
right wheel within 5 s of sim time, on the LEO observatory's tachometer noise and drive imperfections;
no verdict in 2000 s of fault-free noise."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from att_planner.fdir import table
from att_planner.fdir.wheel_health import WheelTorqueDetector
from att_sim.truth import dispersions as disp

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


# -- drive gain and inertia tolerances ----------------------------------------------------------------------------
CAMPAIGNS = sorted((Path(__file__).resolve().parents[3] / "campaigns").glob("*.yaml"))


def worst(d) -> float:
    """The largest magnitude a campaign's distribution can draw (a truncated normal's bound, a uniform's end)."""
    return max(abs(d.a), abs(d.b)) if d.kind == "uniform" else abs(d.a) + d.truncate * d.b


@pytest.mark.parametrize("path", CAMPAIGNS, ids=lambda p: p.stem)
def test_the_shipped_tolerances_bound_every_campaigns_wheel_dispersions(path):
    """One definition per fact: the flight's declared tolerances cover what a campaign may draw."""
    c = disp.load_campaign(path)
    e = table.read().faults["wheel_torque"]
    for name, tolerance in (("wheel_torque_scale", e.drive_gain_tolerance),
                            ("wheel_inertia_scale", e.wheel_inertia_tolerance)):
        if name in c.dispersions:
            assert worst(c.dispersions[name]) <= tolerance + 1e-12, (path.name, name)


def hold(leo, duration_s, fault=None, fault_at=math.inf, scale=(1.0, 1.0, 1.0, 1.0), inertia_scale=1.0,
         net_Nm=0.002, speeds=(1.3, 0.4, -0.8, 0.2), seed=3):
    """A four-wheel pyramid holding its attitude: each wheel commanded the friction it is expected to
    have plus a small net torque (the controller's share of the disturbances), on dispersed drives
    (torque gains ``scale``, spin inertia ``inertia_scale`` × the nominal); the detector on the shipped
    table (its tolerances). Wheel 1 faulted. The verdicts."""
    rng = np.random.default_rng(seed)
    d, tach, I_w = leo.actuators.wheels, leo.sensors.wheel_tachometer, leo.wheel_inertia_kg_m2
    e = table.read().faults["wheel_torque"]
    det = WheelTorqueDetector(4, I_w, e.threshold_Nm, e.persistence_s, e.window_s, PYRAMID, e.drive_gain_tolerance,
                              e.wheel_inertia_tolerance)
    speeds, scale = np.array(speeds, float), np.asarray(scale, float)
    net = net_Nm * np.array([1.0, 1.0, -0.5, 0.7])
    verdicts = []
    for k in range(int(round(duration_s / DT))):
        t = (k + 1) * DT
        measured = np.round((speeds + rng.normal(0.0, tach.noise_rad_per_s, 4)) / tach.quantization_rad_per_s) \
            * tach.quantization_rad_per_s
        u = friction(leo, measured) + net
        applied = np.round((u + rng.normal(0.0, d.torque_noise_Nm, 4)) / d.torque_quantization_Nm) \
            * d.torque_quantization_Nm * scale
        accel = (applied - friction(leo, speeds)) / (I_w * inertia_scale)
        faulty = t > fault_at
        if faulty and fault == "seized":
            accel[1] = 0.0
        if faulty and fault == "off":
            accel[1] = -friction(leo, speeds[1]) / (I_w * inertia_scale)
        if faulty and fault == "friction":
            accel[1] = (applied[1] - 5.0 * friction(leo, speeds[1])) / (I_w * inertia_scale)
        speeds = speeds + accel * DT
        verdicts += det.update(t, measured, u, friction(leo, measured), np.zeros(3))
    return verdicts


CORNERS = [((1.1, 0.9, 1.1, 0.9), 0.95), ((0.9, 1.1, 0.9, 1.1), 1.05), ((1.1, 1.1, 0.9, 0.9), 1.05),
           ((0.9, 0.9, 1.1, 1.1), 0.95)]


@pytest.mark.parametrize("scale, inertia_scale", CORNERS)
def test_dispersed_drives_at_their_tolerances_raise_no_verdict(leo, scale, inertia_scale):
    assert hold(leo, 60.0, scale=scale, inertia_scale=inertia_scale) == []


@pytest.mark.parametrize("scale, inertia_scale", CORNERS)
def test_dispersed_drives_on_a_slew_raise_no_verdict(leo, scale, inertia_scale):
    """The tolerances' share on 0.12 N m commands (24 times the absolute threshold) keeps a wheel
    within its gain quiet."""
    assert hold(leo, 60.0, scale=scale, inertia_scale=inertia_scale, net_Nm=0.12) == []


@pytest.mark.parametrize("fault", ["seized", "off", "friction"])
@pytest.mark.parametrize("scale, inertia_scale", [((1.0,) * 4, 1.0)] + CORNERS[:2])
def test_a_wheel_fault_in_a_hold_is_isolated_within_5_s(leo, fault, scale, inertia_scale):
    """A seized wheel asked 0.003 N m net beyond its friction shows ``−(u − f)``, above the bound
    ``0.0018 + 0.105 × 0.008 + 0.053 × 0.003`` N m once the 2.5 s windows see most of it: isolated in
    3.9–4.2 s on these drives; off in 2.3–2.6 s, friction ×5 in 1.5–2.0 s."""
    verdicts = hold(leo, 26.0, fault, 20.0, scale=scale, inertia_scale=inertia_scale, net_Nm=0.003)
    assert verdicts and [v.index for v in verdicts] == [1], verdicts
    assert 20.0 < verdicts[0].t <= 25.0, verdicts[0]


@pytest.mark.parametrize("net_Nm", [0.0, 0.002])
def test_a_seized_wheel_asked_less_than_the_bound_is_not_seen(leo, net_Nm):
    """The limit: a seized wheel holds its spin and feels no friction, so it misses only the net
    torque ``u − f`` it is asked. Asked none, it does what a healthy wheel does; asked 0.002 N m (the
    leo_pyramid inertial hold's first seconds) it stays under the bound ``0.0018 + 0.105 × 0.007 + 0.053 × 0.002``
    N m, and is seen only once the controller asks more."""
    assert hold(leo, 60.0, "seized", 20.0, net_Nm=net_Nm) == []


def test_the_bound_covers_a_healthy_wheel_at_its_tolerances_and_not_a_faulty_one():
    """Independent recomputation on noiseless speeds: a wheel of gain s and inertia I_w/ρ asked a
    constant u against friction f shows τ_res = ρ(s − 1)u + (ρ − 1)(u − f), within
    0 + a/(1 − b)|u| + b/(1 − b)|u − f|; seized, −(u − f), beyond it."""
    I_w, u, f, a, b = 0.2, 0.05, 0.01, 0.1, 0.05
    for s, rho, seized in ((1.1, 1 / 0.95, False), (0.9, 1 / 1.05, False), (1.0, 1.0, True)):
        det = WheelTorqueDetector(1, I_w, threshold_Nm=1e-9, persistence_s=0.0, window_s=1.0,
                                  drive_gain_tolerance=a, wheel_inertia_tolerance=b)
        speed, verdicts = 10.0, []
        for k in range(80):
            t = (k + 1) * 0.05
            speed += 0.0 if seized else rho * (s * u - f) / I_w * 0.05
            verdicts += det.update(t, [speed], [u], [f])
        tau, motor, net = det.window_means(4.0)
        expected = -(u - f) if seized else rho * (s - 1.0) * u + (rho - 1.0) * (u - f)
        assert tau[0] == pytest.approx(expected, rel=1e-9)
        assert (motor[0], net[0]) == pytest.approx((u, u - f), rel=1e-9)
        assert det.bound(motor, net)[0] == pytest.approx(1e-9 + a / (1 - b) * u + b / (1 - b) * (u - f), rel=1e-9)
        assert bool(verdicts) is seized


def test_tolerances_that_would_hide_a_dead_wheel_are_refused():
    with pytest.raises(ValueError, match=r"drive_gain_tolerance and wheel_inertia_tolerance in \[0, 1\)"):
        WheelTorqueDetector(3, 0.2, 0.01, 0.5, 1.0, drive_gain_tolerance=1.0)
    with pytest.raises(ValueError, match=r"in \[0, 1\)"):
        WheelTorqueDetector(3, 0.2, 0.01, 0.5, 1.0, wheel_inertia_tolerance=-0.1)


def test_a_wheel_whose_tachometer_is_declared_frozen_is_not_judged(leo):
    """A stuck tachometer makes its wheel's residual the commanded acceleration; once the reading is
    declared frozen (the monitor marks it unread) that residual is no evidence against the wheel."""
    e = table.read().faults["wheel_torque"]
    det = WheelTorqueDetector(1, 0.2, e.threshold_Nm, e.persistence_s, e.window_s, drive_gain_tolerance=0.1,
                              wheel_inertia_tolerance=0.05)
    det.unread = {0}
    verdicts = []
    for k in range(200):
        verdicts += det.update((k + 1) * DT, [50.0], [0.05])       # frozen at 50 rad/s, 0.05 N m asked
    assert verdicts == [] and abs(det.residual_torque(200 * DT)[0]) == pytest.approx(0.05, rel=1e-6)
    det.unread = set()
    assert [v.index for k in range(200, 220) for v in det.update((k + 1) * DT, [50.0], [0.05])] == [0]


def _old_window_means(det, samples, t):
    """The window means as the detector computed them before its sample buffer (arrays rebuilt from a
    list of (t, r, asked) each sample): the reference :meth:`window_means` must equal."""
    if len(samples) < 4 or samples[0][0] > t - 2.0 * det.window + 1e-9:
        return None
    times = np.array([s[0] for s in samples])
    now = times > t - det.window + 1e-9
    if now.all() or not now.any():
        return None
    span = times[now].mean() - times[~now].mean()
    values = np.array([s[1] for s in samples])
    asked = np.array([s[2] for s in samples])
    motor, net = (asked[now].mean(axis=0) - asked[~now].mean(axis=0)) / span
    return det.inertia * (values[now].mean(axis=0) - values[~now].mean(axis=0)) / span, motor, net


def test_the_sample_buffer_gives_the_old_window_means_exactly():
    """Over 1200 samples at 20 Hz (the buffer moved to its start and grown) the window means equal, bit
    for bit, the old formula on the same samples kept in a list."""
    rng = np.random.default_rng(3)
    det = WheelTorqueDetector(4, 0.2, 1.0, 0.25, 2.5, wheel_axes=PYRAMID, drive_gain_tolerance=0.1,
                              wheel_inertia_tolerance=0.05)
    det.samples = type(det.samples)(4, capacity=8)
    kept, compared = [], 0
    for k in range(1200):
        t = (k + 1) * DT
        det.update(t, rng.normal(0.0, 50.0, 4), rng.normal(0.0, 0.1, 4), rng.normal(0.0, 0.005, 4),
                   rng.normal(0.0, 1e-3, 3))
        times, values, asked = det.samples.views()
        kept = [s for s in kept + [(times[-1], values[-1].copy(), asked[-1].copy())]
                if not s[0] < t - 2.0 * det.window - 1e-9]           # the old deque's popleft rule
        assert [s[0] for s in kept] == list(times)
        new, old = det.window_means(t), _old_window_means(det, kept, t)
        assert (new is None) == (old is None)
        if new is not None:
            compared += 1
            for a, b in zip(new, old):
                assert np.array_equal(a, b)
    assert compared > 1000 and len(det.samples.t) > 8


def test_a_seized_wheel_in_a_quiet_hold_is_not_observable_within_5_s(leo):
    """The limit the module docstring states, recomputed: a wheel near rest asked the nadir hold's
    zero-mean white net torque (2.45e-3 N m rms at 20 Hz) for 5 s. The least-squares fraction of it
    delivered (a line and the commanded speed change fitted to the tachometer's noisy, quantised
    speeds) has a standard deviation the healthy floor (1 − a)/(1 + b) does not clear even 3 times
    over, so no test can isolate the seized wheel there in 5 s; the torque test stays silent."""
    rng = np.random.default_rng(5)
    tach, I_w = leo.sensors.wheel_tachometer, leo.wheel_inertia_kg_m2
    e = table.read().faults["wheel_torque"]
    n = int(round(5.0 / DT))
    C = np.cumsum(rng.normal(0.0, 2.45e-3, n) / I_w * DT)          # the commanded speed change, rad/s
    X = np.c_[np.ones(n), np.arange(n) * DT, C - C.mean()]
    sigma_v = math.hypot(tach.noise_rad_per_s, tach.quantization_rad_per_s / math.sqrt(12.0))
    sigma_theta = sigma_v * math.sqrt(np.linalg.inv(X.T @ X)[2, 2])
    floor = (1.0 - e.drive_gain_tolerance) / (1.0 + e.wheel_inertia_tolerance)
    assert sigma_theta > floor / 3.0, sigma_theta
    det = WheelTorqueDetector(1, I_w, e.threshold_Nm, e.persistence_s, e.window_s,
                              drive_gain_tolerance=e.drive_gain_tolerance,
                              wheel_inertia_tolerance=e.wheel_inertia_tolerance)
    verdicts, u = [], rng.normal(0.0, 2.45e-3, 400)
    for k in range(400):                                            # seized from 10 s: its spin held
        t = (k + 1) * DT
        speed = 0.05 + (np.sum(u[:k + 1]) / I_w * DT if t <= 10.0 else np.sum(u[:200]) / I_w * DT)
        measured = np.round((speed + rng.normal(0.0, tach.noise_rad_per_s)) / tach.quantization_rad_per_s) \
            * tach.quantization_rad_per_s
        verdicts += det.update(t, [measured], [u[k]], [0.0])
    assert verdicts == []
