"""Star tracker: the attitude of its sensor frame, with noise across and about the boresight, blinded
inside its exclusion angles.

The sensor frame S is mounted in the body by ``q_SB`` (sensor-to-body); its boresight is +z_S. The
true sensor attitude is ``q_SN = q_BN ⊗ q_SB`` and the measurement ``q_SN ⊗ exp(ν)`` with
``ν ~ N(0, diag(σ_c², σ_c², σ_b²))`` about the sensor axes (cross-boresight σ_c, about-boresight σ_b:
a tracker measures star positions on its focal plane, so its roll is several times noisier).

It reports *invalid* — never a wrong attitude — when the Sun, the Moon, the Earth's limb or an
inertial exclusion direction is within its exclusion angle of the boresight (the stray light
washes out the stars), or when the body turns faster than ``max_rate`` (the stars smear). The
Earth's exclusion counts from its limb: blinded when ``∠(boresight, nadir) < ρ_E + half_angle``,
``ρ_E = asin(R_E/|r|)``. Exclusions are checked in the order the datasheet lists them; the first
one that blinds names the status.
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py.types import StarTrackerMeasurement, TrackerStatus
from att_sim.models import rotations as rot
from att_sim.models.sensor_specs import Exclusion, StarTrackerSpec
from att_sim.models.world import Bodies

BORESIGHT_S = np.array([0.0, 0.0, 1.0])
STATUS_OF_BODY = {"sun": TrackerStatus.SUN, "earth_limb": TrackerStatus.EARTH, "moon": TrackerStatus.MOON,
                  "inertial": TrackerStatus.EXCLUDED}


def exclusion_margin(exclusion: Exclusion, boresight_N: np.ndarray, bodies: Bodies) -> float:
    """Angle (rad) by which the boresight clears ``exclusion`` (negative: blinded)."""
    if exclusion.body == "earth_limb":
        axis, half = bodies.nadir, bodies.earth_radius + exclusion.half_angle
    else:
        axis = {"sun": bodies.sun, "moon": bodies.moon, "inertial": exclusion.direction}[exclusion.body]
        half = exclusion.half_angle
    if axis is None:
        raise ValueError(f"a {exclusion.body} exclusion needs the sky (a scenario epoch)")
    return math.acos(min(max(float(boresight_N @ axis), -1.0), 1.0)) - half


class StarTracker:
    def __init__(self, spec: StarTrackerSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng
        self.sigma = np.array([spec.cross_boresight, spec.cross_boresight, spec.about_boresight])

    def status(self, q_SN: np.ndarray, omega_B: np.ndarray, bodies: Bodies) -> TrackerStatus:
        """Whether the tracker sees its stars at sensor attitude ``q_SN`` and body rate ``omega_B``."""
        if float(np.linalg.norm(omega_B)) > self.spec.max_rate:
            return TrackerStatus.RATE
        boresight = rot.dcm_NB(q_SN) @ BORESIGHT_S
        for exclusion in self.spec.exclusions:
            if exclusion_margin(exclusion, boresight, bodies) < 0.0:
                return STATUS_OF_BODY[exclusion.body]
        return TrackerStatus.OK

    def measure(self, t: float, q_BN: np.ndarray, omega_B: np.ndarray, bodies: Bodies,
                frame_id: str = "") -> StarTrackerMeasurement:
        """The measurement of the instant ``t`` (the noise is drawn for every sample, valid or not,
        so the stream of a run does not depend on when the tracker is blinded)."""
        q_SN = rot.multiply(q_BN, self.spec.mounting)
        noise = self.rng.standard_normal(3) * self.sigma
        status = self.status(q_SN, omega_B, bodies)
        valid = status == TrackerStatus.OK
        return StarTrackerMeasurement(t=t, name=self.spec.name, q=rot.multiply(q_SN, rot.exp_map(noise)),
                                      covariance=self.spec.covariance, valid=valid, status=int(status),
                                      frame_id=frame_id)
