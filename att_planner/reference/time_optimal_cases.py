"""The time-optimal slew cases (issue 4): Bilimoria & Wie (1993) and the Swift-like keep-out case
of Melton (2018), with their published figures. J = I, T̄ = 1: times in TU."""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import Cone
from att_planner.problem import ManeuverProblem
from att_sim import rotations as rot
from att_sim.dynamics import Spacecraft

CASES = ("bilimoria_wie", "swift")
PUBLISHED = {
    "bilimoria_wie": "eigenaxis 2√π ≈ 3.545 TU; time-optimal ≈ 3.243 TU (Bilimoria & Wie 1993)",
    "swift": "≈ 3.5 TU (Melton 2018, DE / PSO); local minima seen at 3.07, 3.45, 4.07, 8.6 TU",
}


def case_problem(case: str) -> ManeuverProblem:
    """The issue's test cases: J = I, T̄ = 1, rest to rest from identity."""
    sc = Spacecraft(np.eye(3), body_torque_max=1.0)
    if case == "bilimoria_wie":
        return ManeuverProblem(sc, rot.IDENTITY.copy(), rot.from_axis_angle([0.0, 0.0, 1.0], np.pi))
    if case == "swift":
        cones = [Cone(np.array([0.5, 0.866, 0.0]), np.deg2rad(47.0), "sun"),
                 Cone(np.array([0.0, 0.0, -1.0]), np.deg2rad(33.0), "earth"),
                 Cone(np.array([0.1795, 0.3109, 0.9333]), np.deg2rad(23.0), "moon")]
        return ManeuverProblem(sc, rot.IDENTITY.copy(), rot.from_axis_angle([0.0, 0.0, 1.0], np.deg2rad(135.0)),
                               np.array([1.0, 0.0, 0.0]), cones)
    raise ValueError(f"unknown case '{case}' (use bilimoria_wie or swift)")
