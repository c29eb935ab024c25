"""Olivares & Staffetti (2018), section 5: the observation satellite, the targets of experiments
A, B and C, and the published schedules."""
from __future__ import annotations

import numpy as np

from att_planner.problem import ManeuverProblem
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot

_TARGETS_SCALAR_LAST = {
    "a": (0.13002, 0.01137, 0.08641, 0.98767), "b": (0.19616, 0.09147, 0.41260, 0.88482),
    "c": (0.05516, 0.11829, 0.89855, 0.41900), "d": (0.01886, 0.21561, 0.97258, 0.08508),
    "e": (-0.07486, 0.10692, 0.81214, -0.56866), "f": (-0.17729, 0.12414, 0.55998, -0.79973),
    "g": (0.34071, 0.02980, 0.08189, 0.93611), "h": (0.38302, 0.17860, 0.38302, 0.82139),
    "i": (0.14454, 0.30997, 0.85165, 0.39713), "j": (0.03683, 0.42101, 0.90285, 0.07898),
    "k": (-0.19617, 0.28016, 0.76975, -0.53898), "l": (-0.34618, 0.24240, 0.51983, -0.74240),
    "m": (0.67301, 0.05888, 0.06425, 0.73447), "n": (0.66820, 0.31158, 0.28551, 0.61229),
    "o": (0.28551, 0.61229, 0.66820, 0.31158), "p": (0.06425, 0.73447, 0.67301, 0.05888),
    "q": (-0.38750, 0.55341, 0.60394, -0.42288), "r": (-0.60394, 0.42288, 0.38750, -0.55341),
}

#: Published results (4 GHz i7, BONMIN + 5th-degree Gauss–Lobatto collocation, 2 intervals/phase).
PUBLISHED = {
    "A": {"tf": 592.49, "solve_seconds": 5.48, "order": list("afedcb")},
    "B": {"tf": 744.03, "solve_seconds": 23.27, "order": None},
    "C": {"tf": 897.46, "solve_seconds": 35.50, "order": None},
}
PUBLISHED_REST_TO_REST_AB = {"collocation": 57.05, "dido": 57.59}


def olivares_spacecraft() -> dyn.Spacecraft:
    """The experiments' spacecraft: I_s = diag(6.63, 8.90, 9.63) kg m², three wheels on the body
    axes, I_w = 1.69e-4 kg m², |T_u| ≤ 0.0101 N m, |Ω| ≤ 710 rad/s (body rate bound: 0.04 rad/s,
    see :data:`OLIVARES_RATE_MAX`)."""
    return dyn.Spacecraft(inertia=np.diag([6.63, 8.90, 9.63]), wheel_axes=np.eye(3),
                          wheel_inertia=0.000169, wheel_torque_max=0.0101, wheel_speed_max=710.0)


OLIVARES_RATE_MAX = 0.04  # rad/s per body axis


def olivares_targets(experiment: str = "C") -> dict[str, np.ndarray]:
    """Targets of experiment 'A' (a–f), 'B' (a–l) or 'C' (a–r) as quaternions [x, y, z, w]."""
    count = {"A": 6, "B": 12, "C": 18}.get(str(experiment).upper())
    if count is None:
        raise ValueError(f"experiment must be 'A', 'B' or 'C', not {experiment!r}")
    names = sorted(_TARGETS_SCALAR_LAST)[:count]
    return {n: rot.normalize(np.array(_TARGETS_SCALAR_LAST[n])) for n in names}


def problem(experiment: str = "A", targets: dict | None = None, q_start=rot.IDENTITY, q_end=None) -> ManeuverProblem:
    """The schedule problem of an experiment: every target from rest at ``q_start`` to rest at
    ``q_end`` (default ``q_start``), wheels and body-rate bound of the paper (``targets`` replaces
    the experiment's)."""
    q_start = rot.normalize(np.asarray(q_start, float))
    return ManeuverProblem(olivares_spacecraft(), q_start, q_start if q_end is None else rot.normalize(q_end),
                           targets=olivares_targets(experiment) if targets is None else dict(targets),
                           rate_max=OLIVARES_RATE_MAX)
