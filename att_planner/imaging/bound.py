"""An upper bound on the images of a horizon: a MILP over (window, time slot) with relaxed slews.

Every access window's imaging interval ``[open, close − dwell]`` is cut into slots of
:data:`SLOT_S`; ``x_{w,s} ∈ {0, 1}`` takes window w's image in slot s. A site is imaged at most
once (``Σ_{w of the site, s} x_{w,s} ≤ 1``), and two slots of different sites exclude each other
(``x_1 + x_2 ≤ 1``) when no two instants in them are far enough apart, in either order, for a dwell
and a slew between the two sites' attitudes: ``max |τ_2 − τ_1| < dwell + t_min``.

``t_min`` is a lower bound on any slew of the spacecraft, not only on the planner's: the body covers
at least the geodesic angle θ between the two attitudes (their pointing attitudes at the slots'
centres, less what they turn within half a slot at :data:`TRACK_RATE_MAX_RAD_S`), at a speed
``|ω| ≤ √3 ω̄`` (per-axis rate bound) that grows at most at ``|ω̇| ≤ α``, with
``α = ‖((τ_w + ω̄² max|J_k − J_j|)/J_i)_i‖`` (the wheels' torque per body axis plus the largest
gyroscopic term, Euler's equations), from a tracking rate ≤ :data:`TRACK_RATE_MAX_RAD_S`:
``t_min = θ / min(√3 ω̄, sqrt(ω_t² + 2 α θ))``. Every schedule flown by the spacecraft within its
limits is thus a feasible point, and the MILP's optimum (``scipy.optimize.milp``, HiGHS) bounds the
images; its LP relaxation is reported beside it.
"""
from __future__ import annotations

import math
import time

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp
from scipy.sparse import coo_matrix

from att_planner.imaging.access import AccessWindows
from att_planner.imaging.baseline import rotation_between
from att_planner.imaging.sites import SiteSet

SLOT_S = 5.0                   # s: the imaging slots
TRACK_RATE_MAX_RAD_S = 0.015   # rad/s: above the body rate of tracking any site at >= 58 deg elevation from 800 km
MILP_TIME_LIMIT_S = 120.0      # s: HiGHS stops there (its bound is then reported)


def slots(windows: AccessWindows, dwell_s: float):
    """The slots of every window: (window, start, end) arrays."""
    w, a, b = [], [], []
    for k in range(len(windows)):
        lo, hi = float(windows.open_s[k]), float(windows.close_s[k]) - dwell_s
        n = int(math.ceil((hi - lo) / SLOT_S)) if hi > lo else (1 if hi == lo else 0)
        for i in range(n):
            w.append(k)
            a.append(lo + i * SLOT_S)
            b.append(min(lo + (i + 1) * SLOT_S, hi))
    return np.array(w, int), np.array(a, float), np.array(b, float)


def slew_time_lower_bound(angle, inertia, wheel_torque_max: float, rate_max: float) -> np.ndarray:
    """``t_min`` (s) of rotations by ``angle`` (rad) (module docstring)."""
    J = np.diag(np.asarray(inertia, float))
    gyro = rate_max**2 * (J.max() - J.min())
    alpha = float(np.linalg.norm((wheel_torque_max + gyro) / J))
    theta = np.maximum(np.asarray(angle, float), 0.0)
    speed = np.minimum(math.sqrt(3.0) * rate_max, np.sqrt(TRACK_RATE_MAX_RAD_S**2 + 2.0 * alpha * theta))
    return theta / speed


def relaxed_bound(windows: AccessWindows, sites: SiteSet, planner) -> dict:
    """The MILP bound on the images and on their priority, and the LP relaxation of the first
    (module docstring); ``planner`` (:class:`att_planner.imaging.timeline.Planner`) gives the pointing
    attitudes, the dwell and the limits."""
    start = time.perf_counter()
    dwell = planner.dwell_s
    w, a, b = slots(windows, dwell)
    n = len(w)
    site = windows.site[w]
    centre = 0.5 * (a + b)
    dcm = planner.pointing.dcm_NB(site, centre)
    sc = planner.spacecraft
    rows, cols = [], []
    # site-once rows
    for k, s in enumerate(np.unique(site)):
        idx = np.flatnonzero(site == s)
        rows.extend([k] * len(idx))
        cols.extend(idx.tolist())
    n_site = len(np.unique(site))
    order = np.argsort(a)
    a_sorted = a[order]
    horizon = dwell + SLOT_S + 2 * math.pi / (math.sqrt(3.0) * planner.limits.rate_max_rad_s)
    pairs = 0
    row = n_site
    for i_pos, i in enumerate(order):
        hi = np.searchsorted(a_sorted, b[i] + horizon, side="right")
        cand = order[i_pos + 1:hi]
        cand = cand[site[cand] != site[i]]
        if not len(cand):
            continue
        _, angle = rotation_between(dcm[i], dcm[cand])
        angle = np.maximum(angle - TRACK_RATE_MAX_RAD_S * (b[i] - a[i] + b[cand] - a[cand]) / 2.0, 0.0)
        t_min = slew_time_lower_bound(angle, sc.inertia, sc.wheel_torque_max, planner.limits.rate_max_rad_s)
        spread = np.maximum(b[cand] - a[i], b[i] - a[cand])
        clash = cand[spread < dwell + t_min]
        for j in clash:
            rows.extend([row, row])
            cols.extend([int(i), int(j)])
            row += 1
        pairs += len(clash)
    A = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(row, n)).tocsr()
    constraint = LinearConstraint(A, -np.inf, 1.0)
    out = {"method": f"MILP over (window, {SLOT_S:g} s slot) with relaxed slews (scipy.optimize.milp, HiGHS)",
           "slots": n, "conflicts": pairs, "slot_s": SLOT_S, "dwell_s": dwell}
    for name, value in (("images", np.ones(n)), ("priority", sites.priority[site])):
        res = milp(-value, constraints=constraint, integrality=np.ones(n), bounds=Bounds(0, 1),
                   options={"time_limit": MILP_TIME_LIMIT_S})
        bound = -float(res.mip_dual_bound) if getattr(res, "mip_dual_bound", None) is not None else math.nan
        out[name] = bound if math.isfinite(bound) else (-float(res.fun) if res.x is not None else math.nan)
        out[f"{name}_incumbent"] = -float(res.fun) if res.x is not None else math.nan
        out[f"{name}_status"] = res.message
        if name == "images":
            lp = milp(-value, constraints=constraint, integrality=np.zeros(n), bounds=Bounds(0, 1))
            out["images_lp"] = -float(lp.fun) if lp.x is not None else math.nan
    out["build_and_solve_s"] = time.perf_counter() - start
    return out
