"""A day's observation order: which target next, when, and which cannot be observed.

The mission flies one slew at a time (each planned and verified by the planner among the moving
zones), so the order it follows is re-decided from where the spacecraft is, whenever a slew ends or
a target is lost. :class:`MissionScheduler` does that without ROS:

* each target's **visibility** over the mission's horizon: the spans in which its attitude keeps
  every zone of the scenario (Sun, Moon, Earth limb at their true positions, sampled every
  :data:`~att_planner.methods.schedule.order_search.VISIBILITY_STEP` s) by ``margin`` while some
  star tracker sees the sky clear of its exclusions (the slews start on a converged estimate, and the
  estimate converges on the trackers);
* each **leg**'s duration estimate: the rest-to-rest eigenaxis slew at the per-axis torque limit
  (bang-bang, ``2 sqrt(θ / α)``, α of :func:`att_planner.methods.axis_rotations.axis_acceleration`)
  times ``slew_factor`` (the smooth plans the planner returns take longer) plus ``lead`` (planning)
  and ``settle`` (the controller's hold on the final attitude before it reports the slew done);
* the **order**: the schedule planner's search (:func:`~att_planner.methods.schedule.order_search.
  orders_by_lower_bound` on the leg estimates, every order followed by :func:`~att_planner.methods.
  schedule.order_search.observed_prefix` with the dwells and the waits for visibility); the first order
  that observes every target before the horizon, else the longest observable prefix found (the rest
  left out of this order: a later decision, from elsewhere, may fit them). A target with no visible
  span as long as its dwell and the next slew's lead before the horizon is missed with the zone that
  covers it named.

A ground site (:mod:`att_planner.mission.ground`) moves: its attitude is the tracking law's at each
time. A slew to it ends on the law, its attitude and rate, and the dwell begins at the arrival
(``blend`` 0); or, for a spacecraft whose slews cannot reach a pass's line-of-sight rate (5-10
mrad/s against a large spacecraft's rate bound of a few mrad/s), at rest on the law's attitude, and
the controller blends into the law for ``blend`` s (:class:`att_planner.guidance.laws.BlendedLaw`)
before the dwell: a long blend that starts low, where the line of sight turns slowly. The site counts
as visible for an arrival when the law's attitude keeps the zones from the arrival to the dwell's end
and the site is trackable (high enough, its tracking within the torque) through the dwell (not the
trackers' sky: a pass lasts minutes, and the gyro carries the estimate through an outage; the next
slew still starts on a converged estimate). It is held for blend + dwell, its leg has no settle, the
leg away from it starts after the lead, held still; its legs are estimated as rest-to-rest slews to
where the law is when the site is next visible. The mission never parks at a site.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_msgs_py.types import Zone
from att_planner.methods.axis_rotations import axis_acceleration
from att_planner.methods.schedule.order_search import observed_prefix, orders_by_lower_bound, spans, visibility_grid
from att_planner.mission.ground import StripTrack
from att_planner.zones import FittedZones
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.ephemeris import Ephemeris

MAX_ORDERS = 5_000            # orders examined per decision (the search is best-first: the good ones come early)
HOLD_CHECK_STEP = 10.0        # s between the zone checks of an attitude held while waiting
SKY_PARKS = 64                # directions of the sky the spacecraft may park at besides its sources


@dataclass(frozen=True)
class MissionTarget:
    """A target of the mission: an inertial source held at ``attitude`` (its ``direction`` inertial),
    or a ground site followed along ``track`` (a :class:`~att_planner.mission.ground.GroundTrack`; a
    strip's :class:`~att_planner.mission.ground.StripTrack`, scanned from the arrival)."""

    name: str
    dwell: float
    attitude: np.ndarray | None = None
    direction: np.ndarray | None = None
    track: object = None

    @property
    def moving(self) -> bool:
        return self.track is not None

    def attitudes(self, t) -> np.ndarray:
        """The target's attitude at each time of ``t``, (K, 4)."""
        t = np.atleast_1d(np.asarray(t, float))
        return self.track.attitudes(t) if self.moving else np.broadcast_to(self.attitude, (t.size, 4))

    def observable(self, t) -> np.ndarray:
        """Whether the target's geometry allows observing it at each time of ``t`` (inertial: always)."""
        t = np.atleast_1d(np.asarray(t, float))
        return self.track.trackable(t) if self.moving else np.ones(t.size, bool)

    def direction_at(self, t: float) -> np.ndarray:
        """The inertial direction the sensor axis is put on at time ``t``."""
        return self.track.line_of_sight(t)[0] if self.moving else self.direction


@dataclass(frozen=True)
class Decision:
    """The order to fly from now: target names, their estimated arrivals (s of mission time), the
    targets that cannot be observed any more, with why, and those left out of this order (observable,
    but the order found could not fit them before the horizon; a later decision may)."""

    order: list
    arrivals: list
    missed: dict
    left_out: list = ()


def tracker_skies(scenario: scen.Scenario, sky: Ephemeris, window: float) -> list[FittedZones]:
    """Each star tracker's exclusions as keep-out zones of its boresight (the sensor frame's +z in
    the body), one :class:`FittedZones` per tracker."""
    out = []
    for spec in scenario.sensors.star_trackers:
        axis = rot.dcm_NB(spec.mounting) @ np.array([0.0, 0.0, 1.0])
        zones = [Zone(f"{spec.name}_{e.body}", e.body, axis, e.half_angle, False, e.direction) for e in spec.exclusions]
        if zones:
            out.append(FittedZones(zones, sky, window=window))
    return out


def sky_parks(sensor_axis, attitude_of, n: int = SKY_PARKS) -> dict:
    """``n`` park attitudes spread evenly over the sky (a Fibonacci lattice of boresight directions),
    named ``sky_00``...: where the spacecraft can wait when no source of the mission stays clear.
    ``attitude_of(sensor_axis, direction)`` makes each attitude as the mission's sources are made."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = math.pi * (1.0 + math.sqrt(5.0)) * k
    r = np.sqrt(1.0 - z * z)
    directions = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    width = len(str(n - 1))
    return {f"sky_{i:0{width}d}": MissionTarget(f"sky_{i:0{width}d}", 0.0, attitude_of(sensor_axis, d), d)
            for i, d in enumerate(directions)}


def slew_estimate(inertia: np.ndarray, torque_max: float, q_from, q_to, rate_max: float = math.inf) -> float:
    """Rest-to-rest eigenaxis slew time (s) at the per-axis torque limit: bang-bang, or
    bang-coast-bang when the eigenaxis rate reaches ``rate_max`` (per body axis, rad/s) first."""
    axis, angle = rot.to_axis_angle(rot.multiply(rot.conjugate(rot.normalize(np.asarray(q_from, float))),
                                                 rot.normalize(np.asarray(q_to, float))))
    if angle < 1e-12:
        return 0.0
    alpha = axis_acceleration(inertia, axis, angle, torque_max)
    w = rate_max / float(np.max(np.abs(axis)))                  # the eigenaxis rate that reaches the bound
    return 2.0 * math.sqrt(angle / alpha) if angle <= w * w / alpha else angle / w + w / alpha


class MissionScheduler:
    """Orders ``targets`` (name -> :class:`MissionTarget`) for ``scenario`` over ``[0, horizon]`` s of
    mission time (t = 0 at the scenario's epoch), keeping ``zones`` (default: the scenario's; module
    docstring). ``parks``: more attitudes (name -> inertial :class:`MissionTarget`, e.g. :func:`sky_parks`)
    the spacecraft may wait at besides the sources, never observed."""

    def __init__(self, scenario: scen.Scenario, targets: dict, horizon: float, *, zones: list | None = None,
                 margin: float = 0.0, slew_factor: float = 1.5, lead: float = 60.0, rate_max: float = math.inf,
                 settle: float = 0.0, blend: float = 0.0, parks: dict | None = None):
        if scenario.epoch is None:
            raise ValueError(f"scenario '{scenario.name}' has no epoch: a mission needs the real sky")
        self.scenario, self.horizon, self.targets = scenario, float(horizon), dict(targets)
        self.slew_factor, self.lead, self.rate_max = slew_factor, lead, rate_max
        self.settle, self.blend = settle, blend
        sky = Ephemeris(scenario.epoch, scenario.orbit_model)
        self.zones = FittedZones(list(scenario.zones if zones is None else zones), sky, window=self.horizon)
        self.trackers = tracker_skies(scenario, sky, self.horizon)
        self.grid = visibility_grid(0.0, self.horizon)
        self.visible = {k: self._site_spans(target, margin) if target.moving else
                        spans(self.grid, self._clear_samples(target, margin)) for k, target in self.targets.items()}
        self.park_targets = {k: p for k, p in (parks or {}).items() if k not in self.targets and not p.moving}
        self.visible.update({k: spans(self.grid, self._clear_samples(p, margin)) for k, p in self.park_targets.items()})

    def _clear_samples(self, target: MissionTarget, margin: float) -> np.ndarray:
        """Whether source ``target`` keeps the zones and a tracker sees the sky, at each time of the grid."""
        q = target.attitude
        return (self.zones.margins(self.grid, q, true=True).min(axis=1) >= margin) & self.tracked(q, self.grid)

    def _site_spans(self, target: MissionTarget, margin: float) -> list[tuple]:
        """A site's spans ``(a, b)`` (a strip's: the arrivals from which its scan is seen high enough, within
        the torque and keeping the zones at its start, middle and end, then ``b`` + its scan): a slew
        arriving at ``A`` in ``[a, b − blend − dwell]`` is followed
        by the blend into the site's law and the dwell, with the law's attitude clear of the zones from
        ``A`` to the dwell's end and the site trackable through the dwell (the blend starts where the
        site rises, its line of sight slow; so ``held`` = blend + dwell as for a source's dwell)."""
        t, held = self.grid, self.blend + target.dwell
        if isinstance(target.track, StripTrack):        # a strip: each arrival scans it from there
            ok = target.observable(t)
            for fraction in (0.0, 0.5, 1.0):            # the zones kept at the scan's start, middle and end
                at = t[ok] + fraction * target.dwell
                ok[ok] = self.zones.margins(at, target.track.scan_attitudes(t[ok], fraction),
                                            true=True).min(axis=1) >= margin
            return [(a, b + held) for a, b in spans(t, ok)]
        clear = self.zones.margins(t, target.attitudes(t), true=True).min(axis=1) >= margin
        trackable = target.observable(t) & clear
        out = []
        for za, zb in spans(t, clear):
            for ka, kb in spans(t, trackable):
                lo, hi = max(za, ka - self.blend), min(zb - held, kb - held)
                if lo <= hi:
                    out.append((lo, hi + held))
        return sorted(out)

    def tracked(self, q, t) -> np.ndarray:
        """Whether some star tracker sees the sky (clear of its exclusions) at attitude ``q`` (one, or
        one per time) at each time of ``t`` (all True without trackers)."""
        t = np.atleast_1d(np.asarray(t, float))
        if not self.trackers:
            return np.ones(t.shape, bool)
        return np.max([z.margins(t, np.asarray(q, float), true=True).min(axis=1) for z in self.trackers], axis=0) >= 0

    def slew(self, q_from, q_to, settle: bool = True) -> float:
        """Estimated duration (s) of a planned slew until the controller reports it done:
        :func:`slew_estimate` × ``slew_factor``, then (``settle``) ``settle`` on the final attitude."""
        sc = self.scenario.spacecraft
        return self.slew_factor * slew_estimate(sc.inertia, sc.body_torque_max, q_from, q_to, self.rate_max) \
            + (self.settle if settle else 0.0)

    def slew_to(self, name: str, q_from, t: float) -> float:
        """Estimated slew (s) from ``q_from`` to target ``name`` (a site: where its law is when it is
        next visible after ``t``; no settle: the controller hands over to the law)."""
        target = self.targets[name]
        return self.slew(q_from, self.attitude_near(name, t), settle=not target.moving)

    def attitude_near(self, name: str, t: float) -> np.ndarray:
        """Target ``name``'s attitude: a site's at the start of its first visible span after ``t``
        (at ``t`` when there is none)."""
        target = self.targets[name]
        if not target.moving:
            return target.attitude
        return target.attitudes(next((max(a, t) for a, b in self.visible[name] if b > t), t))[0]

    def leg(self, q_from, q_to) -> float:
        """Estimated duration (s) of a slew the mission flies: planning lead, then the plan."""
        return self.lead + self.slew(q_from, q_to)

    def covering_zone(self, name: str, t_now: float) -> str:
        """The zone that most often covers target ``name`` between ``t_now`` and the horizon."""
        target = self.targets[name]
        t = np.linspace(t_now, self.horizon, 200)
        t = t[target.observable(t)]
        if not t.size:
            return ""
        m = self.zones.margins(t, target.attitudes(t), true=True)
        worst = np.argmin(m, axis=1)[m.min(axis=1) < 0]
        if not worst.size:
            return ""
        return self.zones.names[int(np.bincount(worst).argmax())]

    def why_missed(self, name: str, t_now: float) -> str:
        """Why target ``name`` cannot be observed any more from ``t_now`` (its first slew after the lead)."""
        target, held = self.targets[name], f" (needs {self.held(name):g} s of visibility)"
        if target.moving:
            t = self.grid[self.grid >= t_now]
            if not target.observable(t).any():
                return (f"never {math.degrees(target.track.min_elevation):g} deg above its horizon with its "
                        f"tracking within the torque before the horizon{held}")
        zone = self.covering_zone(name, t_now)
        if zone:
            return f"a {zone} zone covers it until the horizon{held}"
        t_first = t_now + self.lead
        longest = max((b - max(a, t_first) for a, b in self.visible[name] if b > t_first), default=0.0)
        return (f"its visibility before the horizon lasts {longest:g} s at most" if longest > 0.0 else
                "no visibility left before the horizon") + held

    def held(self, name: str) -> float:
        """How long target ``name`` must stay visible once reached (s): a source its dwell, then the
        lead of the slew away from it (requested while the spacecraft still holds it); a site the
        controller's blend into its law, then its dwell (the spacecraft then holds still)."""
        target = self.targets[name]
        return self.blend + target.dwell if target.moving else target.dwell + self.lead

    def decide(self, t_now: float, q_now, remaining: list) -> Decision:
        """The order to fly from attitude ``q_now`` at mission time ``t_now`` through ``remaining``:
        each leg a slew estimate, the first after the lead from now, each target held visible for
        :meth:`held` (so the chain's arrivals are those of legs of :meth:`leg` after each dwell)."""
        missed, names = {}, []
        for k in remaining:
            if self.observable_from(k, t_now + self.lead) is None:
                missed[k] = self.why_missed(k, t_now)
            else:
                names.append(k)
        if not names:
            return Decision([], [], missed)
        nodes = [np.asarray(q_now, float)] + [self.attitude_near(k, t_now + self.lead) for k in names]
        moving = [False] + [self.targets[k].moving for k in names]
        n = len(names)
        C = np.zeros((n + 2, n + 2))                  # the end node: anywhere, at no cost
        for i in range(n + 1):
            for j in range(1, n + 1):
                if i != j:                            # away from a site: held still for the lead first
                    C[i, j] = self.slew(nodes[i], nodes[j], settle=not moving[j]) + (self.lead if moving[i] else 0.0)
        held = np.array([self.held(k) for k in names])
        t0 = t_now + self.lead                        # the first slew starts after the lead
        visible = [[(max(a, t0) - t0, b - t0) for a, b in self.visible[k] if b > t0] for k in names]
        best_prefix: tuple = ()
        for examined, (_, order) in enumerate(orders_by_lower_bound(C)):
            if examined >= MAX_ORDERS:
                break
            arrivals, _ = observed_prefix(C, order, held, visible)        # the end node costs nothing
            if len(arrivals) == n:
                return Decision([names[i] for i in order], list(t0 + arrivals), missed)
            if len(arrivals) > len(best_prefix[1] if best_prefix else ()):
                best_prefix = (tuple(order[:len(arrivals)]), tuple(arrivals))
        order, arrivals = best_prefix or ((), ())
        left_out = [names[i] for i in range(n) if i not in order]
        return Decision([names[i] for i in order], [t0 + a for a in arrivals], missed, left_out)

    def observable_from(self, name: str, t: float) -> float | None:
        """The earliest time ≥ ``t`` from which target ``name`` stays visible for :meth:`held` (None:
        not before the horizon)."""
        held = self.held(name)
        return next((max(a, t) for a, b in self.visible[name] if b - max(a, t) >= held), None)

    def clear(self, q, t0: float, t1: float) -> bool:
        """Whether attitude ``q`` keeps every zone (at their true positions, no margin) over ``[t0, t1]``
        (sampled every :data:`HOLD_CHECK_STEP` s and at both ends) and a star tracker sees the sky at
        ``t1`` (a slew starts on a converged estimate)."""
        return self.keeps_zones(q, t0, t1) and bool(self.tracked(q, t1)[0])

    def keeps_zones(self, q, t0: float, t1: float) -> bool:
        """Whether attitude ``q`` keeps every zone (true positions, no margin) over ``[t0, t1]``,
        sampled every :data:`HOLD_CHECK_STEP` s and at both ends."""
        t = np.unique(np.append(np.arange(t0, t1, HOLD_CHECK_STEP), t1))
        return bool(self.zones.margins(t, np.asarray(q, float), true=True).min() >= 0.0)

    def parks(self, q_from, t_now: float, until: float) -> list[str]:
        """Sources (observed or not; never a site) and the scheduler's other park attitudes to wait at
        from ``t_now`` until ``until``: reached by a leg from ``q_from`` and visible from their arrival
        to ``until``, the nearest first (one reached only at ``until`` or later is no place to wait)."""
        found = []
        for name, target in (self.targets | self.park_targets).items():
            if target.moving:
                continue
            arrive = t_now + self.leg(q_from, target.attitude)
            if arrive < until and any(a <= arrive and until <= b for a, b in self.visible[name]):
                found.append((arrive, name))
        return [name for _, name in sorted(found)]
