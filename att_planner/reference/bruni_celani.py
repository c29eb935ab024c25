"""Bruni & Celani: the magnetorquer PD-gain study's published initial conditions, gains and figures."""
from __future__ import annotations

import numpy as np

from att_planner.tuning.settling import multistart_points

#: Initial conditions (20), (22), (23) as ``h = (ρ, φ, θ, ω1, ω2, ω3, ψ)``.
PUBLISHED_ICS = {
    "ic20": np.array([0.0, 0.0, 0.0, 0.02, 0.02, -0.03, 0.332]),
    "ic22": np.array([0.0, 0.0, 0.0, 0.1, 0.1, 0.1, 0.332]),
    "ic23": np.array([0.5, 0.0, 2.356194490192345, -0.1, 0.1, 0.1, 1.570796326794897]),
}

#: Gains ``(κ_p, κ_d)``: the trial pair, the fixed-IC DIRECT optimum and the three robust answers.
PUBLISHED_GAINS = {
    "trial": (2e5, 3e8),
    "fixed_direct": (205761.316872, 99382716.049383),
    "robust_direct_direct": (205493.83, 117283950.62),
    "robust_direct_sdbox": (203930.04, 154320987.65),
    "robust_direct_sdbox_multistart": (209581.62, 117283950.62),
}

#: Published figures of those gains: settling times (orbits) at the ICs, worst case, solve time (s);
#: None where the paper gives none.
PUBLISHED_TABLE = {
    "trial": {"ic20": 4.002, "ic22": None, "ic23": None, "worst": None, "seconds": None},
    "fixed_direct": {"ic20": 1.775, "ic22": 3.562, "ic23": 4.338, "worst": None, "seconds": 251.5},
    "robust_direct_direct": {"ic20": 1.945, "ic22": 2.958, "ic23": 3.370, "worst": "3.87–3.99",
                             "seconds": 172243.0},
    "robust_direct_sdbox": {"ic20": None, "ic22": None, "ic23": None, "worst": None, "seconds": 57255.0},
    "robust_direct_sdbox_multistart": {"ic20": None, "ic22": None, "ic23": None, "worst": None,
                                       "seconds": 89641.0},
}


def robust_seeds() -> np.ndarray:
    """The first hard set of the robust min-max: the published ICs, then the paper's 8 SDBOX starts."""
    return np.vstack([np.array(list(PUBLISHED_ICS.values())), multistart_points()])
