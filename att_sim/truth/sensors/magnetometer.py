"""Three-axis magnetometer: the field in body axes with the errors of a datasheet.

``B_m = Q( (I + M) B_b + b + k m_applied + n )``: misalignment ``M`` (six small off-diagonal angles)
and fixed bias ``b`` drawn once per unit, white noise ``n`` (σ per axis), quantisation ``Q``, and
the field of the spacecraft's own magnetorquers ``k m_applied`` (T per A m², along the applied
dipole): why flight software blanks the magnetometer while it torques (duty cycling).
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import MagnetometerMeasurement
from att_sim.models.rotations import small_error_matrix
from att_sim.models.sensor_specs import MagnetometerSpec
from att_sim.truth.actuators import quantize


class Magnetometer:
    def __init__(self, spec: MagnetometerSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng
        self.transfer = small_error_matrix(rng, 0.0, spec.misalignment)
        self.bias = rng.normal(0.0, spec.bias, 3)
        self.covariance = np.eye(3) * (spec.noise**2 + spec.quantization**2 / 12.0)

    def measure(self, t: float, field_B: np.ndarray, dipole_applied: np.ndarray,
                frame_id: str = "") -> MagnetometerMeasurement:
        s = self.spec
        b = self.transfer @ field_B + self.bias + s.dipole_coupling * np.asarray(dipole_applied, float)
        b = quantize(b + self.rng.standard_normal(3) * s.noise, s.quantization)
        return MagnetometerMeasurement(t=t, field=b, covariance=self.covariance, frame_id=frame_id)
