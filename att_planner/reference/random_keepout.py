"""Seeded random keep-out sets about the Swift case of Melton (2018): its Sun, Earth and Moon cones
(:func:`att_planner.reference.celani_bruni.benchmark_problem`) plus random cones scattered about its
eigenaxis path, start and goal clear of every cone. J = I, T̄ = 1: times in TU.

:func:`keepout_set` draws one set from a seed; :data:`FASTEST_SETS` seeds the 40 sets on which the
time-optimal answer is compared with every other verified plan of the planner service (``att-bench
fastest``; ``test/att_planner/service/test_fastest.py``).
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from att_msgs_py.types import Cone
from att_planner.problem import ManeuverProblem
from att_planner.reference.celani_bruni import benchmark_problem
from att_sim.models import rotations as rot

FASTEST_SETS = range(40)         # the seeds of the 40 sets
EXTRA_CONES = (1, 7)             # fewest and most random cones of a set
HALF_ANGLE_DEG = (8.0, 20.0)     # range of their half-angles
SCATTER_RAD = 0.3                # rms offset of a cone axis from a point of the path, per component
END_CLEARANCE_DEG = 3.0          # least angle between a cone's boundary and the start or goal direction
PATH_POINTS = 50                 # points of the eigenaxis path (between 10 % and 90 % of it) cones are drawn near


def keepout_set(seed: int, extra: tuple[int, int] = EXTRA_CONES) -> ManeuverProblem:
    """The Swift problem with ``extra[0]``–``extra[1]`` random cones (numpy ``default_rng(seed)``):
    each axis a point of the eigenaxis path of the sensor plus Gaussian scatter of
    :data:`SCATTER_RAD` per component, normalised; its half-angle uniform in :data:`HALF_ANGLE_DEG`;
    a cone closer than :data:`END_CLEARANCE_DEG` to the start or goal direction is drawn again."""
    low, high = extra
    if not 0 <= low <= high:
        raise ValueError(f"extra must be (fewest, most) cones with 0 <= fewest <= most, got {extra!r}")
    base = benchmark_problem("swift")
    path = rot.dcm_NB(rot.slerp(base.q_initial, base.q_final, np.linspace(0.1, 0.9, PATH_POINTS))) @ base.sensor_axis
    ends = [rot.dcm_NB(q) @ base.sensor_axis for q in (base.q_initial, base.q_final)]
    rng = np.random.default_rng(seed)
    count = len(base.cones) + int(rng.integers(low, high + 1))
    cones = list(base.cones)
    while len(cones) < count:
        axis = path[rng.integers(len(path))] + rng.normal(size=3) * SCATTER_RAD
        axis /= np.linalg.norm(axis)
        half = math.radians(rng.uniform(*HALF_ANGLE_DEG))
        if all(math.acos(np.clip(e @ axis, -1.0, 1.0)) > half + math.radians(END_CLEARANCE_DEG) for e in ends):
            cones.append(Cone(axis, half, f"extra{len(cones)}"))
    return replace(base, cones=cones)
