"""The fault monitor (no ROS): the table's detectors fed each step, the active faults and their reports.

:class:`FaultMonitor` builds one detector per entry of the fault table (:mod:`.table`) for the
spacecraft's wheels and sensors, and takes what a node or the in-process closed loop has each step:
the tachometer speeds with the commanded motor torques, the gyro, the magnetometer, the trackers'
innovations (:meth:`att_planner.estimation.estimator.Estimator.take_innovations`) and arrivals, the
controller's attitude and rate errors and the estimate's health. Each call returns the
:class:`~.status.FaultStatus` reports it made (a fault declared, or cleared where its detector
clears); :attr:`FaultMonitor.active` holds the faults in force and :meth:`FaultMonitor.responses`
what to fly on (:func:`.responses.responses`). A frozen-reading detector watches only a sensor with
noise in its datasheet (a noiseless one repeats itself legitimately).
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import FaultStatus, Health
from att_planner.estimation.health import Innovation
from att_planner.fdir import table as tables
from att_planner.fdir.bias import BiasJumpDetector
from att_planner.fdir.coils import CoilDetector, Readback, momentum_noise
from att_planner.fdir.frozen import FrozenDetector
from att_planner.fdir.innovations import InnovationDetector
from att_planner.fdir.outage import OutageDetector
from att_planner.fdir.responses import Responses, responses
from att_planner.fdir.status import Verdict
from att_planner.fdir.tracker_gyro import GyroRampDetector, Residuals, TrackerStepDetector
from att_planner.fdir.watchdogs import Watchdog
from att_planner.fdir.wheel_check import WheelCheckDetector
from att_planner.fdir.wheel_health import WheelTorqueDetector
from att_sim.models.dynamics import Spacecraft
from att_sim.models.sensor_specs import SensorSpecs

KNOWN = (Health.CONVERGED, Health.PROPAGATING)        # an estimate with an attitude


class FaultMonitor:
    """The detectors of a fault table on one spacecraft (module docstring)."""

    def __init__(self, table: tables.FaultTable, spacecraft: Spacecraft, specs: SensorSpecs, frame_id: str = ""):
        self.table, self.spacecraft, self.frame_id = table, spacecraft, frame_id
        self.trackers = [s.name for s in specs.star_trackers]
        self.active: dict[tuple[str, int], FaultStatus] = {}
        self.history: list[FaultStatus] = []          # every report, in order
        self.detectors: dict[str, list] = {}          # input kind -> [(fault id, detector)]
        self._residuals: dict[tuple, Residuals] = {}   # (window, onset, discontinuity) -> residuals
        for fault_id, entry in table.faults.items():
            kind, detector = self._detector(entry, spacecraft, specs)
            if detector is not None:
                self.detectors.setdefault(kind, []).append((fault_id, detector))

    def _detector(self, e, sc: Spacecraft, specs: SensorSpecs):
        """(input kind, detector) of table entry ``e`` (detector None: nothing to watch on this spacecraft)."""
        n = sc.n_wheels
        if isinstance(e, tables.WheelTorque):
            return "wheels", (WheelTorqueDetector(n, sc.wheel_inertia, e.threshold_Nm, e.persistence_s, e.window_s,
                                                  sc.wheel_axes, e.drive_gain_tolerance,
                                                  e.wheel_inertia_tolerance)
                              if n and sc.wheel_inertia > 0 else None)
        if isinstance(e, tables.WheelCheck):
            tach = specs.tachometer
            if not (n and sc.wheel_inertia > 0 and tach is not None and tach.noise > 0):
                return "wheels", None
            sigma = math.hypot(tach.noise, tach.quantization / math.sqrt(12.0))
            return "wheels", WheelCheckDetector(n, sc.wheel_inertia, sigma, e.threshold, e.friction_threshold, e.z,
                                                e.window_s, e.persistence_s, sc.wheel_axes, e.drive_gain_tolerance,
                                                e.wheel_inertia_tolerance)
        if isinstance(e, tables.TachometerFrozen):
            noisy = specs.tachometer is not None and specs.tachometer.noise > 0
            return "tachometer", (FrozenDetector("wheel_tachometer", e.detector, n, e.threshold_rad_s, e.persistence_s,
                                                 "rad/s") if n and noisy else None)
        if isinstance(e, tables.GyroFrozen):
            noisy = specs.gyro is not None and specs.gyro.arw > 0
            return "gyro", (FrozenDetector("gyro", e.detector, 3, e.threshold_rad_s, e.persistence_s, "rad/s")
                            if noisy else None)
        if isinstance(e, tables.MagnetometerFrozen):
            noisy = specs.magnetometer is not None and specs.magnetometer.noise > 0
            return "magnetometer", (FrozenDetector("magnetometer", e.detector, 3, e.threshold_nT, e.persistence_s,
                                                   "nT", single_unit=True) if noisy else None)
        if isinstance(e, tables.TrackerInnovation):
            return "innovations", (InnovationDetector(self.trackers, e.threshold, e.persistence_s, e.readmit_s)
                                   if self.trackers else None)
        if isinstance(e, tables.GyroInnovation):
            return "innovations", (InnovationDetector(self.trackers, gyro_threshold=e.threshold,
                                                      gyro_persistence_s=e.persistence_s)
                                   if len(self.trackers) > 1 else None)
        if isinstance(e, tables.GyroBiasJump):
            return "bias", BiasJumpDetector(e.threshold_deg_h, e.window_s, e.persistence_s) if specs.gyro else None
        if isinstance(e, tables.TrackerStep | tables.GyroRamp):
            if not (specs.star_trackers and specs.gyro):
                return "tracker_gyro", None
            key = (e.window_s, e.onset_s, e.discontinuity_deg)
            if key not in self._residuals:
                self._residuals[key] = Residuals(specs.star_trackers, e.window_s, e.onset_s,
                                                 math.radians(e.discontinuity_deg))
            kind = TrackerStepDetector if isinstance(e, tables.TrackerStep) else GyroRampDetector
            return "tracker_gyro", kind(self._residuals[key], e.threshold, e.persistence_s)
        if isinstance(e, tables.CoilTorque):
            if specs.gyro is None or specs.gyro.arw <= 0 or specs.tachometer is None and n:
                return "coils", None
            tacho = specs.tachometer.noise if n else 0.0
            sigma_H = momentum_noise(sc.inertia, sc.wheel_axes, sc.wheel_inertia, specs.gyro.arw, specs.gyro.rate,
                                     tacho)
            mag = specs.magnetometer
            readback = None
            if e.check is not None and mag is not None and mag.dipole_coupling > 0 and mag.noise > 0:
                readback = Readback(mag.dipole_coupling, math.hypot(mag.noise, mag.quantization / math.sqrt(12.0)),
                                    e.threshold, e.check.window_s, e.persistence_s)
            return "coils", CoilDetector(sc.inertia, sc.wheel_axes, sc.wheel_inertia, sigma_H, e.threshold, e.window_s,
                                         e.persistence_s, readback)
        if isinstance(e, tables.TrackerOutage):
            return "tick", OutageDetector(self.trackers, e.threshold_s, e.persistence_s) if self.trackers else None
        if isinstance(e, tables.AttitudeError):
            return "attitude", Watchdog("attitude", e.detector, e.threshold_deg, e.persistence_s, "deg",
                                        "attitude error")
        if isinstance(e, tables.RateError):
            return "rate", Watchdog("rate", e.detector, e.threshold_deg_s, e.persistence_s, "deg/s", "rate error")
        if isinstance(e, tables.EstimateUncertain):
            return "estimate", Watchdog("estimate", e.detector, e.threshold_deg, e.persistence_s, "deg",
                                        "attitude 3 sigma of the estimate")
        raise TypeError(f"a detector of the fault table ({', '.join(tables.DETECTORS)}), got {type(e).__name__}")

    # -- inputs -----------------------------------------------------------------------------------
    def on_wheels(self, t: float, speeds_rad_s, torque_Nm, friction_Nm=None, omega_BN_B=None) -> list[FaultStatus]:
        """A tachometer sample (speeds relative to the body) and the motor torques commanded over the
        interval it ends, the drive friction expected over it, the body rate. A wheel whose tachometer
        is declared frozen is not judged on its speeds."""
        unread = {s.index for s in self.active.values() if s.component == "wheel_tachometer"}
        for _, d in self.detectors.get("wheels", []):
            d.unread = unread
        out = self._run("wheels", lambda d: d.update(t, speeds_rad_s, torque_Nm, friction_Nm, omega_BN_B))
        out += self._run("coils", lambda d: d.on_wheels(t, speeds_rad_s))
        return out + self._run("tachometer", lambda d: d.update(t, speeds_rad_s))

    def on_gyro(self, t: float, omega_BN_B_measured) -> list[FaultStatus]:
        out = self._run("gyro", lambda d: d.update(t, omega_BN_B_measured))
        out += self._run("coils", lambda d: d.on_gyro(t, omega_BN_B_measured))
        return out + self._run("tracker_gyro", lambda d: d.on_gyro(t, omega_BN_B_measured))

    def on_magnetometer(self, t: float, field_B_T) -> list[FaultStatus]:
        out = self._run("coils", lambda d: d.on_field(t, field_B_T))
        return out + self._run("magnetometer", lambda d: d.update(t, np.asarray(field_B_T, float) * 1e9))

    def on_dipole(self, t: float, dipole_Am2) -> list[FaultStatus]:
        """The magnetorquer dipole commanded (A m², body axes; empty: none) at ``t``, until the next."""
        d = np.asarray(dipole_Am2, float)
        return self._run("coils", lambda det: det.on_dipole(t, d if d.shape == (3,) else np.zeros(3)))

    def on_innovations(self, innovations: list[Innovation]) -> list[FaultStatus]:
        return self._run("innovations", lambda d: d.update(innovations))

    def on_tracker(self, name: str, t: float) -> None:
        """A measurement of tracker ``name`` (valid or not) taken at ``t`` arrived."""
        for _, d in self.detectors.get("tick", []):
            d.heard_from(name, t)

    def on_star_tracker(self, t: float, name: str, q_SN, valid: bool) -> list[FaultStatus]:
        """A measurement of tracker ``name`` taken at ``t``: its sensor attitude (sensor-to-inertial) and
        whether it is valid, judged against the gyro's propagation (:mod:`.tracker_gyro`)."""
        gyro_failed = any(s.component == "gyro" for s in self.active.values())
        for _, d in self.detectors.get("tracker_gyro", []):
            if isinstance(d, TrackerStepDetector):
                d.gyro_failed = gyro_failed
        return self._run("tracker_gyro", lambda d: d.on_tracker(t, name, q_SN, valid))

    def tick(self, t: float) -> list[FaultStatus]:
        """The time-driven detectors (tracker silence) at sim time ``t``."""
        return self._run("tick", lambda d: d.update(t))

    def on_control(self, t: float, attitude_error_rad: float, rate_error_rad_s: float) -> list[FaultStatus]:
        """The controller's attitude and rate errors from its reference (nan: no reference: not judged)."""
        out = []
        if not math.isnan(attitude_error_rad):
            out += self._run("attitude", lambda d: d.update(t, math.degrees(attitude_error_rad)))
        if not math.isnan(rate_error_rad_s):
            out += self._run("rate", lambda d: d.update(t, math.degrees(rate_error_rad_s)))
        return out

    def on_estimate(self, t: float, health: int, attitude_covariance, gyro_bias=None,
                    bias_covariance=None) -> list[FaultStatus]:
        """The estimate's health, attitude covariance (rad²: its 3σ, infinite without an attitude),
        gyro bias estimate (rad/s; None: not judged) and its covariance ((rad/s)²)."""
        sigma3, out = math.inf, []
        if health in KNOWN:
            sigma3 = math.degrees(3.0 * math.sqrt(max(float(np.linalg.eigvalsh(attitude_covariance).max()), 0.0)))
            if gyro_bias is not None:
                out += self._run("bias", lambda d: d.update(t, gyro_bias, bias_covariance))
        return out + self._run("estimate", lambda d: d.update(t, sigma3))

    # -- state ------------------------------------------------------------------------------------
    def responses(self) -> Responses:
        """What to fly on, from the active faults (:func:`.responses.responses`)."""
        return responses(self.active.values(), self.spacecraft.wheel_axes, self.trackers)

    def _run(self, kind: str, call) -> list[FaultStatus]:
        out = []
        for fault_id, detector in self.detectors.get(kind, []):
            out += [self._report(fault_id, v) for v in call(detector)]
        return out

    def _report(self, fault_id: str, v: Verdict) -> FaultStatus:
        key = (fault_id, v.index)
        declared = self.active.get(key)
        detected_at = declared.detected_at if declared is not None and not v.active else v.t
        status = FaultStatus(v.t, fault_id, v.component, v.index, v.detector, v.evidence,
                             self.table.faults[fault_id].response, v.active, detected_at, self.frame_id)
        if v.active:
            self.active[key] = status
        else:
            self.active.pop(key, None)
        self.history.append(status)
        return status
