"""The active wheel check: the null vector of the leo_pyramid wheels (``G n = 0``), none with three
healthy wheels; under the shipped table's null-space excitation, in a quiet hold (wheels near rest, a
zero-mean white net torque of 2.45e-3 N m rms), a seized wheel, a wheel off and friction ×5 are isolated
to the right wheel within 5 s, and healthy wheels at the worst drive-gain (±10 %) and inertia (±5 %)
draws are never declared over long runs; the table refuses thresholds a healthy wheel could cross."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from att_planner.control.wheel_check import WheelCheck, excite, null_vector
from att_planner.fdir import table
from att_planner.fdir.wheel_check import WheelCheckDetector
from att_sim.models import config_files
from att_sim.models.config_schema import SpacecraftFile

DT = 0.05
PYRAMID_FILE = Path(__file__).resolve().parents[3] / "config" / "spacecraft" / "leo_pyramid.yaml"


@pytest.fixture(scope="module")
def pyramid() -> SpacecraftFile:
    return config_files.load_file(PYRAMID_FILE, SpacecraftFile).model


def axes(sc) -> np.ndarray:
    return np.asarray(sc.wheel_axes, float).reshape(-1, 3).T


def friction(sc, speeds, k=1.0):
    d = sc.actuators.wheels
    return k * (d.coulomb_friction_Nm * np.tanh(speeds / d.friction_speed_rad_s) + d.viscous_friction_Nm_s * speeds)


def test_the_pyramid_null_vector(pyramid):
    G = axes(pyramid)
    n = null_vector(G)
    assert np.allclose(G @ n, 0.0, atol=1e-12) and math.isclose(np.linalg.norm(n), 1.0)
    assert np.allclose(np.abs(n), 0.5)                      # every wheel excited alike
    for failed in range(4):
        healthy = [i != failed for i in range(4)]
        assert null_vector(G, healthy) is None                # three wheels: no null space
        assert WheelCheck(0.1, 4.0).torques(1.0, G, healthy) is None
    assert null_vector(G[:, :3]) is None


def test_the_square_wave_is_zero_mean_and_scaled_to_the_headroom():
    check = WheelCheck(0.1, 4.0)
    s = np.array([check.sign(t) for t in np.arange(DT / 2, 40.0, DT)])
    assert abs(s.mean()) < 1e-9 and set(s) == {-1.0, 1.0}
    n = np.array([0.5, -0.5, 0.5, -0.5])
    u = excite([0.28, 0.0, 0.0, 0.0], 0.1 * n, 0.3)           # 0.02 N m of headroom on wheel 0
    assert np.allclose(u, [0.3, -0.02, 0.02, -0.02])          # the whole excitation scaled, kept in the null space


def hold(sc, duration_s, fault=None, fault_at=math.inf, scale=(1.0, 1.0, 1.0, 1.0), inertia_scale=1.0, seed=3,
         excitation=True):
    """The leo_pyramid wheels near rest in a quiet hold: each commanded the expected friction, a white
    zero-mean net torque of 2.45e-3 N m rms and the shipped excitation; dispersed drives (torque gains
    ``scale``, spin inertia ``inertia_scale`` × the nominal), the tachometer's noise and quantisation;
    wheel 1 faulted at ``fault_at``. The verdicts of the shipped table's wheel_check entry."""
    rng = np.random.default_rng(seed)
    d, tach, I_w = sc.actuators.wheels, sc.sensors.wheel_tachometer, sc.wheel_inertia_kg_m2
    G = axes(sc)
    e = table.read().faults["wheel_check"]
    check = WheelCheck(e.amplitude_Nm, e.period_s)
    sigma = math.hypot(tach.noise_rad_per_s, tach.quantization_rad_per_s / math.sqrt(12.0))
    det = WheelCheckDetector(4, I_w, sigma, e.threshold, e.friction_threshold, e.z, e.window_s, e.persistence_s,
                             None, e.drive_gain_tolerance, e.wheel_inertia_tolerance)
    speeds, scale = np.array([0.05, -0.03, 0.08, -0.02]), np.asarray(scale, float)
    verdicts, u, f = [], np.zeros(4), np.zeros(4)
    for k in range(int(round(duration_s / DT))):
        t = k * DT
        measured = np.round((speeds + rng.normal(0.0, tach.noise_rad_per_s, 4)) / tach.quantization_rad_per_s) \
            * tach.quantization_rad_per_s
        verdicts += det.update(t, measured, u, f)        # the sample ends the interval of the last command
        f = friction(sc, measured)
        u = f + rng.normal(0.0, 2.45e-3, 4)
        if excitation:
            u = excite(u, check.torques(t, G), sc.wheel_torque_max_Nm)
        applied = np.round((u + rng.normal(0.0, d.torque_noise_Nm, 4)) / d.torque_quantization_Nm) \
            * d.torque_quantization_Nm * scale
        drag = friction(sc, speeds)
        faulty = t >= fault_at
        if faulty and fault == "off":
            applied[1] = 0.0
        if faulty and fault == "friction":
            drag[1] = friction(sc, speeds[1], k=5.0)
        speeds = speeds + (applied - drag) / (I_w * inertia_scale) * DT
        if faulty and fault == "seized":
            speeds[1] = 0.0
    return verdicts


@pytest.mark.parametrize("fault", ["seized", "off", "friction"])
@pytest.mark.parametrize("fault_at", [60.0, 81.3])
def test_a_wheel_fault_in_a_quiet_hold_is_isolated_within_5_s(pyramid, fault, fault_at):
    verdicts = hold(pyramid, fault_at + 8.0, fault, fault_at)
    assert verdicts, f"{fault} at {fault_at} s not detected"
    first = verdicts[0]
    assert (first.component, first.index, first.detector) == ("wheel", 1, "wheel_check"), first
    assert [v.index for v in verdicts] == [1]
    assert fault_at < first.t <= fault_at + 5.0, first


def test_without_the_excitation_nothing_is_judged(pyramid):
    """The quiet hold alone leaves sigma_theta far above the gate: a seized wheel is not declared (nor any other)."""
    assert hold(pyramid, 60.0, "seized", 20.0, excitation=False) == []


@pytest.mark.parametrize("scale,inertia_scale", [((0.9, 1.1, 0.9, 1.1), 1.05), ((1.1, 0.9, 1.1, 0.9), 0.95),
                                                 ((0.9, 0.9, 0.9, 0.9), 1.05), ((1.1, 1.1, 1.1, 1.1), 0.95)])
def test_healthy_wheels_at_the_worst_tolerances_are_never_declared(pyramid, scale, inertia_scale):
    assert hold(pyramid, 600.0, scale=scale, inertia_scale=inertia_scale, seed=11) == []


def test_the_table_refuses_thresholds_a_healthy_wheel_crosses():
    base = dict(detector="wheel_check", amplitude_Nm=0.1, period_s=4.0, window_s=4.0, threshold=0.43,
                friction_threshold=2.5, z=5.0, drive_gain_tolerance=0.1, wheel_inertia_tolerance=0.05,
                persistence_s=0.5, response="exclude_wheel")
    table.FaultTable.model_validate({"faults": {"w": base}})
    for bad, why in ((dict(threshold=0.9), "threshold below"),
                     (dict(friction_threshold=1.02), "friction_threshold above"),
                     (dict(window_s=2.0), "window_s at least period_s")):
        with pytest.raises(ValueError, match=why):
            table.FaultTable.model_validate({"faults": {"w": {**base, **bad}}})
    with pytest.raises(ValueError):
        table.FaultTable.model_validate({"faults": {"w": {**base, "response": "exclude_sensor"}}})


def test_the_table_refuses_two_entries_that_disagree_on_the_wheels_tolerances():
    shipped = table.read().model_dump()["faults"]
    table.FaultTable.model_validate({"faults": shipped})
    for field in ("drive_gain_tolerance", "wheel_inertia_tolerance"):
        edited = {k: dict(v) for k, v in shipped.items()}
        edited["wheel_check"][field] = edited["wheel_torque"][field] / 2
        with pytest.raises(ValueError, match=f"{field} differs between entries .*wheel_torque.*wheel_check"):
            table.FaultTable.model_validate({"faults": edited})
