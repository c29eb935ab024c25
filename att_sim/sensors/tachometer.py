"""Wheel tachometers: each wheel's speed relative to the body, as its drive measures it, with white
noise and quantisation."""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import WheelSpeedMeasurement
from att_sim.actuators import quantize
from att_sim.sensors.specs import TachometerSpec


class Tachometer:
    def __init__(self, spec: TachometerSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng

    def measure(self, t: float, relative_speed: np.ndarray, frame_id: str = "") -> WheelSpeedMeasurement:
        s = self.spec
        speeds = np.asarray(relative_speed, float) + self.rng.standard_normal(len(relative_speed)) * s.noise
        speeds = quantize(speeds, s.quantization)
        return WheelSpeedMeasurement(t=t, speeds=speeds, frame_id=frame_id)
