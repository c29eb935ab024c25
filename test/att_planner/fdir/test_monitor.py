"""The fault monitor on the shipped fault table and the LEO observatory: quiet on healthy inputs, a
wheel failure and a tracker jump reported with the table's id and response, the responses following,
a re-admitted tracker leaving the active faults; detectors only where the datasheets have noise."""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import Health
from att_planner.estimation.health import Innovation
from att_planner.fdir import table
from att_planner.fdir.monitor import FaultMonitor
from att_sim.models import rotations as rot
from att_sim.models.scenario import spacecraft_from_model
from att_sim.models.sensor_specs import SensorSpecs, sensors_from_model

ARCSEC = math.pi / 180.0 / 3600.0


def monitor(leo, specs=None) -> FaultMonitor:
    specs = specs if specs is not None else sensors_from_model(leo.sensors)
    return FaultMonitor(table.read(), spacecraft_from_model(leo), specs, "body")


def feed(m: FaultMonitor, t0: float, t1: float, rng, wheel_off=None, jump=None, excluded=()):
    """Healthy 20 Hz wheels, gyro and control errors, 2 Hz magnetometer, 5 Hz trackers from t0 to t1;
    ``wheel_off``: that wheel delivers no torque; ``jump``: st1's innovations carry it."""
    out = []
    R = np.eye(3) * (5.0 * ARCSEC) ** 2
    S_inv = np.linalg.inv(R + np.eye(3) * (2.0 * ARCSEC) ** 2)
    for k in range(int(round(t0 * 20)), int(round(t1 * 20))):
        t = (k + 1) / 20.0
        u = 0.1 * np.sin(t / 20.0 + np.array([0.0, 1.0, 2.0]))
        delivered = u.copy()
        if wheel_off is not None:
            delivered[wheel_off] = 0.0
        m.speeds = m.speeds + delivered / 0.2 / 20.0
        out += m.on_wheels(t, m.speeds + rng.normal(0, 0.01, 3), u)
        out += m.on_gyro(t, 1e-4 + rng.normal(0, 6.5e-6, 3))
        out += m.on_control(t, math.radians(0.01), math.radians(0.001))
        out += m.on_estimate(t, Health.CONVERGED, np.eye(3) * (3 * ARCSEC) ** 2)
        if k % 10 == 0:
            out += m.on_magnetometer(t, 3e-5 * np.array([math.cos(t / 900), math.sin(t / 900), 0.3])
                                     + rng.normal(0, 50e-9, 3))
        if k % 4 == 0:
            batch = []
            error = rng.normal(0, 2.0 * ARCSEC, 3)
            for name in m.trackers:
                y = error + rng.normal(0, 5.0 * ARCSEC, 3) + (jump if name == "st1" and jump is not None else 0.0)
                batch.append(Innovation(t, name, y, float(y @ S_inv @ y), R, name not in excluded))
                m.on_tracker(name, t)
            out += m.on_innovations(batch)
        out += m.tick(t)
    return out


def test_quiet_then_a_wheel_off_then_a_tracker_jump_then_readmitted(leo):
    m = monitor(leo)
    m.speeds = np.array([100.0, -50.0, 30.0])
    rng = np.random.default_rng(3)
    assert feed(m, 0.0, 300.0, rng) == [] and m.active == {}
    reports = feed(m, 300.0, 310.0, rng, wheel_off=1)
    assert [(s.fault_id, s.component, s.index, s.response, s.active) for s in reports] == [
        ("wheel_check", "wheel", 1, "exclude_wheel", True), ("wheel_torque", "wheel", 1, "exclude_wheel", True)]
    assert 300.0 < reports[0].detected_at <= 305.0 and reports[0].frame_id == "body"
    r = m.responses()
    assert r.healthy_wheels == (True, False, True) and not r.wheels_controllable and r.safe_mode
    jump = np.array([60.0, 0.0, 0.0]) * ARCSEC
    reports = feed(m, 310.0, 340.0, rng, jump=jump)
    assert [(s.fault_id, s.index, s.response) for s in reports] == [("tracker_inconsistent", 0, "exclude_sensor")]
    assert m.responses().excluded_sensors == {"st1"}
    reports = feed(m, 340.0, 380.0, rng, excluded=("st1",))
    (back,) = reports
    assert (back.fault_id, back.active, back.detected_at) == ("tracker_inconsistent", False, m.history[2].detected_at)
    assert m.responses().excluded_sensors == frozenset() and set(m.active) == {("wheel_check", 1), ("wheel_torque", 1)}


def test_a_lost_estimate_and_a_silent_tracker(leo):
    m = monitor(leo)
    assert m.on_estimate(0.0, Health.DIVERGED, np.eye(3)) == []
    (lost,) = m.on_estimate(10.0, Health.DIVERGED, np.eye(3))
    assert (lost.fault_id, lost.response, lost.component) == ("estimate_uncertain", "safe_mode", "estimate")
    m.on_tracker("st1", 0.0)
    m.on_tracker("st2", 0.0)
    assert m.tick(5.0) == []
    reports = m.tick(5.2)
    assert [(s.fault_id, s.index) for s in reports] == [("tracker_outage", 0), ("tracker_outage", 1)]
    assert m.responses().excluded_sensors == {"st1", "st2"} and m.responses().safe_mode


def test_noiseless_sensors_are_not_watched_for_a_stuck_reading(leo):
    m = monitor(leo, SensorSpecs())
    assert set(m.detectors) == {"wheels", "attitude", "rate", "estimate"}
    assert m.on_gyro(1.0, np.zeros(3)) == [] and m.on_innovations([]) == [] and m.tick(100.0) == []


def test_every_detector_of_the_table_is_built(leo):
    """Each detector the schema knows has its detector in the monitor (one entry of each kind)."""
    m = monitor(leo)
    built = {type(d).__name__ for ds in m.detectors.values() for _, d in ds}
    assert built == {"WheelTorqueDetector", "FrozenDetector", "InnovationDetector", "BiasJumpDetector",
                     "OutageDetector", "Watchdog", "TrackerStepDetector", "GyroRampDetector",
                     "CoilDetector", "WheelCheckDetector"}
    assert sum(len(ds) for ds in m.detectors.values()) == len(table.read().faults) == len(table.DETECTORS)


def test_the_trackers_against_the_gyro_and_the_coils_are_fed_by_the_monitor(leo):
    """A gyro bias step of 0.01 deg/s about body y with one tracker valid: the shipped table's
    gyro_rate_step reports it (safe mode) within 3 s; the commanded dipoles reach the coil detector."""
    m = monitor(leo)
    st2 = m.detectors["tracker_gyro"][0][1].residuals.specs["st2"]
    rng = np.random.default_rng(4)
    q, w, reports = np.array([0.0, 0.0, 0.0, 1.0]), np.array([0.0, 0.002, 0.0]), []
    for k in range(1, 801):                               # 40 s at 20 Hz, the step at 30 s
        t = 0.05 * k
        q = rot.propagate_constant_rate(q, w, 0.05)
        step = np.array([0.0, math.radians(0.01), 0.0]) if t >= 30.0 else 0.0
        reports += m.on_gyro(t, w + step + rng.normal(0.0, math.radians(0.005) / 60.0 * math.sqrt(20.0), 3))
        reports += m.on_dipole(t, [1.0, 2.0, 3.0])
        if k % 4 == 0:
            noise = rng.normal(size=3) * np.sqrt(np.diag(st2.covariance))
            reports += m.on_star_tracker(t, "st1", q, False)
            reports += m.on_star_tracker(t, "st2", rot.multiply(rot.multiply(q, st2.mounting), rot.exp_map(noise)),
                                         True)
    assert [(r.fault_id, r.component, r.index, r.response) for r in reports] == [
        ("gyro_rate_step", "gyro", 1, "safe_mode")]
    assert 30.0 < reports[0].detected_at <= 33.0
    (coils,) = [d for _, d in m.detectors["coils"]]
    assert coils.dipole.tolist() == [1.0, 2.0, 3.0]
