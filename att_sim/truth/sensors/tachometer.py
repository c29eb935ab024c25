"""Wheel tachometers: each wheel's speed relative to the body, as its drive measures it, with white
noise and quantisation."""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import WheelSpeedMeasurement
from att_sim.models.sensor_specs import TachometerSpec
from att_sim.truth.actuators import quantize


class Tachometer:
    def __init__(self, spec: TachometerSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng

    def measure(self, t: float, relative_speed: np.ndarray, frame_id: str = "") -> WheelSpeedMeasurement:
        speeds = measure_together([self], np.asarray(relative_speed, float)[None])[0]
        return WheelSpeedMeasurement(t=t, speeds=speeds, frame_id=frame_id)


def measure_together(tachometers: list[Tachometer], relative_speeds: np.ndarray) -> np.ndarray:
    """The speeds each tachometer measures (a row of ``relative_speeds`` each: the runs of a
    lockstep), each one's noise from its own stream, the arithmetic on rows (element by element:
    each row's bits alone)."""
    noise = np.array([[tach.spec.noise] for tach in tachometers])
    lsb = np.array([[tach.spec.quantization] for tach in tachometers])
    n = relative_speeds.shape[1]
    draws = np.array([tach.rng.standard_normal(n) for tach in tachometers]).reshape(len(tachometers), n)
    return quantize(relative_speeds + draws * noise, lsb)
