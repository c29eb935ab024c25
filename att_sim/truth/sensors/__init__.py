"""The spacecraft's sensors (truth side, no ROS): datasheets (:mod:`.specs`), one model per module
(:mod:`.gyro`, :mod:`.star_tracker`, :mod:`.magnetometer`, :mod:`.sun_sensors`, :mod:`.tachometer`)
and :class:`SensorSuite`, which samples them at their rates as the simulation advances.

Reproducibility: every random stream of a run (each sensor's drawn errors and noise, the wheel
drives' and magnetorquers' errors) comes from ``numpy.random.SeedSequence(seed, spawn_key=(k,))``
with a fixed ``k`` per source (:data:`STREAMS`), so a run is reproduced by its seed alone and a
source added later does not change the others' streams.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import (
    GyroMeasurement,
    MagnetometerMeasurement,
    SensorTruth,
    StarTrackerMeasurement,
    SunSensorMeasurement,
    WheelSpeedMeasurement,
)
from att_sim.models import rotations as rot
from att_sim.models.sensor_specs import SensorSpecs
from att_sim.models.world import Bodies
from att_sim.truth import faults as faulting
from att_sim.truth.sensors.gyro import Gyro
from att_sim.truth.sensors.magnetometer import Magnetometer
from att_sim.truth.sensors.star_tracker import StarTracker
from att_sim.truth.sensors.sun_sensors import SunSensors
from att_sim.truth.sensors.tachometer import Tachometer
from att_sim.truth.sensors.tachometer import measure as measure_tachometers

STREAMS = {"gyro": 0, "magnetometer": 1, "sun_sensors": 2, "tachometer": 3, "wheel_drive": 4, "magnetorquers": 5,
           "star_tracker": 16}      # star tracker i: 16 + i


def rng(seed: int, source: str, index: int = 0) -> np.random.Generator:
    """The random stream of one source of a run (see module docstring)."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(STREAMS[source] + index,)))


@dataclass
class Readings:
    """The measurements one instant produces (each None or empty when not due)."""

    gyro: GyroMeasurement | None = None
    star_trackers: list[StarTrackerMeasurement] = field(default_factory=list)
    magnetometer: MagnetometerMeasurement | None = None
    sun_sensors: SunSensorMeasurement | None = None
    wheel_speeds: WheelSpeedMeasurement | None = None
    truth: SensorTruth | None = None


@dataclass
class Taken:
    """What was measured for a suite already, its schedules asked (:meth:`att_sim.truth.batch.SimulationBatch.sense`
    measures the gyros and tachometers of its runs on rows): the gyro's interval (None: not due)
    and rate, the tachometer's sample (None: not due)."""

    gyro_interval: tuple[np.ndarray, float] | None = None
    gyro_rate: np.ndarray | None = None
    wheel_speeds: WheelSpeedMeasurement | None = None


class _Schedule:
    """Due times of a sensor of ``rate`` Hz: t = 0, 1/rate, 2/rate, ... (counted, never drifting)."""

    def __init__(self, rate: float):
        self.period, self.count = 1.0 / rate, 0

    def due(self, t: float) -> bool:
        if t < self.count * self.period - 1e-9:
            return False
        self.count = math.floor(t / self.period + 1e-9) + 1
        return True


class SensorSuite:
    """Every sensor of ``specs``, sampled as :meth:`sample` is called at increasing times."""

    def __init__(self, specs: SensorSpecs, seed: int, frame_id: str = "", body_frame_id: str = "",
                 faults: faulting.Faults | None = None):
        self.specs, self.frame_id, self.body_frame_id = specs, frame_id, body_frame_id
        self.faults = faults              # the run's hardware faults (:mod:`att_sim.truth.faults`; None: none)
        self.gyro = Gyro(specs.gyro, rng(seed, "gyro")) if specs.gyro else None
        self.trackers = [StarTracker(s, rng(seed, "star_tracker", i)) for i, s in enumerate(specs.star_trackers)]
        self.magnetometer = Magnetometer(specs.magnetometer, rng(seed, "magnetometer")) if specs.magnetometer else None
        self.sun_sensors = SunSensors(specs.sun_sensors, rng(seed, "sun_sensors")) if specs.sun_sensors else None
        self.tachometer = Tachometer(specs.tachometer, rng(seed, "tachometer")) if specs.tachometer else None
        rate = {"gyro": specs.gyro, "magnetometer": specs.magnetometer, "sun_sensors": specs.sun_sensors,
                "tachometer": specs.tachometer}
        self.schedules = {name: _Schedule(s.rate) for name, s in rate.items() if s is not None}
        self.tracker_schedules = [_Schedule(s.rate) for s in specs.star_trackers]
        self.pending: list[tuple[float, StarTrackerMeasurement]] = []        # (release time, measurement)
        self.gyro_last: tuple[float, np.ndarray] | None = None               # (t, q) of the last gyro sample

    def gyro_interval(self, t: float, q: np.ndarray, omega: np.ndarray,
                      rotation: np.ndarray | None = None) -> tuple[np.ndarray, float] | None:
        """When the gyro is due at ``t``: the rotation vector it measures (since its previous sample,
        ``log(q_last* ⊗ q)``: ``rotation`` when computed already; at its first, ``omega`` over one
        period) and the interval; None when it is not (or there is none). Asking starts the gyro's
        next interval."""
        if self.gyro is None or not self.schedules["gyro"].due(t):
            return None
        if self.gyro_last is None:
            dt = self.schedules["gyro"].period
            rotation = np.asarray(omega, float) * dt
        else:
            dt = t - self.gyro_last[0]
            rotation = rot.log_map(rot.multiply(rot.conjugate(self.gyro_last[1]), q)) if rotation is None else rotation
        self.gyro_last = (t, np.array(q, float))
        return rotation, dt

    def tachometer_due(self, t: float) -> bool:
        """Whether the tachometer samples at ``t`` (asking starts its next period)."""
        return self.tachometer is not None and self.schedules["tachometer"].due(t)

    def sample(self, t: float, q: np.ndarray, omega: np.ndarray, relative_wheel_speed: np.ndarray | None,
               field_B: np.ndarray, dipole_applied: np.ndarray, bodies: Callable[[], Bodies],
               taken: Taken | None = None) -> Readings:
        """What the sensors output at time ``t`` for the truth state (attitude ``q``, body rate
        ``omega``, wheel speeds relative to the body) and the environment (``field_B`` in body axes,
        the applied dipole, ``bodies()``: called when a sensor that sees them is due). The gyro
        measures the rotation since its previous sample (at its first sample: ``omega`` over one
        period); a tracker's measurement of ``t`` comes out at the first call at or after ``t`` + its
        latency. ``taken``: the gyro's and the tachometer's measurements when they were taken already
        on rows of runs (:meth:`att_sim.truth.batch.SimulationBatch.sense`; then
        ``relative_wheel_speed`` is not used); else this suite takes them, a row of one. The run's
        faults act on every reading (:mod:`att_sim.truth.faults`)."""
        faults = self.faults
        if taken is None:
            taken = Taken(self.gyro_interval(t, q, omega))
            if taken.gyro_interval is not None:
                taken.gyro_rate = self.gyro.measure(*taken.gyro_interval)
                if faults is not None:
                    taken.gyro_rate = faulting.gyro_rows([faults], taken.gyro_rate[None])[0]
            if self.tachometer_due(t):
                speeds = measure_tachometers([self.tachometer], np.asarray(relative_wheel_speed, float)[None])
                if faults is not None:
                    speeds = faulting.tachometer_rows([faults], speeds)
                taken.wheel_speeds = WheelSpeedMeasurement(t, speeds[0], self.body_frame_id)
        out = Readings()
        body = self.body_frame_id
        if taken.gyro_interval is not None:
            out.gyro = GyroMeasurement(t, taken.gyro_rate, self.gyro.noise_covariance(taken.gyro_interval[1]), body)
            bias = self.gyro.bias.copy() if faults is None else self.gyro.bias + faults.gyro_bias
            out.truth = SensorTruth(t, bias, self._magnetometer_bias(), body)
        sky = None
        for k, (tracker, schedule) in enumerate(zip(self.trackers, self.tracker_schedules)):
            if schedule.due(t):
                sky = bodies() if sky is None else sky
                measured = tracker.measure(t, q, omega, sky, self.frame_id)
                if faults is not None:
                    measured = faults.tracker_reading(k, measured)
                if measured is not None:
                    self.pending.append((t + tracker.spec.latency, measured))
        if self.pending:
            out.star_trackers = [m for release, m in self.pending if release <= t + 1e-9]
            self.pending = [(release, m) for release, m in self.pending if release > t + 1e-9]
        out.wheel_speeds = taken.wheel_speeds
        if self.magnetometer is not None and self.schedules["magnetometer"].due(t):
            out.magnetometer = self.magnetometer.measure(t, field_B, dipole_applied, body)
            if faults is not None:
                out.magnetometer = faults.magnetometer_reading(out.magnetometer)
        if self.sun_sensors is not None and self.schedules["sun_sensors"].due(t):
            out.sun_sensors = self.sun_sensors.measure(t, q, bodies() if sky is None else sky, body)
        return out

    def _magnetometer_bias(self) -> np.ndarray:
        return self.magnetometer.bias.copy() if self.magnetometer is not None else np.zeros(3)
