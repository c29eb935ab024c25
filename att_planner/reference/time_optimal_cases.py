"""The time-optimal slew cases: Bilimoria & Wie (1993) and the Swift-like keep-out case
of Melton (2018), with their published figures; Melton's (2012) boundary cases. J = I,
T̄ = 1: times in TU.

Boundary cases (Melton 2012, §3): the sensor starts on the boundary of a cone of half-angle θ and
must end rotated by −φ about the cone's axis, semi-free (only the sensor direction is imposed at
the end); BA (boundary arc): on the boundary throughout; BP (boundary points): only its ends on it.
BA1/BP1: θ = 45°, φ = 90°; BA2/BP2: θ = 23°, φ = 70°. The paper does not give the cone axis
relative to the body axes, which matters with a per-axis torque box. Our geometry: from rest at
identity, the cone axis along body z, the sensor r = (sin θ, 0, cos θ) in the body x–z plane
(``orientation`` turns the whole scene, axis and sensor, by a rotation of the body frame).
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import Cone
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

BOUNDARY_CASES = {"ba1": (45.0, 90.0, True), "ba2": (23.0, 70.0, True),     # θ (deg), φ (deg), forced arc
                  "bp1": (45.0, 90.0, False), "bp2": (23.0, 70.0, False)}
CASES = ("bilimoria_wie", "swift", *BOUNDARY_CASES)
_MELTON_2012 = "our copy of Melton (2012) gives BP1 only: t_f = 1.9258 TU, about 1 % faster than BA1"
PUBLISHED = {
    "bilimoria_wie": "eigenaxis 2√π ≈ 3.545 TU; time-optimal ≈ 3.243 TU (Bilimoria & Wie 1993)",
    "swift": "≈ 3.5 TU (Melton 2018, DE / PSO); local minima seen at 3.07, 3.45, 4.07, 8.6 TU",
    **dict.fromkeys(BOUNDARY_CASES, _MELTON_2012),
}


def boundary_problem(case: str, orientation=rot.IDENTITY) -> ManeuverProblem:
    """A boundary case of Melton (2012) (module docstring) with the scene turned by ``orientation``
    (a quaternion: cone axis ``R z``, sensor ``R r``); BA cases carry the forced arc (``boundary_cone`` 0)."""
    theta_deg, phi_deg, arc = BOUNDARY_CASES[case]
    theta, phi = np.deg2rad(theta_deg), np.deg2rad(phi_deg)
    R = rot.dcm_NB(np.asarray(orientation, float))
    axis, sensor = R @ np.array([0.0, 0.0, 1.0]), R @ np.array([np.sin(theta), 0.0, np.cos(theta)])
    target = rot.dcm_NB(rot.from_axis_angle(axis, -phi)) @ sensor
    return ManeuverProblem(Spacecraft(np.eye(3), body_torque_max=1.0), rot.IDENTITY.copy(), rot.IDENTITY.copy(),
                           sensor, [Cone(axis, theta, "cone")], sensor_target=target,
                           boundary_cone=0 if arc else None)


def case_problem(case: str) -> ManeuverProblem:
    """The published test cases (module docstring): J = I, T̄ = 1, rest to rest from identity."""
    if case in BOUNDARY_CASES:
        return boundary_problem(case)
    sc = Spacecraft(np.eye(3), body_torque_max=1.0)
    if case == "bilimoria_wie":
        return ManeuverProblem(sc, rot.IDENTITY.copy(), rot.from_axis_angle([0.0, 0.0, 1.0], np.pi))
    if case == "swift":
        cones = [Cone(np.array([0.5, 0.866, 0.0]), np.deg2rad(47.0), "sun"),
                 Cone(np.array([0.0, 0.0, -1.0]), np.deg2rad(33.0), "earth"),
                 Cone(np.array([0.1795, 0.3109, 0.9333]), np.deg2rad(23.0), "moon")]
        return ManeuverProblem(sc, rot.IDENTITY.copy(), rot.from_axis_angle([0.0, 0.0, 1.0], np.deg2rad(135.0)),
                               np.array([1.0, 0.0, 0.0]), cones)
    raise ValueError(f"unknown case '{case}' (use one of {', '.join(CASES)})")
