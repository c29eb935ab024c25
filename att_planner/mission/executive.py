"""The mission executive: what a day in orbit does next, decided from events, without ROS.

:class:`MissionExecutive` flies a mission's target list from its first state to the horizon. It is a state
machine: :meth:`MissionExecutive.on` takes one event (of :mod:`.executive_io`: :class:`Tick`, a state
heard at sim time ``t``; :class:`EstimateHealth`; the answer to one of its requests) and returns the
actions to take (:class:`Report` a mission event, :class:`Log`, :class:`WaitUntil` a sim time,
:class:`RequestPlan`, :class:`StartManeuver`, :class:`SetPointing`). Time comes in the events only:
there is no clock, thread or sleep inside. At most one thing is awaited at a time, a sim time or the
answer to the request carrying the pending ``request`` number; an answer with another number (late,
repeated, unknown) is ignored and kept in :attr:`MissionExecutive.ignored`, a state older than the
latest is ignored for the time and attitude. What the executive waits for now is :attr:`phase`.

The decisions, each from where the spacecraft holds at that moment:

1. :class:`~att_planner.mission.scheduler.MissionScheduler` decides the order (targets no zone leaves
   visible for their dwell before the horizon are missed, with the zone that covers them);
2. the first of the order's first three targets whose slew can wait for its start at the held
   attitude clear of the zones is planned ``start_lead`` s of sim time before its start (later when
   the target becomes visible later), planned again when it would arrive before the target is
   visible (three plans at most; a ground site: planned again while it would not arrive when the
   site is trackable, four plans at most);
3. when none can wait there, the spacecraft parks at a source, or at one of the scheduler's sky
   park attitudes (:func:`~att_planner.mission.scheduler.sky_parks`: directions spread over the
   sky, so that a mission of few sources still has somewhere clear to go), clear until the first
   one's start (the nearest three tried), or holds for
   :data:`~att_planner.mission.holds.RECOVERY_STEP` s, and decides again;
4. the controller flies the plan and holds the target for its dwell (a ground site: the plan ends
   on the site's law, its attitude and rate, and hands over to it; or it ends at rest on the law's
   attitude and the controller blends into the law first); then back to 1. A slew the planner or the
   controller refuses counts as an attempt at its target when the held attitude can start another
   slew: after :data:`MAX_ATTEMPTS` attempts the target is missed;
5. a held attitude that cannot start a slew (estimate not converged, a zone or the trackers' blind
   sky within the lead) is recovered: left for a park when a zone is about to cover it and the
   estimate is converged, else held until a slew can start (checked every
   :data:`~att_planner.mission.holds.RECOVERY_STEP` s,
   :data:`~att_planner.mission.holds.RECOVERY_LIMIT` s at most);
6. with no target left, the spacecraft holds until the horizon, leaving a zone's path by a park, and
   reports the end.
"""
from __future__ import annotations

import itertools
import math
from collections import Counter
from collections.abc import Callable

import numpy as np

from att_msgs_py.types import MissionEvent
from att_msgs_py.types import MissionEventKind as Kind
from att_planner.mission import executive_io as io
from att_planner.mission.holds import RECOVERY_STEP, Holds
from att_planner.mission.scheduler import MissionScheduler, sky_parks
from att_planner.mission.targets import CELESTIAL_NORTH, pointing_attitude

SITE_ARRIVAL_SLACK = 1.0       # s: a slew to a site must arrive within this of the site's visibility
SITE_DURATION_MATCH = 2.0      # s: a slew ending at rest on a site's law arrives within this of its aim
SLEW_FACTOR = 1.25             # planned slew / bang-coast-bang estimate (1.18 measured on the rate-bounded day)
MAX_ATTEMPTS = 2               # slews refused per target before it is missed
SOURCE_PLANS = 3               # plans of one slew to a source that arrive before it is visible, at most
SITE_PLANS = 4                 # plans of one slew to a ground site that do not fit its visibility, at most


class MissionExecutive(Holds):
    """The decisions of one mission (module docstring) over ``targets`` (name ->
    :class:`~att_planner.mission.scheduler.MissionTarget`) ordered by ``scheduler`` (what
    :class:`~att_planner.mission.scheduler.MissionScheduler` answers). ``settle``: the controller's
    hold on a plan's end before it reports it done (s); ``on_law``: slews to a ground site end on its
    law (its attitude and rate), else at rest on its attitude, the controller then blending into the law
    over ``blend`` s;
    ``converged``: the estimate's health before any :class:`~.executive_io.EstimateHealth` (True without
    an estimator)."""

    def __init__(self, scheduler, targets: dict, *, horizon: float, start_lead: float, time_budget: float,
                 settle: float, on_law: bool = True, blend: float = 0.0, sensor_axis_B=None,
                 pointing_tolerance: float = 0.0, frame_id: str = "", zone_names: tuple = (), converged: bool = False):
        self.scheduler, self.targets = scheduler, targets
        self.horizon, self.start_lead, self.time_budget = horizon, start_lead, time_budget
        self.settle, self.on_law, self.blend = settle, on_law, 0.0 if on_law else blend
        self.sensor_axis_B = np.zeros(3) if sensor_axis_B is None else np.asarray(sensor_axis_B, float)
        self.pointing_tolerance, self.frame_id, self.zone_names = pointing_tolerance, frame_id, tuple(zone_names)
        self.converged, self._health_t = converged, -math.inf
        self.t, self.q_BN = None, None                   # the latest state heard
        self.t_day, self.q_hold_BN, self.holding = None, None, False    # where the day's decisions stand
        self.remaining, self.observed, self.attempts = list(targets), 0, Counter()
        self.phase, self.done, self.ignored = "starting", False, []
        self._awaited: io.Awaited | None = None
        self.flown_mode: tuple | None = None             # (target, the mode its slew flown last hands over to)
        self._numbers = itertools.count(1)
        self._out: list = []

    @classmethod
    def of_mission(cls, mission, settle: float, converged: bool) -> MissionExecutive:
        """The executive of a :class:`~att_planner.mission.config.MissionConfig`, its scheduler as the
        mission file says (the controller's ``settle``; the estimate's health at the start)."""
        targets = mission.targets()
        on_law = mission.site_arrival == "on_law"
        blend = 0.0 if on_law else mission.handover_blend
        roll = getattr(mission.target_list, "roll_reference", CELESTIAL_NORTH)
        parks = sky_parks(mission.sensor_axis, lambda axis, d: pointing_attitude(axis, d, roll))
        scheduler = MissionScheduler(mission.scenario, targets, mission.horizon, zones=mission.zones,
                                     margin=mission.margin, lead=mission.start_lead, rate_max=mission.rate_max,
                                     slew_factor=SLEW_FACTOR, settle=settle, blend=blend, parks=parks)
        return cls(scheduler, targets, horizon=mission.horizon, start_lead=mission.start_lead,
                   time_budget=mission.time_budget, settle=settle, on_law=on_law, blend=blend,
                   sensor_axis_B=mission.sensor_axis, pointing_tolerance=mission.pointing_tolerance,
                   frame_id=mission.scenario.frame_id, zone_names=tuple(z.name for z in mission.zones),
                   converged=converged)

    def on(self, event: io.ExecutiveEvent) -> list:
        """Take ``event``; the actions to take, in order (:attr:`awaiting` the one to answer)."""
        self._out = []
        if self.done:
            self.ignored.append(event)
            return self._out
        if self.t is None or event.t >= self.t:
            self.t, self.q_BN = float(event.t), np.asarray(event.q_BN, float)
        if isinstance(event, io.EstimateHealth) and event.t >= self._health_t:
            self.converged, self._health_t = bool(event.converged), event.t
        awaited = self._awaited
        answer = awaited is not None and isinstance(event, awaited.answers) and event.request == awaited.action.request
        if isinstance(event, io.RESULTS) and not answer:
            self.ignored.append(event)
        if self.phase == "starting":
            if isinstance(event, io.Tick):
                self._begin()
        elif answer:
            self._awaited = None
            awaited.then(event)
        elif awaited is not None and isinstance(awaited.action, io.WaitUntil) and self.t >= awaited.action.t:
            self._awaited = None
            awaited.then()
        return self._out

    @property
    def awaiting(self):
        """The action whose answer the executive waits for (a :class:`~.executive_io.WaitUntil` or a
        request), None before the first state and after the end. An action list may hold waits that
        later events in the same delivery already satisfied: this one is what to answer."""
        return self._awaited.action if self._awaited is not None else None

    def _await_time(self, until: float, phase: str, then: Callable) -> None:
        assert self._awaited is None, "one thing awaited at a time"
        action = io.WaitUntil(until)
        self._awaited, self.phase = io.Awaited(action, then), phase
        self._out.append(action)

    def _request(self, make: Callable, phase: str, answers: tuple, then: Callable) -> None:
        assert self._awaited is None, "one thing awaited at a time"
        action = make(next(self._numbers))
        self._awaited, self.phase = io.Awaited(action, then, answers), phase
        self._out.append(action)

    def _report(self, kind: Kind, target: str = "", start: float = 0.0, end: float = 0.0, plan_id: str = "",
                message: str = "") -> None:
        q_BN, direction_N, pointing = np.array([0.0, 0.0, 0.0, 1.0]), np.zeros(3), None
        if target:
            at = start or self.t
            reported = self._target(target)
            q_BN, direction_N = reported.attitudes(at)[0], reported.direction_at(at)
            pointing = self._pointing_of(target, at) if reported.moving else None
        self._out.append(io.Report(MissionEvent(
            self.t, kind, target, start, end, q_BN, direction_N, self.sensor_axis_B if target else np.zeros(3),
            self.pointing_tolerance if target else 0.0, plan_id, message, self.frame_id, pointing, self.zone_names)))

    def _pointing_of(self, name: str, t: float):
        """Moving target ``name``'s pointing mode: the one its slew flown last hands over to (a strip's
        scan from that slew's arrival), else its track's for an arrival at ``t``."""
        flown = self.flown_mode
        return flown[1] if flown is not None and flown[0] == name else self.targets[name].track.mode_at(t)

    def _log(self, t: float, text: str) -> None:
        self._out.append(io.Log(t, text))

    # ---- the day (decisions 1-4 and 6) ----

    def _begin(self) -> None:
        self.t_day, self.q_hold_BN = self.t, self.q_BN
        self._next()

    def _next(self) -> None:
        """Decide again from where the spacecraft holds, or end the day."""
        if not (self.remaining and self.t_day < self.horizon):
            return self._finish()
        if not self.startable(self.q_hold_BN, self.t_day):
            return self._recover(self.q_hold_BN, self.t_day, math.inf, self._recovered)
        self._recovered((self.q_hold_BN, self.t_day))

    def _recovered(self, held: tuple) -> None:
        self.q_hold_BN, self.t_day = held
        if self.holding:
            return self._decide()

        def held_here(q_BN):               # the attitude the day starts at, held (not left to drift)
            self.q_hold_BN, self.holding = q_BN, True
            self._decide()
        self._hold(None, held_here)

    def _decide(self) -> None:
        t, q_hold_BN = self.t_day, self.q_hold_BN
        decision = self.scheduler.decide(t, q_hold_BN, self.remaining)
        for name, why in decision.missed.items():
            self._report(Kind.MISSED, name, message=why)
            self.remaining.remove(name)
        if not decision.order and not decision.left_out:
            return self._finish()
        if not decision.order:             # observable later, but no order fits from here now: decide again
            self._log(t, f"no order fits from t = {t:.0f} s for {', '.join(decision.left_out)}: holding "
                         f"{RECOVERY_STEP:g} s before deciding again")
            return self._await_time(t + RECOVERY_STEP, "holding", self._stepped)
        self._report(Kind.SCHEDULED, message="order " + ", ".join(
            f"{k} at {a:.0f} s" for k, a in zip(decision.order, decision.arrivals)))
        name, t_start = self.next_slew(decision, q_hold_BN, t)
        if name is not None:
            return self._await_time(t_start - self.start_lead, "waiting", lambda: self._slew(name, t_start))

        def parked(result):                # the held attitude cannot wait: park, then decide again
            if result is not None:
                self.q_hold_BN, self.t_day = result
                return self._next()
            self._log(t, f"no source to park at until t = {t_start:.0f} s: holding")
            self._await_time(t + RECOVERY_STEP, "holding", self._stepped)
        self._park(q_hold_BN, t, t_start, None, None, parked)

    def _stepped(self) -> None:
        self.t_day = self.t
        self._next()

    def next_slew(self, decision, q_hold_BN, t: float) -> tuple:
        """The first of the decided order's first three targets whose slew can wait for its start at
        ``q_hold_BN`` clear of the zones: (name, start) or (None, the first target's start)."""
        first = None
        for name, arrival in list(zip(decision.order, decision.arrivals))[:3]:
            start = max(t + self.start_lead, arrival - self.scheduler.slew_to(name, q_hold_BN, arrival))
            first = start if first is None else first
            if self.scheduler.clear(q_hold_BN, t, start):
                return name, start
        return None, first

    def _slew(self, name: str, t_start: float) -> None:
        self.t_day = self.t
        t_start = max(t_start, self.t_day + self.start_lead)
        if self.targets[name].moving:
            return self._fly_to_site(name, self.q_hold_BN, t_start, lambda end: self._arrived(name, end))
        self._fly(name, self.q_hold_BN, t_start, True, None, lambda end: self._arrived(name, end))

    def _arrived(self, name: str, end: float | None) -> None:
        target = self.targets[name]
        if end is None:
            self.q_hold_BN, self.t_day = self.q_BN, self.t
            if self.startable(self.q_hold_BN, self.t_day):     # the slew itself was refused: the target's count
                self.count_attempt(name)
            return self._next()
        start = self.scheduler.observable_from(name, end)
        if start is None or (start > end + SITE_ARRIVAL_SLACK if target.moving
                             else not self.scheduler.clear(target.attitude, end, start)):
            self._report(Kind.REFUSED, name, message="arrived too late for this visibility window: deciding again")
            self.count_attempt(name)

            def held(q_BN):
                self.q_hold_BN, self.t_day = q_BN, self.t
                self._next()
            return self._hold(name, held)
        if target.moving:                              # on the site's law from the arrival, or after the blend
            return self._dwell(name, end + self.blend)
        self._hold(name, lambda _q_BN: self._dwell(name, start))

    def _dwell(self, name: str, start: float) -> None:
        target = self.targets[name]
        self._report(Kind.DWELL, name, start, start + target.dwell, message=f"observing for {target.dwell:g} s")

        def observed(q_BN):
            self.q_hold_BN = q_BN
            self.remaining.remove(name)
            self.observed += 1
            self._next()

        def dwelt():
            self.t_day = self.t
            if target.moving:
                return self._hold(name, observed)
            observed(target.attitude)
        self._await_time(start + target.dwell, "dwelling", dwelt)

    def count_attempt(self, name: str) -> None:
        """One more failed attempt at target ``name``: missed after :data:`MAX_ATTEMPTS`."""
        self.attempts[name] += 1
        if self.attempts[name] >= MAX_ATTEMPTS:
            self.remaining.remove(name)
            self._report(Kind.MISSED, name, message=f"{MAX_ATTEMPTS} attempts at it failed (above)")

    def _finish(self) -> None:
        for name in self.remaining:
            self._report(Kind.MISSED, name, message=f"not reached before the mission ended (horizon "
                                                    f"{self.horizon:g} s)")
        self._hold_until(self.q_hold_BN, self.t_day, self.horizon, self._ended)

    def _ended(self) -> None:
        self._report(Kind.ENDED, message=f"{self.observed} targets held for their dwell, "
                                         f"{len(self.targets) - self.observed} missed or not reached at "
                                         f"t = {self.t:.0f} s")
        self.phase, self.done = "ended", True

    def _target(self, name: str):
        """Target ``name`` of the mission, or a park attitude of the scheduler's (never observed)."""
        return self.targets[name] if name in self.targets else self.scheduler.park_targets[name]

    def startable(self, q_hold_BN, t: float) -> bool:
        """Whether a slew can start from ``q_hold_BN`` soon after ``t``: the attitude clear of every
        zone until ``start_lead`` from now and the estimate converged."""
        return self.converged and self.scheduler.clear(q_hold_BN, t, t + self.start_lead)

    def _plan(self, name: str, q_from_BN, q_to_BN, t_start: float, budget: float | None, then: Callable,
              end_pointing=None) -> None:
        """Ask for the plan (ending on ``end_pointing`` when given); ``then`` its :class:`PlanReturned`,
        or None after a refusal (reported)."""
        def answered(event):
            if isinstance(event, io.PlanRefused):
                self._report(Kind.REFUSED, name, message=f"planner: code {event.code}: {event.message}")
                return then(None)
            then(event)
        budget = budget or self.time_budget
        self._request(lambda number: io.RequestPlan(number, name, q_from_BN, q_to_BN, t_start, budget, end_pointing),
                      "planning", (io.PlanReturned, io.PlanRefused), answered)

    def _fly(self, name: str, q_from_BN, t_start: float, wait_for_visibility: bool, budget: float | None,
             then: Callable) -> None:
        """Plan the slew to source ``name`` from ``q_from_BN`` starting at ``t_start`` and fly it;
        ``then`` its end time, or None after a refusal (none while the estimate is not converged). A
        plan that would arrive before the target is visible for its dwell (``wait_for_visibility``)
        is planned again to arrive then."""
        q_to_BN = self._target(name).attitude
        if not self.converged:
            return then(None)
        plans = 0

        def planned(plan):
            nonlocal plans, t_start
            if plan is None:
                return then(None)
            plans += 1
            arrival = t_start + plan.duration + self.settle          # the controller reports it done then
            visible = self.scheduler.observable_from(name, arrival) if wait_for_visibility else arrival
            if visible is None:
                self._report(Kind.REFUSED, name, message=f"the slew would arrive at {arrival:.0f} s, after the "
                                                         "target's last visibility before the horizon")
                return then(None)
            if visible <= arrival + 1.0:
                return self._execute(name, plan, t_start, None, then)
            if plans == SOURCE_PLANS:
                self._report(Kind.REFUSED, name, message=f"three slews arrived before the target is visible "
                                                         f"at {visible:.0f} s")
                return then(None)
            t_start = visible - plan.duration - self.settle
            self._plan(name, q_from_BN, q_to_BN, t_start, budget, planned)
        self._plan(name, q_from_BN, q_to_BN, t_start, budget, planned)

    def _fly_to_site(self, name: str, q_from_BN, t_start: float, then: Callable) -> None:
        """Plan a slew from ``q_from_BN``, starting at ``t_start`` or later, that reaches ground site
        ``name`` when it is trackable for its dwell, and fly it, handing over to the site's pointing mode;
        ``then`` the arrival time, or None.

        The arrival aimed at first is the site's first visibility after ``t_start`` plus the scheduler's
        slew estimate, the start that estimate before it. With :attr:`on_law` the plan ends on the
        site's law (its attitude and rate) and fits when it arrives while the site is trackable (within
        :data:`SITE_ARRIVAL_SLACK` s); else it ends at rest on the law's attitude at the aim and fits when
        it arrives within :data:`SITE_DURATION_MATCH` s of it. A plan that does not fit is planned again,
        aimed at the first visibility a slew of its duration reaches from ``t_start`` (half the slack
        into it on the law), :data:`SITE_PLANS` plans at most."""
        target = self.targets[name]
        if not self.converged:
            return then(None)
        guess = self.scheduler.slew_to(name, q_from_BN, t_start)
        aim = self.scheduler.observable_from(name, t_start + guess)
        if aim is None:
            self._report(Kind.REFUSED, name, message="the slew cannot arrive before the site's last "
                                                     "visibility before the horizon")
            return then(None)
        plans = 0

        def attempt():
            start = max(t_start, aim - guess)
            self._plan(name, q_from_BN, target.attitudes(aim)[0], start, None, lambda plan: planned(plan, start),
                       end_pointing=target.track.mode_at(aim) if self.on_law else None)

        def planned(plan, start: float):
            nonlocal plans
            if plan is None:
                return then(None)
            plans += 1
            arrival = start + plan.duration
            if self.on_law:
                visible = self.scheduler.observable_from(name, arrival)
                fits = visible is not None and visible <= arrival + SITE_ARRIVAL_SLACK
            else:
                fits = abs(arrival - aim) <= SITE_DURATION_MATCH
            if not fits:
                return replan(plan, arrival)
            after = plan.pointing_after or target.track.mode_at(arrival)     # a strip's: from the arrival
            if not self.on_law:
                return self._execute(name, plan, start, after, then)
            # on the law from the plan's end, whichever later step reports it: the dwell starts there
            self._execute(name, plan, start, after, lambda end: then(None if end is None else arrival))

        def replan(plan, arrival: float):
            nonlocal aim, guess
            earliest = self.scheduler.observable_from(name, t_start + plan.duration)
            if earliest is None:
                self._report(Kind.REFUSED, name, message=f"a slew of {plan.duration:.0f} s from {t_start:.0f} s or "
                                                         "later cannot arrive before the site's last visibility "
                                                         "before the horizon")
                return then(None)
            if plans == SITE_PLANS:
                self._report(Kind.REFUSED, name, message=f"{SITE_PLANS} plans did not fit the site's visibility "
                                                         f"(the last arrived at {arrival:.0f} s)")
                return then(None)
            aim, guess = earliest + (SITE_ARRIVAL_SLACK / 2.0 if self.on_law else 0.0), plan.duration
            attempt()
        attempt()

    def _execute(self, name: str, plan: io.PlanReturned, t_start: float, pointing_after, then: Callable) -> None:
        """Fly ``plan`` from ``t_start`` (``pointing_after``: the mode the controller hands over to at
        its end); ``then`` the time the controller reports it done, or None after a refusal."""
        late = self.t - t_start
        if late > 0:            # never flown: no slew event (a slew event is a slew started)
            self._report(Kind.REFUSED, name, plan_id=plan.plan_id,
                         message=f"planning ended {late:.1f} s of sim time after the slew's start ({plan.method}, "
                                 f"planned in {plan.solve_seconds:.2f} s): start_lead is too short")
            return then(None)
        if pointing_after is not None:
            self.flown_mode = (name, pointing_after)
        self._report(Kind.SLEW, name, t_start, t_start + plan.duration, plan.plan_id,
                     f"{plan.method} {plan.duration:.1f} s, {math.degrees(plan.min_cone_margin):.2f} deg "
                     f"from the zones, planned in {plan.solve_seconds:.2f} s")

        def flown(event):
            if not event.success:
                self._report(Kind.REFUSED, name, plan_id=plan.plan_id,
                             message=f"controller: code {event.code}: {event.message}")
                return then(None)
            then(self.t)

        def start():
            self._request(lambda number: io.StartManeuver(number, plan.plan_id, plan.duration, pointing_after),
                          "slewing", (io.ManeuverEnded,), flown)
        self._await_time(t_start, "waiting", start)
