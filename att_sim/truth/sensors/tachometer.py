"""Wheel tachometers: each wheel's speed relative to the body, as its drive measures it, with white
noise and quantisation."""
from __future__ import annotations

import numpy as np

from att_sim.models.sensor_specs import TachometerSpec
from att_sim.truth.actuators import quantize


class Tachometer:
    def __init__(self, spec: TachometerSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng


def measure(tachometers: list[Tachometer], relative_speeds: np.ndarray) -> np.ndarray:
    """The speeds each tachometer measures, a row of ``relative_speeds`` (n × N) each (one
    spacecraft's, or the runs of a batch), each one's noise from its own stream."""
    noise = np.array([[tach.spec.noise] for tach in tachometers])
    lsb = np.array([[tach.spec.quantization] for tach in tachometers])
    n = relative_speeds.shape[1]
    draws = np.array([tach.rng.standard_normal(n) for tach in tachometers]).reshape(len(tachometers), n)
    return quantize(relative_speeds + draws * noise, lsb)
