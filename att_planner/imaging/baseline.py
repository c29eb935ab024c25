"""The accessible bound and bsk-rl's greedy imaging policy, as a planning estimate.

* **Accessible bound**: the sites with at least one access window in the horizon
  (:mod:`att_planner.imaging.access`) and their total priority; no schedule images more.
* **Greedy baseline** (bsk-rl's greedy policy, AVSLab's environments on Basilisk): from the current
  time and attitude, of the next :data:`LOOKAHEAD` access windows not yet imaged and not yet closed
  (in the order they open), take the one that closes first whose site can be reached: the
  rest-to-rest eigenaxis slew from the current attitude to the attitude pointing the imager at the
  site (:func:`att_planner.problem.rest_to_rest_time`: bang-bang under the per-axis torque bound,
  coasting at the body-rate and wheel-momentum bounds) arrives before the window closes. The image
  is taken at the arrival, or at the window's opening when the slew arrives earlier; the next
  decision starts ``dwell_s`` later from that attitude. When none of them can be reached, those
  windows are dropped and the next ones are tried.

The pointing attitude puts the imager (``boresight_B``) on the line of sight from the spacecraft
to the site and the next body axis (:func:`att_planner.mission.targets.next_axis`) nearest the
orbital velocity (the detector's along-track axis). The arrival is found by fixed-point iteration
on the target attitude at the arrival time (:data:`ARRIVAL_ITERATIONS`; the slew recorded is the one
to the attitude at the recorded arrival, which it reaches within the iteration's residual).

This is a **planning estimate, not a flight**: the slews are rest-to-rest estimates (they neither
end on the site's motion nor are verified against the zones), nothing is flown, and the imaging
instant is the arrival. Verified slews and the flown day are built on it elsewhere; its counts are
"planned, not flown".
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_planner.imaging.access import AccessWindows, SkyGeometry
from att_planner.imaging.sites import SiteSet
from att_planner.mission.targets import next_axis
from att_planner.problem import rest_to_rest_time

LOOKAHEAD = 32                # windows the greedy policy looks at (bsk-rl's 32 upcoming targets)
ARRIVAL_ITERATIONS = 4        # fixed-point iterations of a slew's arrival time


@dataclass(frozen=True)
class Bound:
    """The accessible bound: sites with at least one window and their total priority."""

    sites: int
    priority: float


def accessible_bound(windows: AccessWindows, sites: SiteSet) -> Bound:
    reach = windows.accessible()
    return Bound(int(reach.sum()), float(sites.priority[reach].sum()))


@dataclass(frozen=True)
class PlannedImage:
    """One image of the greedy plan: ``site`` (index) imaged at ``time_s`` within window ``window``,
    after a rest-to-rest slew of ``slew_s`` by ``slew_angle_rad``."""

    site: int
    window: int
    time_s: float
    slew_s: float
    slew_angle_rad: float


@dataclass(frozen=True)
class GreedyPlan:
    images: tuple[PlannedImage, ...]
    priority: float

    def __len__(self) -> int:
        return len(self.images)


class Pointing:
    """The attitudes (body-to-inertial DCMs) that put ``boresight_B`` on sites, along-track axis
    ``along_B`` (default :func:`~att_planner.mission.targets.next_axis` of the boresight) nearest the
    orbital velocity (module docstring)."""

    def __init__(self, environment, geometry: SkyGeometry, boresight_B, along_B=None):
        self.orbit, self.field, self.geometry = environment.orbit, environment.field, geometry
        s = np.asarray(boresight_B, float)
        s = s / np.linalg.norm(s)
        x = next_axis(s) if along_B is None else np.asarray(along_B, float) - (np.asarray(along_B, float) @ s) * s
        x = x / np.linalg.norm(x)
        self.body = np.column_stack([s, x, np.cross(s, x)])              # body basis, (3, 3)

    def dcm_NB(self, site: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Body-to-inertial DCMs pointing at site ``site[k]`` at time ``t[k]``, (M, 3, 3)."""
        t = np.atleast_1d(np.asarray(t, float))
        r, v = (np.asarray(a, float).reshape(-1, 3) for a in self.orbit.state(t))
        R = self.field.itrs_rotation(t)                                  # GCRS -> ITRS
        target = np.einsum("kji,kj->ki", R, self.geometry.sites_itrs[site])
        return self.looking(target - r, v)

    def nadir(self, t: float) -> np.ndarray:
        r, v = (np.asarray(a, float).reshape(-1, 3) for a in self.orbit.state(np.atleast_1d(float(t))))
        return self.looking(-r, v)[0]

    def looking(self, direction: np.ndarray, reference: np.ndarray) -> np.ndarray:
        d = direction / np.linalg.norm(direction, axis=1, keepdims=True)
        ref = reference - np.einsum("ij,ij->i", reference, d)[:, None] * d
        ref = ref / np.linalg.norm(ref, axis=1, keepdims=True)
        inertial = np.stack([d, ref, np.cross(d, ref)], axis=-1)       # (M, 3, 3), columns
        return inertial @ self.body.T


def rotation_between(dcm_NB0: np.ndarray, dcm_NB1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenaxes (body of the first attitude, (M, 3)) and angles (rad, (M,)) from ``dcm_NB0`` (3, 3)
    to each of ``dcm_NB1`` (M, 3, 3)."""
    rel = np.einsum("ji,mjk->mik", dcm_NB0, dcm_NB1)                   # B0 <- B1
    cos = np.clip((np.trace(rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    axis = np.stack([rel[:, 2, 1] - rel[:, 1, 2], rel[:, 0, 2] - rel[:, 2, 0], rel[:, 1, 0] - rel[:, 0, 1]], axis=1)
    norm = np.linalg.norm(axis, axis=1)
    near_pi = norm < 1e-6
    if np.any(near_pi):                        # R + I = 2 e eᵀ near π: its largest column
        sym = rel[near_pi] + np.eye(3)
        col = np.argmax(np.linalg.norm(sym, axis=1), axis=1)
        axis[near_pi] = sym[np.arange(len(col)), :, col]
        norm[near_pi] = np.linalg.norm(axis[near_pi], axis=1)
    axis = np.where(norm[:, None] > 0, axis / np.where(norm > 0, norm, 1.0)[:, None], [[1.0, 0.0, 0.0]])
    return axis, angle


def greedy(environment, spacecraft, sites: SiteSet, windows: AccessWindows, boresight_B, *,
           rate_max: float = math.inf, wheel_momentum_max: float = math.inf, lookahead: int = LOOKAHEAD,
           dwell_s: float = 0.0) -> GreedyPlan:
    """bsk-rl's greedy policy over ``windows`` (module docstring), starting at the horizon's start
    with the imager on nadir; ``spacecraft`` (:class:`att_sim.models.dynamics.Spacecraft`) gives
    the inertia and the torque bound, ``rate_max`` (rad/s per body axis) and ``wheel_momentum_max``
    (N m s per wheel) the slews' other bounds."""
    if not (isinstance(lookahead, int) and lookahead >= 1):
        raise ValueError(f"lookahead: expected an integer >= 1, got {lookahead!r}")
    if not (math.isfinite(dwell_s) and dwell_s >= 0.0):
        raise ValueError(f"dwell_s: expected a finite time >= 0 s, got {dwell_s!r}")
    pointing = Pointing(environment, SkyGeometry(environment, sites), boresight_B)
    t, dcm = windows.t0_s, pointing.nadir(windows.t0_s)
    alive = np.ones(len(windows), bool)
    imaged = np.zeros(windows.n_sites, bool)
    images = []
    while True:
        alive &= (windows.close_s > t) & ~imaged[windows.site]
        pending = np.flatnonzero(alive)[:lookahead]           # windows sorted by opening
        if not len(pending):
            break
        pending = pending[np.argsort(windows.close_s[pending], kind="stable")]
        site, opening, closing = windows.site[pending], windows.open_s[pending], windows.close_s[pending]
        arrival = np.maximum(opening, t)
        for _ in range(ARRIVAL_ITERATIONS):
            axis, angle = rotation_between(dcm, pointing.dcm_NB(site, arrival))
            slew = rest_to_rest_time(spacecraft, axis, angle, rate_max, wheel_momentum_max)
            arrival = np.maximum(opening, t + slew)
        axis, angle = rotation_between(dcm, pointing.dcm_NB(site, arrival))      # the slew to the arrival's attitude
        slew = rest_to_rest_time(spacecraft, axis, angle, rate_max, wheel_momentum_max)
        reached = np.flatnonzero(arrival <= closing)
        if not len(reached):
            alive[pending] = False
            continue
        k = int(reached[0])
        images.append(PlannedImage(int(site[k]), int(pending[k]), float(arrival[k]), float(slew[k]),
                                   float(angle[k])))
        imaged[site[k]] = True
        dcm = pointing.dcm_NB(site[k:k + 1], arrival[k:k + 1])[0]
        t = float(arrival[k]) + dwell_s
    return GreedyPlan(tuple(images), float(sum(sites.priority[i.site] for i in images)))
