"""An imaging timeline: which sites, in which order, reached by verified track-to-track slews.

The spacecraft starts on nadir (the imager on the sub-satellite point, its along-track axis nearest
the velocity). From the current pointing law L at the time ``t`` it is free, a decision weighs the
next :data:`~att_planner.imaging.baseline.LOOKAHEAD` access windows (by opening) whose site is not
imaged yet and that are still open long enough: each one's imaging time is first **estimated**
with the rest-to-rest eigenaxis time from L's attitude at ``t`` (vectorised,
:func:`att_planner.problem.rest_to_rest_time`), ``max(t + slew + settle, open)``, and those whose
image and dwell fit before the window closes are ranked by the **policy**:

* ``greedy`` — bsk-rl's greedy policy: the window that closes first;
* ``ours`` — insertion before the deadline: the image that ends first, less
  :data:`PRIORITY_WEIGHT_S` per unit of the site's priority, provided the earliest-closing window
  stays reachable after it on the estimates (slews scaled by :data:`SLEW_SCALE`); else the
  earliest-closing window. In a dense field the nearest site in time keeps the spacecraft imaging
  while the window about to close is still served;
* ``rollout`` — a rollout of ours (Bertsekas, Tsitsiklis & Wu 1997, "Rollout algorithms for
  combinatorial optimization", J. Heuristics 3; Bertsekas 2013, "Rollout algorithms for discrete
  optimization: a survey"): the candidates are the first :data:`ROLLOUT_CANDIDATES` windows of
  ours' order and the :data:`ROLLOUT_CANDIDATES` that image first. From each candidate c imaged
  at its estimate, ours is simulated on the estimates, every slew the rest-to-rest time scaled by
  :data:`ROLLOUT_SLEW_SCALE` (the exact track-to-track slews over their rest-to-rest estimate,
  fitted: median 1.23, 5–95 % 1.20–1.38 on uniform:3000, seed 0, one orbit), until
  ``t + ROLLOUT_HORIZON_S``. Its score is ``J(c) = n(c) − λ ℓ(c)``: n the images of the
  simulation (c's included), ℓ the sites whose every window closes in it unimaged (lost for good),
  λ = :data:`ROLLOUT_LOST_WEIGHT`; the largest J, then the earliest free time at the horizon, then
  ours' order wins (a candidate whose scaled estimate ends after its window closes is not rolled out).
  The winner is attempted first, then ours' order. The simulation is a model
  (no zones, no exact slews): nothing it plans is kept but the choice of the next window.

The first of the ranked windows (at most :data:`TRIES`) whose **exact** attempt succeeds is taken.
An attempt (:meth:`Planner.attempt`) plans the slew from L's tracking state onto the site's law
(:func:`att_planner.imaging.slews.fastest`); when it would arrive more than the settle time before
the window opens, it starts later (holding L) so that it arrives then, or, when that wait would be
longer than :data:`HOLD_MAX_S`, it first slews to nadir and holds it. Every slew is verified
(:func:`att_planner.imaging.slews.verify`: the arrival on the site's true law, the zones at their
true positions, the limits) and every held stretch (the holds, the settle and the dwell) keeps
clear of the zones at samples :data:`ZONE_SAMPLE_S` apart on its law; a failed attempt drops the
window. The image is taken :data:`SETTLE_S` after the arrival (or at the window's opening) and held
``dwell_s``; the spacecraft is free again at the dwell's end, on the site's law.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import PointingMode
from att_planner.guidance import reference
from att_planner.guidance.ground_arrival import ground_motion
from att_planner.guidance.laws import PointingGeometry, directions
from att_planner.guidance.modes import law_of
from att_planner.imaging import slews
from att_planner.imaging.access import AccessWindows, SkyGeometry
from att_planner.imaging.baseline import LOOKAHEAD, Pointing, rotation_between
from att_planner.imaging.sites import SiteSet
from att_planner.mission.targets import next_axis
from att_planner.problem import rest_to_rest_time
from att_sim.models import rotations as rot

POLICIES = ("greedy", "ours", "rollout")
SETTLE_S = 3.0            # s tracked between the arrival and the image (the hand-over settles)
DWELL_S = 2.0             # s an image is held (level b)
HOLD_MAX_S = 60.0         # s: a longer wait for a window is spent on nadir
ZONE_SAMPLE_S = 2.0       # s between the zone samples of a held stretch
TRIES = 4                 # exact attempts per decision
PRIORITY_WEIGHT_S = 10.0  # s of waiting one unit of priority is worth (policy ours)
SLEW_SCALE = 1.6          # the track-to-track slews' time over the rest-to-rest estimate (policy ours)
ROLLOUT_CANDIDATES = 3    # windows the rollout simulates at a decision (policy rollout)
ROLLOUT_HORIZON_S = 200.0  # s each rollout is simulated ahead (policy rollout)
ROLLOUT_SLEW_SCALE = 1.25  # the exact slews' time over the rest-to-rest estimate, fitted (policy rollout)
ROLLOUT_LOST_WEIGHT = 1.0  # images one site lost for good is worth in a rollout's score (policy rollout)
NADIR = -1                # the target index of nadir
REFERENCE_STEP_S = 0.01   # s: the central difference of the nadir law's rate


@dataclass(frozen=True)
class Leg:
    """A slew of the timeline onto ``target`` (a site index, or :data:`NADIR`)."""

    target: int
    slew: slews.Slew
    check: slews.SlewCheck


@dataclass(frozen=True)
class Image:
    """A planned image: ``site`` within access window ``window``, held from ``time_s`` for ``dwell_s``,
    after the slew arriving at ``arrival_s``."""

    site: int
    window: int
    time_s: float
    dwell_s: float
    arrival_s: float


@dataclass
class Timeline:
    """The legs and images of a horizon, the planner's CPU time (s) and its attempts (tried, failed)."""

    policy: str
    legs: list[Leg] = field(default_factory=list)
    images: list[Image] = field(default_factory=list)
    cpu_s: float = 0.0
    attempts: int = 0
    failed: int = 0
    worst_zone_margin: float = math.inf
    failures: dict[str, int] = field(default_factory=dict)      # why attempts failed: count

    def priority(self, sites: SiteSet) -> float:
        return float(sum(sites.priority[i.site] for i in self.images))


def along_track_axis(boresight_B, zone_axes_B) -> np.ndarray:
    """The body axis kept along the track: normal to the boresight, in the plane the zones' sensors
    (the star trackers) lean into (the principal direction of their axes' parts normal to the
    boresight), so that the trackers look fore and aft along the track, away from the orbit normal;
    :func:`att_planner.mission.targets.next_axis` of the boresight when there are none."""
    s = np.asarray(boresight_B, float) / np.linalg.norm(boresight_B)
    a = np.asarray(zone_axes_B, float).reshape(-1, 3)
    p = a - np.outer(a @ s, s)
    if not len(p) or np.linalg.norm(p) < 1e-9:
        return next_axis(s)
    x = np.linalg.eigh(p.T @ p)[1][:, -1]
    x = x - (x @ s) * s
    x = x / np.linalg.norm(x)
    k = int(np.argmax(np.abs(x)))
    return x if x[k] > 0 else -x


class Laws:
    """The pointing laws of the sites and of nadir on the onboard geometry of ``environment``: the
    imager ``boresight_B`` on the target, ``along_B`` nearest the velocity; as the controller's
    :class:`PointingMode` and as ``t ↦ (q_RN, ω_RN_R)``."""

    def __init__(self, environment, sites: SiteSet, boresight_B, along_B):
        self.geometry = PointingGeometry.of(environment)
        self.sites = sites
        self.boresight = np.asarray(boresight_B, float) / np.linalg.norm(boresight_B)
        self.along = np.asarray(along_B, float)
        self._velocity = directions(self.geometry)["velocity"]
        self._laws: dict[int, object] = {}

    def mode(self, target: int) -> PointingMode:
        if target == NADIR:
            return PointingMode("nadir", primary_axis=self.boresight, secondary_axis=self.along, secondary="velocity")
        s = self.sites.sites[target]
        return PointingMode("ground", primary_axis=self.boresight, secondary_axis=self.along, secondary="velocity",
                            latitude=math.radians(s.lat_deg), longitude=math.radians(s.lon_deg), altitude=s.alt_m)

    def __call__(self, target: int):
        if target not in self._laws:
            if target == NADIR:
                law = law_of(self.mode(NADIR), self.geometry, 0.0, rot.IDENTITY)

                def motion(t, law=law):
                    ref = reference(law.attitude, t, REFERENCE_STEP_S)
                    return ref.q_RN, ref.omega_RN_R
                self._laws[target] = motion
            else:
                s = self.sites.sites[target]
                self._laws[target] = ground_motion(self.geometry, math.radians(s.lat_deg), math.radians(s.lon_deg),
                                                   s.alt_m, self.boresight, self.along, self._velocity)
        return self._laws[target]


class Planner:
    """The timeline's planner (module docstring) over ``windows`` of ``sites``."""

    def __init__(self, environment, spacecraft, sites: SiteSet, windows: AccessWindows, boresight_B,
                 limits: slews.Limits, zones=None, *, lookahead: int = LOOKAHEAD, dwell_s: float = DWELL_S,
                 settle_s: float = SETTLE_S):
        self.spacecraft, self.sites, self.windows, self.limits, self.zones = spacecraft, sites, windows, limits, zones
        along = along_track_axis(boresight_B, [] if zones is None else zones.sensor_axes)
        self.laws = Laws(environment, sites, boresight_B, along)
        self.pointing = Pointing(environment, SkyGeometry(environment, sites), boresight_B, along)
        self.lookahead, self.dwell_s, self.settle_s = lookahead, dwell_s, settle_s
        self.rollout_base = "ours"

    # -- the pieces --------------------------------------------------------------------------------
    def _held_margin(self, target: int, t0: float, t1: float) -> float:
        """The lowest zone clearance (rad) holding ``target``'s law over [t0, t1]."""
        if self.zones is None or not self.zones.zones or t1 <= t0:
            return math.inf
        law = self.laws(target)
        t = np.append(np.arange(t0, t1, ZONE_SAMPLE_S), t1)
        q = np.array([law(float(s))[0] for s in t])
        return float(self.zones.margins(t, q, true=True).min())

    def _slew(self, source: int, t0: float, target: int) -> slews.Slew | None:
        return slews.fastest(self.laws(source)(t0), t0, self.laws(target), self.limits)

    def _verified(self, slew: slews.Slew | None, source: int, target: int) -> Leg | str:
        """The slew verified onto ``target``'s law, or why it is refused."""
        if slew is None:
            return "no slew within the bounds"
        check = slews.verify(slew, self.spacecraft, self.laws(target), self.limits, self.zones)
        return Leg(target, slew, check) if check.refusal is None else check.refusal.split(" by ")[0] + (
            " (from nadir)" if source == NADIR else " (to nadir)" if target == NADIR else "")

    def _leg(self, source: int, t0: float, target: int) -> Leg | str:
        """The verified slew from ``source``'s law at ``t0`` onto ``target``'s, or why there is none."""
        return self._verified(self._slew(source, t0, target), source, target)

    def attempt(self, source: int, t: float, window: int):
        """The legs and the image of window ``window`` from ``source``'s law at ``t`` (module
        docstring), with the lowest zone clearance of the stretches held; why not when it fails."""
        site = int(self.windows.site[window])
        opening, closing = float(self.windows.open_s[window]), float(self.windows.close_s[window])
        legs, holds = [], []
        direct = self._slew(source, t, site)
        if direct is None:
            return "no slew within the bounds"
        wait = opening - self.settle_s - direct.arrival_s
        if wait <= 0.0:
            leg = self._verified(direct, source, site)
        elif wait <= HOLD_MAX_S:
            holds.append((source, t, t + wait))
            leg = self._leg(source, t + wait, site)
        else:
            first = self._leg(source, t, NADIR)
            if isinstance(first, str):
                return first
            legs.append(first)
            start = max(first.slew.arrival_s, opening - self.settle_s - direct.duration_s)
            leg = self._leg(NADIR, start, site)
            if not isinstance(leg, str):
                holds.append((NADIR, first.slew.arrival_s, leg.slew.t0_s))
        if isinstance(leg, str):
            return leg
        legs.append(leg)
        image_s = max(leg.slew.arrival_s + self.settle_s, opening)
        end = image_s + self.dwell_s
        if end > closing:
            return "the image ends after the window closes"
        holds.append((site, leg.slew.arrival_s, end))
        margin = min([self._held_margin(*h) for h in holds] + [g.check.min_zone_margin for g in legs])
        if not margin >= 0.0:
            return "a held stretch enters a zone"
        return legs, Image(site, window, image_s, self.dwell_s, leg.slew.arrival_s), margin

    def estimates(self, source: int, t: float, pending: np.ndarray, dcm: np.ndarray | None = None,
                  scale: float = 1.0) -> np.ndarray:
        """Estimated image times of the windows ``pending`` from ``source``'s law at ``t`` (or from the
        attitude ``dcm``), the rest-to-rest slew times scaled by ``scale``."""
        w = self.windows
        site, opening = w.site[pending], w.open_s[pending]
        if dcm is None:
            dcm = rot.dcm_NB(self.laws(source)(t)[0])
        arrival = np.maximum(opening - self.settle_s, t)
        axis, angle = rotation_between(dcm, self.pointing.dcm_NB(site, arrival))
        slew = rest_to_rest_time(self.spacecraft, axis, angle, self.limits.rate_max_rad_s, self.limits.momentum_max_Nms)
        return np.maximum(t + scale * slew + self.settle_s, opening)

    def _rollout(self, site: int, image_s: float, alive: np.ndarray, imaged: np.ndarray, until: float,
                 base: str) -> tuple[float, float]:
        """The score of imaging ``site`` at the estimate ``image_s`` and then following ``base`` on the
        scaled estimates until ``until`` (module docstring): (images less the sites lost for good,
        the time free at the end)."""
        w = self.windows
        alive, imaged = alive.copy(), imaged.copy()
        imaged[site] = True
        images, t, source = 1, image_s + self.dwell_s, site
        dcm = self.pointing.dcm_NB(np.array([site]), np.array([t]))[0]
        horizon = alive & (w.open_s < until)
        alive &= horizon
        while True:
            alive &= (w.close_s - self.dwell_s > t) & ~imaged[w.site]
            pending = np.flatnonzero(alive)[:self.lookahead]
            if not len(pending):
                break
            est = self.estimates(source, t, pending, dcm, ROLLOUT_SLEW_SCALE)
            fits = est + self.dwell_s <= w.close_s[pending]
            alive[pending[~fits]] = False
            pending, est = pending[fits], est[fits]
            if not len(pending):
                continue
            order = np.argsort(w.close_s[pending], kind="stable")
            if base == "ours":
                order = self._insertion(pending, est, order)
            k = order[0]
            if est[k] + self.dwell_s > until:
                break
            source, t = int(w.site[pending[k]]), float(est[k]) + self.dwell_s
            imaged[source] = True
            images += 1
            dcm = self.pointing.dcm_NB(np.array([source]), np.array([t]))[0]
        # the sites whose last window closed in the rollout without an image
        closed = horizon & (w.close_s - self.dwell_s <= t) & ~imaged[w.site]
        later = np.zeros(w.n_sites, bool)
        later[w.site[w.close_s - self.dwell_s > t]] = True
        lost = len(np.setdiff1d(np.unique(w.site[closed]), np.flatnonzero(later)))
        return images - ROLLOUT_LOST_WEIGHT * lost, t

    def _rollout_order(self, source: int, t: float, pending: np.ndarray, image_s: np.ndarray, order: np.ndarray,
                       alive: np.ndarray, imaged: np.ndarray) -> np.ndarray:
        """rollout's order (module docstring): the candidate with the best rollout score first (ties to
        the base's order), then the base's order."""
        w = self.windows
        scaled = self.estimates(source, t, pending, scale=ROLLOUT_SLEW_SCALE)
        candidates = list(dict.fromkeys([*order[:ROLLOUT_CANDIDATES].tolist(),
                                         *np.argsort(image_s, kind="stable")[:ROLLOUT_CANDIDATES].tolist()]))
        until = t + ROLLOUT_HORIZON_S
        best, best_score = None, None
        for k in candidates:
            if scaled[k] + self.dwell_s > w.close_s[pending[k]]:
                continue
            images, end = self._rollout(int(w.site[pending[k]]), float(scaled[k]), alive, imaged, until,
                                        self.rollout_base)
            score = (images, -end)
            if best_score is None or score > best_score:
                best, best_score = k, score
        if best is None:
            return order
        return np.concatenate([[best], order[order != best]])

    def _insertion(self, pending: np.ndarray, image_s: np.ndarray, order: np.ndarray) -> np.ndarray:
        """ours' order (module docstring): the earliest-finishing window (less :data:`PRIORITY_WEIGHT_S`
        per unit of priority) that leaves the earliest-closing one reachable on the estimates, then the
        earliest-closing order; the reachability of every window ahead in one batch."""
        w = self.windows
        first = int(order[0])
        rank = np.argsort(image_s - PRIORITY_WEIGHT_S * self.sites.priority[w.site[pending]], kind="stable")
        ahead = rank[:int(np.flatnonzero(rank == first)[0])]
        if not len(ahead):
            return order
        f = pending[first]
        free = image_s[ahead] + self.dwell_s
        dcm = self.pointing.dcm_NB(w.site[pending[ahead]], free)
        arrival = np.maximum(w.open_s[f] - self.settle_s, free)
        rel = np.einsum("mji,mjk->mik", dcm, self.pointing.dcm_NB(np.full(len(ahead), w.site[f]), arrival))
        axis, angle = rotation_between(np.eye(3), rel)
        slew = rest_to_rest_time(self.spacecraft, axis, angle, self.limits.rate_max_rad_s,
                                 self.limits.momentum_max_Nms)
        after = np.maximum(free + SLEW_SCALE * slew + self.settle_s, w.open_s[f])
        ok = np.flatnonzero(after + self.dwell_s <= w.close_s[f])
        if not len(ok):
            return order
        k = ahead[ok[0]]
        return np.concatenate([[k], order[order != k]])

    # -- the horizon -------------------------------------------------------------------------------
    def plan(self, policy: str) -> Timeline:
        """The timeline of ``policy`` (:data:`POLICIES`) over the windows' horizon."""
        if policy not in POLICIES:
            raise ValueError(f"policy: expected one of {', '.join(POLICIES)}; found {policy!r}")
        start = time.process_time()
        w = self.windows
        timeline = Timeline(policy)
        source, t = NADIR, w.t0_s
        timeline.worst_zone_margin = self._held_margin(NADIR, t, t)
        alive = np.ones(len(w), bool)
        imaged = np.zeros(w.n_sites, bool)
        while True:
            alive &= (w.close_s - self.dwell_s > t) & ~imaged[w.site]
            pending = np.flatnonzero(alive)[:self.lookahead]
            if not len(pending):
                break
            image_s = self.estimates(source, t, pending)
            fits = image_s + self.dwell_s <= w.close_s[pending]
            alive[pending[~fits]] = False
            pending, image_s = pending[fits], image_s[fits]
            if not len(pending):
                continue
            order = np.argsort(w.close_s[pending], kind="stable")
            if policy in ("ours", "rollout"):
                order = self._insertion(pending, image_s, order)
            if policy == "rollout":
                order = self._rollout_order(source, t, pending, image_s, order, alive, imaged)
            taken = None
            for k in order[:TRIES]:
                timeline.attempts += 1
                taken = self.attempt(source, t, int(pending[k]))
                if not isinstance(taken, str):
                    break
                timeline.failed += 1
                timeline.failures[taken] = timeline.failures.get(taken, 0) + 1
                alive[pending[k]] = False
            if isinstance(taken, str):
                continue
            legs, image, margin = taken
            timeline.legs.extend(legs)
            timeline.images.append(image)
            timeline.worst_zone_margin = min(timeline.worst_zone_margin, margin)
            imaged[image.site] = True
            source, t = image.site, image.time_s + image.dwell_s
        timeline.cpu_s = time.process_time() - start
        return timeline
