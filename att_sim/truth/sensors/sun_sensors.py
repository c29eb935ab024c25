"""Coarse sun sensors: cosine detectors on the body, albedo-free, dark in the Earth's shadow.

Detector i with body normal ``n_i`` and field of view ``fov`` (half-angle) outputs
``I_i = f · max(0, n_iᵀ ŝ_B) + ε_i`` when ``∠(n_i, ŝ_B) < fov``, else ``ε_i``, clipped at 0; ``ŝ_B``
is the Sun's direction in body axes, ``f`` the visible fraction of the solar disc (0 in umbra,
penumbra in between) and ``ε_i`` white noise of 1σ ``noise`` (Wertz 1978 §6.1: the cosine law of a
photodiode; the Earth's albedo is left out).
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import SunSensorMeasurement
from att_sim.models import rotations as rot
from att_sim.models.sensor_specs import SunSensorSpec
from att_sim.models.world import Bodies


class SunSensors:
    def __init__(self, spec: SunSensorSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng
        self.cos_fov = math.cos(spec.fov)

    def measure(self, t: float, q_BN: np.ndarray, bodies: Bodies, frame_id: str = "") -> SunSensorMeasurement:
        s = self.spec
        cosines = s.normals @ (rot.dcm_BN(q_BN) @ bodies.sun)
        lit = np.where(cosines > self.cos_fov, np.maximum(cosines, 0.0) * bodies.shadow, 0.0)
        values = np.maximum(lit + self.rng.standard_normal(len(cosines)) * s.noise, 0.0)
        return SunSensorMeasurement(t=t, values=values, noise=s.noise, frame_id=frame_id)
