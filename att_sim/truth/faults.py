"""Hardware faults of the truth simulation, applied inside the actuator and sensor models.

Each run holds its faults (:class:`Faults`): the ones scheduled and the state of the ones started.
A fault starts at the first step (or sensor sample) at or after its onset ``t_s``
(:meth:`Faults.start_due`) and stands for the rest of the run. The models, ``i`` the faulted
unit (see :mod:`att_sim.models.config_faults` for the catalogue):

* wheel ``seized``: no net torque on the wheel, ``u_net,i = 0`` (motor and friction), so its
  inertial spin ``Ω_i`` stays at its value and the body feels no reaction torque from it;
* wheel ``off``: no motor torque, ``u_i = 0``; friction still acts, ``u_net,i = −f(ν_i)``, and the
  wheel spins down (with ideal motors, which have no friction, its speed stays);
* wheel ``friction``: ``u_net,i = env(u_i, ν_i) − k f(ν_i)``, the drive's friction ``f`` (Coulomb and
  viscous, :func:`att_sim.models.actuator_specs.friction_torque`) times ``k = factor``;
* wheel ``tachometer_stuck``: the tachometer reads ``ν̃_i(t) = ν̃_i(t_f)``, its last reading before the onset;
* star tracker ``outage``: no measurement (its noise is still drawn: the run's other streams stay);
* star tracker ``bias_jump``: the measured sensor attitude ``q̃_SN ⊗ exp(b)``, ``b = bias_rad`` (rad,
  sensor axes) added to the noise;
* gyro ``axis_stuck``: axis ``i`` outputs its last reading; gyro ``bias_step``: ``ω̃_i + Δb`` with
  ``Δb = bias_rad_s`` from the onset (the evaluation truth's bias includes it);
* magnetometer ``stuck``: the last reading (field and stamp of the new sample);
* magnetorquer ``coil_open``: coil ``i`` produces no dipole, ``m_i = 0`` before the coils' transfer.

The actuator faults act on rows of runs (the :class:`att_sim.truth.batch.SimulationBatch` step):
:func:`wheel_rows` stacks each run's wheel state, :class:`FaultedDrive` applies it to the drives'
net torque in every RK4 stage, :func:`open_coils` zeroes the open coils' commands;
:func:`gyro_rows` and :func:`tachometer_rows` apply the sensor faults to the rows of readings.
A run without faults takes none of these paths: its numbers are those of the model without faults.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import FaultEvent, FaultSource, MagnetometerMeasurement, StarTrackerMeasurement
from att_sim.models import rotations as rot
from att_sim.models.actuator_specs import friction_torque
from att_sim.models.config_faults import FaultSpec, Hardware


@dataclass(frozen=True)
class Scheduled:
    """A fault waiting for its onset, and where it came from."""

    fault: FaultSpec
    source: FaultSource


class Faults:
    """The faults of one run: those scheduled and the state of those started (module docstring)."""

    def __init__(self, hardware: Hardware, frame_id: str = ""):
        n, trackers = hardware.wheels, hardware.star_trackers
        self.hardware, self.frame_id = hardware, frame_id
        self.pending: list[Scheduled] = []
        self.started: list[FaultEvent] = []             # every fault started, in order
        self.unpublished: list[FaultEvent] = []         # started since the last :meth:`take_events`
        self.wheels = False                             # any wheel drive fault started
        self.wheel_motor = np.ones(n)                   # motor torque factor: 0 off or seized
        self.wheel_friction = np.ones(n)                # friction multiplier k
        self.wheel_held = np.zeros(n, bool)             # seized: no net torque
        self.sensors = False                            # any gyro or tachometer fault started
        self.tachometer_stuck = np.zeros(n, bool)
        self.tachometer_last = np.full(n, np.nan)       # rad/s: the last reading (NaN: none yet)
        self.gyro_stuck = np.zeros(3, bool)
        self.gyro_last = np.full(3, np.nan)             # rad/s: the last reading (NaN: none yet)
        self.gyro_bias = np.zeros(3)                    # rad/s: the bias steps
        self.tracker_out = np.zeros(trackers, bool)
        self.tracker_bias: list[np.ndarray | None] = [None] * trackers   # bias quaternion of each tracker
        self.magnetometer_stuck = False
        self.magnetometer_last: MagnetometerMeasurement | None = None
        self.coil_open = np.zeros(3, bool)

    def schedule(self, fault: FaultSpec, source: FaultSource) -> None:
        """Start ``fault`` at its onset (a checked fault: :func:`att_sim.models.config_faults.fault_problem`)."""
        self.pending.append(Scheduled(fault, FaultSource(source)))
        self.pending.sort(key=lambda s: s.fault.t_s)

    def start_due(self, t: float) -> list[FaultEvent]:
        """Start the faults whose onset is at or before ``t``; their events (stamped ``t``)."""
        if not self.pending or self.pending[0].fault.t_s > t + 1e-9:
            return []
        due = [s for s in self.pending if s.fault.t_s <= t + 1e-9]
        self.pending = self.pending[len(due):]
        events = [self._start(s.fault, s.source, t) for s in due]
        self.started += events
        self.unpublished += events
        return events

    def take_events(self) -> list[FaultEvent]:
        """The faults started since the last call (the simulator node publishes them)."""
        events, self.unpublished = self.unpublished, []
        return events

    def _start(self, f: FaultSpec, source: FaultSource, t: float) -> FaultEvent:
        i, kind = f.index, f.kind
        if f.component == "wheel":
            if kind in ("seized", "off"):
                self.wheel_motor[i] = 0.0
                self.wheel_held[i] |= kind == "seized"
                self.wheels = True
            elif kind == "friction":
                self.wheel_friction[i] = f.factor
                self.wheels = True
            else:
                self.tachometer_stuck[i] = self.sensors = True
        elif f.component == "star_tracker":
            if kind == "outage":
                self.tracker_out[i] = True
            else:
                jump = rot.exp_map(np.asarray(f.bias_rad, float))
                held = self.tracker_bias[i]
                self.tracker_bias[i] = jump if held is None else rot.multiply(held, jump)
        elif f.component == "gyro":
            if kind == "axis_stuck":
                self.gyro_stuck[i] = True
            else:
                self.gyro_bias[i] += f.bias_rad_s
            self.sensors = True
        elif f.component == "magnetometer":
            self.magnetometer_stuck = True
        else:
            self.coil_open[i] = True
        return FaultEvent(t=t, component=f.component, index=i, kind=kind, factor=f.factor,
                          bias_rad=tuple(f.bias_rad) if kind == "bias_jump" else (), bias_rad_s=f.bias_rad_s,
                          source=source, frame_id=self.frame_id)

    def tracker_reading(self, index: int, m: StarTrackerMeasurement) -> StarTrackerMeasurement | None:
        """Star tracker ``index``'s measurement ``m`` through its faults (None: in outage)."""
        if self.tracker_out.size and self.tracker_out[index]:
            return None
        bias = self.tracker_bias[index] if self.tracker_bias else None
        if bias is None:
            return m
        return StarTrackerMeasurement(t=m.t, name=m.name, q=rot.multiply(m.q, bias), covariance=m.covariance,
                                      valid=m.valid, status=m.status, frame_id=m.frame_id)

    def magnetometer_reading(self, m: MagnetometerMeasurement) -> MagnetometerMeasurement:
        """The magnetometer's measurement ``m`` through its fault: stuck, the last field at the new stamp."""
        if self.magnetometer_stuck and self.magnetometer_last is not None:
            last = self.magnetometer_last
            return MagnetometerMeasurement(t=m.t, field=last.field.copy(), covariance=m.covariance,
                                           frame_id=m.frame_id)
        self.magnetometer_last = m
        return m


def _stuck(values: np.ndarray, stuck: np.ndarray, last: np.ndarray) -> np.ndarray:
    """Rows ``values`` with each stuck entry at its last value (an entry with none yet keeps its own)."""
    return np.where(stuck & np.isfinite(last), last, values)


def gyro_rows(faults: list[Faults], rates: np.ndarray) -> np.ndarray:
    """The gyro readings ``rates`` (one row per run of ``faults``) through each run's gyro faults: the
    bias steps added, the stuck axes at their last reading; the runs' last readings kept."""
    if not any(f.sensors for f in faults):
        for f, rate in zip(faults, rates):
            f.gyro_last = rate
        return rates
    rates = _stuck(rates + np.array([f.gyro_bias for f in faults]), np.array([f.gyro_stuck for f in faults]),
                   np.array([f.gyro_last for f in faults]))
    for f, rate in zip(faults, rates):
        f.gyro_last = rate
    return rates


def tachometer_rows(faults: list[Faults], speeds: np.ndarray) -> np.ndarray:
    """The tachometer readings ``speeds`` (one row per run of ``faults``) with each stuck wheel's at its
    last reading; the runs' last readings kept."""
    if any(f.sensors for f in faults):
        speeds = _stuck(speeds, np.array([f.tachometer_stuck for f in faults]),
                        np.array([f.tachometer_last for f in faults]))
    for f, speed in zip(faults, speeds):
        f.tachometer_last = speed
    return speeds


def open_coils(faults: list[Faults], m: np.ndarray) -> np.ndarray:
    """The dipole commands ``m`` (rows of the runs of ``faults``) with each open coil's zeroed."""
    if not any(f.coil_open.any() for f in faults):
        return m
    return np.where(np.array([f.coil_open for f in faults]), 0.0, m)


@dataclass(frozen=True)
class WheelRows:
    """The wheel faults of a batch's runs on rows (n, N): motor factor, friction multiplier, seized."""

    motor: np.ndarray
    friction: np.ndarray
    held: np.ndarray


def wheel_rows(faults: list[Faults]) -> WheelRows | None:
    """Each run's wheel drive faults on rows (None: no run has one)."""
    if not any(f.wheels for f in faults):
        return None
    return WheelRows(np.array([f.wheel_motor for f in faults]), np.array([f.wheel_friction for f in faults]),
                     np.array([f.wheel_held for f in faults]))


class FaultedDrive:
    """The wheel drives of a batch's runs (a :class:`att_sim.truth.actuators.WheelDrive`, or None for
    ideal motors) with their wheel faults (module docstring): the ``drive(u, ν)`` of
    :func:`att_sim.models.dynamics.rates`. The motor factor is applied to the held commands already
    (:meth:`att_sim.truth.batch.SimulationBatch.inputs`); here friction is scaled and a seized wheel's
    net torque is zero."""

    def __init__(self, drive, rows: WheelRows):
        self.drive, self.rows = drive, rows

    def motor(self, u: np.ndarray, speed: np.ndarray) -> np.ndarray:
        return u if self.drive is None else self.drive.motor(u, speed)

    def __call__(self, u: np.ndarray, speed: np.ndarray) -> np.ndarray:
        net = self.motor(u, speed)
        if self.drive is not None:
            net = net - self.rows.friction * friction_torque(*self.drive.friction_columns, speed)
        return np.where(self.rows.held, 0.0, net)
