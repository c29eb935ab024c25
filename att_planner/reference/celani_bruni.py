"""Celani & Bruni (2021) / Celani & Lucarelli: the smooth keep-out maneuvers and their published figures."""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import Cone
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

PUBLISHED = {
    # t_f (s for earth_obs, TU for swift) and compute time where given
    "earth_obs": {"mssa": 2.73e3, "dfsp": 755.0, "dfsp_minutes": 136.0, "time_optimal_nonsmooth": 405.0},
    "swift": {"mssa": 6.26, "mssa_conference": 6.37, "dfsp": 5.90, "dfsp_minutes": 55.0,
              "time_optimal_nonsmooth": 3.5},
}
CASES = tuple(PUBLISHED)


def benchmark_problem(case: str) -> ManeuverProblem:
    """The published rest-to-rest cases as :class:`ManeuverProblem` (R_i = I).

    ``earth_obs``: J = diag(3000, 4500, 6000) kg m², T̄ = 0.25 N m, 135° about body x, r = y,
    Sun and Moon cones. ``swift``: J = I, T̄ = 1 (time unit TU), 135° about body z, r = x, Sun,
    Earth and Moon cones.
    """
    if case == "earth_obs":
        sc = Spacecraft(inertia=np.diag([3000.0, 4500.0, 6000.0]), body_torque_max=0.25)
        qf = rot.from_axis_angle([1.0, 0.0, 0.0], 0.75 * np.pi)
        r = np.array([0.0, 1.0, 0.0])
        cones = [Cone(np.array([-0.18, 0.56, 0.81]), np.radians(47.0), "sun"),
                 Cone(np.array([0.95, 0.0, 0.31]), np.radians(36.0), "moon")]
    elif case == "swift":
        sc = Spacecraft(inertia=np.eye(3), body_torque_max=1.0)
        qf = rot.from_axis_angle([0.0, 0.0, 1.0], 0.75 * np.pi)
        r = np.array([1.0, 0.0, 0.0])
        cones = [Cone(np.array([0.5, 0.866, 0.0]), np.radians(47.0), "sun"),
                 Cone(np.array([0.0, 0.0, -1.0]), np.radians(33.0), "earth"),
                 Cone(np.array([0.1795, 0.3109, 0.9333]), np.radians(23.0), "moon")]
    else:
        raise ValueError(f"case must be one of {CASES}, got {case!r}")
    return ManeuverProblem(spacecraft=sc, q_initial=rot.IDENTITY.copy(), q_final=qf, sensor_axis=r, cones=cones)
