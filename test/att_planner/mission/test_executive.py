"""The mission executive without ROS: each decision (the order flown, re-plans for visibility, retry
counts, holds, parks, recovery, the end) driven by scripted events from a toy world (a scheduler whose
answers the test sets, a planner and a controller answering as the test says), every time and count
checked against what the test computes from its own numbers; hostile events (repeated, unknown,
out of order, of the wrong kind, after the end) change nothing."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import MissionEventKind as Kind
from att_msgs_py.types import PointingMode
from att_planner.mission import executive as exe
from att_planner.mission import executive_io as io
from att_planner.mission import holds
from att_planner.mission.scheduler import Decision, MissionTarget

IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])
LEAD, SETTLE, BLEND, BUDGET = 100.0, 10.0, 30.0, 5.0


def q_about_z(angle_deg: float) -> np.ndarray:
    half = math.radians(angle_deg) / 2.0
    return np.array([0.0, 0.0, math.sin(half), math.cos(half)])


def source(name: str, angle_deg: float, dwell: float = 60.0) -> MissionTarget:
    return MissionTarget(name, dwell, q_about_z(angle_deg), np.array([1.0, 0.0, 0.0]))


class Scheduler:
    """The scheduler's answers as the test sets them: the order in ``arrivals`` (name -> arrival),
    visibility from ``visible`` (name -> first time, None: never), ``clear``/``keeps`` as functions
    of (q, t0, t1), ``parks`` the park sources, every slew ``slew`` s."""

    def __init__(self, arrivals: dict, visible=None, clear=None, keeps=None, parks=(), slew=60.0, missed=None,
                 park_targets=None, no_order_before=-math.inf):
        self.arrivals, self.visible, self.no_order_before = arrivals, visible or {}, no_order_before
        self.park_targets = {t.name: t for t in park_targets or ()}        # parks that are not mission targets
        self.clear_fn, self.keeps_fn = clear or (lambda q, t0, t1: True), keeps or (lambda q, t0, t1: True)
        self.park_names, self.slew, self.missed = list(parks), slew, dict(missed or {})
        self.decisions = []

    def decide(self, t, q, remaining):
        self.decisions.append((t, list(remaining)))
        missed = {k: v for k, v in self.missed.items() if k in remaining}
        order = [k for k in self.arrivals if k in remaining and k not in missed]
        if t < self.no_order_before:                   # observable, but no order fits yet
            return Decision([], [], missed, order)
        return Decision(order, [max(self.arrivals[k], t + LEAD) for k in order], missed)

    def observable_from(self, name, t):
        first = self.visible.get(name, 0.0)
        return None if first is None else (first(t) if callable(first) else max(first, t))

    def clear(self, q, t0, t1):
        return self.clear_fn(q, t0, t1)

    def keeps_zones(self, q, t0, t1):
        return self.keeps_fn(q, t0, t1)

    def parks(self, q, t, until):
        return list(self.park_names)

    def slew_to(self, name, q, t):
        return self.slew


class World:
    """Answers the executive's actions: sim time jumps to each wait's end, a plan takes
    ``plan_seconds`` of sim time and lasts ``duration(action)`` s (refused when ``refuse_plan(action)``),
    a maneuver ends ``duration + SETTLE`` s after its start at the plan's goal (``duration`` s with a
    mode to hand over to; refused when ``refuse_maneuver(action)``), a hold is refused while
    ``refuse_hold(t)``."""

    def __init__(self, executive, duration=lambda a: 50.0, plan_seconds=0.0, refuse_plan=lambda a: False,
                 refuse_maneuver=lambda a: False, refuse_hold=lambda t: False, health=(), after=lambda a, d: None):
        self.ex, self.duration, self.plan_seconds, self.after = executive, duration, plan_seconds, after
        self.refuse_plan, self.refuse_maneuver, self.refuse_hold = refuse_plan, refuse_maneuver, refuse_hold
        self.health = sorted(health)            # (sim time, converged) changes of the estimate
        self.t, self.q_BN, self.goals = 0.0, IDENTITY, {}
        self.actions, self.plans = [], []

    def deliver(self, event) -> list:
        out = []
        while self.health and self.health[0][0] <= event.t:
            at, converged = self.health.pop(0)
            out += self.ex.on(io.EstimateHealth(t=event.t, q_BN=self.q_BN, converged=converged))
        return out + self.ex.on(event)

    def answer(self, action):
        if isinstance(action, io.WaitUntil):
            self.t = max(self.t, action.t)
            return io.Tick(t=self.t, q_BN=self.q_BN)
        if isinstance(action, io.RequestPlan):
            self.plans.append(action)
            self.t += self.plan_seconds
            if self.refuse_plan(action):
                return io.PlanRefused(t=self.t, q_BN=self.q_BN, request=action.request, code=7, message="no path")
            plan_id = f"p{len(self.plans)}"
            self.goals[plan_id] = action.q_to_BN
            duration = self.duration(action)
            return io.PlanReturned(t=self.t, q_BN=self.q_BN, request=action.request, plan_id=plan_id,
                                   duration=duration, method="toy", solve_seconds=0.5,
                                   min_cone_margin=math.radians(3.0), pointing_after=self.after(action, duration))
        if isinstance(action, io.StartManeuver):
            if self.refuse_maneuver(action):
                return io.ManeuverEnded(t=self.t, q_BN=self.q_BN, request=action.request, success=False, code=4,
                                        message="aborted")
            self.t += action.duration + (SETTLE if action.pointing_after is None else 0.0)
            self.q_BN = self.goals[action.plan_id]
            return io.ManeuverEnded(t=self.t, q_BN=self.q_BN, request=action.request, success=True)
        if isinstance(action, io.SetPointing):
            ok = not self.refuse_hold(self.t)
            return io.PointingSet(t=self.t, q_BN=self.q_BN, request=action.request, success=ok,
                                  code=0 if ok else 9, message="" if ok else "estimate not converged")
        return None

    def run(self, limit: int = 20_000):
        actions = self.deliver(io.Tick(t=self.t, q_BN=self.q_BN))
        for _ in range(limit):
            self.actions += actions
            if self.ex.done:
                return self
            assert self.ex.awaiting in actions or any(isinstance(a, io.WaitUntil) for a in actions)
            actions = self.deliver(self.answer(self.ex.awaiting))
        raise AssertionError("the day did not end")

    def reports(self, kind=None):
        return [a.event for a in self.actions if isinstance(a, io.Report) and kind in (None, a.event.event)]

    def logs(self):
        return [a.text for a in self.actions if isinstance(a, io.Log)]


def executive(scheduler, targets, horizon=3000.0, converged=True, on_law=True):
    return exe.MissionExecutive(scheduler, {t.name: t for t in targets}, horizon=horizon, start_lead=LEAD,
                                time_budget=BUDGET, settle=SETTLE, on_law=on_law, blend=BLEND,
                                sensor_axis_B=[0.0, 1.0, 0.0], pointing_tolerance=1e-3, frame_id="eci",
                                zone_names=("sun",), converged=converged)


def test_a_day_of_two_sources_slews_dwells_holds_to_the_horizon_and_ends():
    a, b = source("a", 30.0, dwell=60.0), source("b", -45.0, dwell=90.0)
    ex = executive(Scheduler({"a": 300.0, "b": 900.0}), [a, b], horizon=2000.0)
    world = World(ex).run()
    # a: start = arrival - slew (300 - 60), requested a lead before; arrives at start + 50 + settle
    t_a = 300.0 - 60.0
    end_a = t_a + 50.0 + SETTLE
    # b: decided at a's dwell's end; its start is its arrival - slew, later than a lead from then
    t_b = max(900.0 - 60.0, end_a + 60.0 + LEAD)
    end_b = t_b + 50.0 + SETTLE
    kinds = [(e.event, e.target) for e in world.reports()]
    assert kinds == [(Kind.SCHEDULED, ""), (Kind.SLEW, "a"), (Kind.DWELL, "a"), (Kind.SCHEDULED, ""),
                     (Kind.SLEW, "b"), (Kind.DWELL, "b"), (Kind.ENDED, "")]
    slews, dwells = world.reports(Kind.SLEW), world.reports(Kind.DWELL)
    assert [(e.start, e.end) for e in slews] == [(t_a, t_a + 50.0), (t_b, t_b + 50.0)]
    assert [(e.start, e.end) for e in dwells] == [(end_a, end_a + 60.0), (end_b, end_b + 90.0)]
    assert [p.t_start for p in world.plans] == [t_a, t_b] and all(p.time_budget == BUDGET for p in world.plans)
    assert np.array_equal(world.plans[1].q_from_BN, a.attitude) and np.array_equal(world.plans[1].q_to_BN, b.attitude)
    # the first hold is the attitude of the moment, then each source's own attitude
    holds = [x for x in world.actions if isinstance(x, io.SetPointing)]
    assert holds[0].q_BN is None and [h.q_BN.tolist() for h in holds[1:]] == [a.attitude.tolist(), b.attitude.tolist()]
    # held until the horizon in steps, then the end
    waits = [x.t for x in world.actions if isinstance(x, io.WaitUntil)]
    t_done = end_b + 90.0
    steps = math.ceil((2000.0 - t_done) / exe.RECOVERY_STEP)
    assert waits[-steps:] == [min(2000.0, t_done + k * exe.RECOVERY_STEP) for k in range(1, steps + 1)]
    ended = world.reports(Kind.ENDED)[0]
    assert ended.t == 2000.0 and ended.message.startswith("2 targets held") and ex.phase == "ended"
    # the events carry the target's attitude and direction, the sensor axis, tolerance and zones
    assert np.array_equal(dwells[0].attitude, a.attitude) and np.array_equal(dwells[0].sensor_axis, [0, 1, 0])
    assert dwells[0].tolerance == 1e-3 and dwells[0].zones == ("sun",) and dwells[0].frame_id == "eci"
    assert ex.remaining == [] and ex.observed == 2


def test_a_refused_slew_is_tried_again_and_the_target_missed_after_max_attempts():
    a, b = source("a", 30.0), source("b", 60.0)
    ex = executive(Scheduler({"a": 300.0, "b": 1500.0}), [a, b])
    world = World(ex, refuse_plan=lambda action: action.target == "a").run()
    refused = [e for e in world.reports(Kind.REFUSED) if e.target == "a"]
    assert len(refused) == exe.MAX_ATTEMPTS and all("planner: code 7" in e.message for e in refused)
    assert sum(p.target == "a" for p in world.plans) == exe.MAX_ATTEMPTS
    missed = world.reports(Kind.MISSED)
    assert [e.target for e in missed] == ["a"] and f"{exe.MAX_ATTEMPTS} attempts" in missed[0].message
    assert [e.target for e in world.reports(Kind.DWELL)] == ["b"] and ex.attempts["a"] == exe.MAX_ATTEMPTS
    # the controller refusing the maneuver counts the same way, with its code
    ex = executive(Scheduler({"a": 300.0}), [a])
    world = World(ex, refuse_maneuver=lambda action: True).run()
    refused = world.reports(Kind.REFUSED)
    assert len(refused) == exe.MAX_ATTEMPTS and all(e.message == "controller: code 4: aborted" for e in refused)
    assert [e.plan_id for e in refused] == ["p1", "p2"] and len(world.reports(Kind.SLEW)) == exe.MAX_ATTEMPTS


def test_a_slew_that_would_arrive_early_is_planned_again_to_arrive_when_the_source_is_visible():
    a = source("a", 30.0)
    ex = executive(Scheduler({"a": 300.0}, visible={"a": 700.0}), [a])
    world = World(ex).run()
    t_first = 300.0 - 60.0
    assert [p.t_start for p in world.plans] == [t_first, 700.0 - 50.0 - SETTLE]
    assert world.reports(Kind.DWELL)[0].start == 700.0
    # a visibility that keeps moving away: three plans, then refused
    ex = executive(Scheduler({"a": 300.0}, visible={"a": lambda t: t + 500.0}), [a])
    world = World(ex).run()
    assert sum(p.target == "a" for p in world.plans) == exe.MAX_ATTEMPTS * exe.SOURCE_PLANS
    assert sum("three slews arrived before" in e.message for e in world.reports(Kind.REFUSED)) == exe.MAX_ATTEMPTS
    assert not world.reports(Kind.SLEW) and world.reports(Kind.MISSED)[0].target == "a"


def test_a_plan_back_after_its_start_is_refused_without_a_slew():
    a = source("a", 30.0)
    ex = executive(Scheduler({"a": 300.0}), [a])
    world = World(ex, plan_seconds=LEAD + 12.5).run()
    refused = world.reports(Kind.REFUSED)
    assert len(refused) == exe.MAX_ATTEMPTS and not world.reports(Kind.SLEW)
    assert refused[0].plan_id == "p1" and "planning ended 12.5 s of sim time after" in refused[0].message
    assert not any(isinstance(x, io.StartManeuver) for x in world.actions)


def test_a_source_that_arrives_too_late_for_its_window_counts_an_attempt_and_is_held():
    a = source("a", 30.0)

    def clear(q, t0, t1):               # the source's attitude is covered at its arrival, clear over any span
        return not np.array_equal(q, a.attitude) or t1 > t0
    ex = executive(Scheduler({"a": 300.0}, clear=clear), [a])
    world = World(ex).run()
    too_late = "arrived too late for this visibility window: deciding again"
    assert [e.message for e in world.reports(Kind.REFUSED)] == [too_late] * exe.MAX_ATTEMPTS
    assert len(world.reports(Kind.SLEW)) == exe.MAX_ATTEMPTS and not world.reports(Kind.DWELL)
    assert [e.target for e in world.reports(Kind.MISSED)] == ["a"]
    holds = [x.q_BN for x in world.actions if isinstance(x, io.SetPointing)]
    assert holds[0] is None and all(np.array_equal(h, a.attitude) for h in holds[1:]) and len(holds) == 3
    # the second slew starts from the source's attitude held after the first
    assert np.array_equal(world.plans[1].q_from_BN, a.attitude)


def test_a_held_attitude_that_cannot_wait_parks_at_a_source_then_decides_again():
    a, p = source("a", 30.0), source("p", 90.0)

    def clear(q, t0, t1):               # the start attitude is covered from t = 150 s on; the park source never
        return not (np.array_equal(q, IDENTITY) and t1 > 150.0)
    ex = executive(Scheduler({"a": 600.0}, clear=clear, parks=["p"]), [a, p])       # p: a park only
    world = World(ex).run()
    park = world.reports(Kind.PARK)[0]
    # decided at t = 0: a's start (600 - 60) cannot be waited for at the start attitude; the park slew
    # starts a lead later and arrives after its duration and settle, to wait there until a's start
    assert world.plans[0].target == "p" and world.plans[0].t_start == LEAD
    assert (park.target, park.start, park.end) == ("p", LEAD + 50.0 + SETTLE, 600.0 - 60.0)
    assert park.message == "waiting at p until t = 540 s"
    assert world.plans[1].target == "a" and np.array_equal(world.plans[1].q_from_BN, p.attitude)
    assert world.plans[1].t_start == 540.0
    assert [e.target for e in world.reports(Kind.DWELL)] == ["a"]
    assert [(e.target, "not reached" in e.message) for e in world.reports(Kind.MISSED)] == [("p", True)]


def test_a_park_of_the_scheduler_s_sky_is_flown_held_and_never_counted_as_a_target():
    """A park attitude the scheduler offers that is not a mission target (a sky park): planned to its
    attitude, reported as the park, and neither observed nor missed."""
    a, sky = source("a", 30.0), source("sky_07", 120.0, dwell=0.0)

    def clear(q, t0, t1):
        return not (np.array_equal(q, IDENTITY) and t1 > 150.0)
    ex = executive(Scheduler({"a": 600.0}, clear=clear, parks=["sky_07"], park_targets=[sky]), [a])
    world = World(ex).run()
    park = world.reports(Kind.PARK)[0]
    assert world.plans[0].target == "sky_07" and np.array_equal(world.plans[0].q_to_BN, sky.attitude)
    assert park.target == "sky_07" and np.array_equal(park.attitude, sky.attitude)
    assert np.array_equal(world.plans[1].q_from_BN, sky.attitude) and world.plans[1].target == "a"
    assert [e.target for e in world.reports(Kind.DWELL)] == ["a"] and not world.reports(Kind.MISSED)
    assert ex.observed == 1


def test_an_estimate_not_converged_is_waited_for_before_any_slew():
    a = source("a", 30.0)
    converged_at = 437.0
    ex = executive(Scheduler({"a": 300.0}), [a], converged=False)
    world = World(ex, health=[(converged_at, True)]).run()
    assert world.logs()[0] == "holding: the estimate is not converged"
    # checked every step from t = 0: the first check at or after the change lets the day go on
    first_check = math.ceil(converged_at / exe.RECOVERY_STEP) * exe.RECOVERY_STEP
    assert world.plans[0].t_start == max(300.0 - 60.0, first_check + LEAD)
    assert world.ex.converged and [e.target for e in world.reports(Kind.DWELL)] == ["a"]


def test_recovery_gives_up_after_its_limit_and_the_day_still_ends():
    a = source("a", 30.0)
    ex = executive(Scheduler({"a": 300.0}), [a], horizon=2500.0, converged=False)
    world = World(ex).run()
    waits = [x.t for x in world.actions if isinstance(x, io.WaitUntil)]
    # one recovery: a check every step up to the limit; then the hold, the decision and the wait for
    # the slew's request (a's start: a lead and its slew after the decision), whose slew cannot start
    checks = round(holds.RECOVERY_LIMIT / exe.RECOVERY_STEP)
    assert waits[:checks] == [exe.RECOVERY_STEP * k for k in range(1, checks + 1)]
    assert waits[checks] == max(300.0 - 60.0, holds.RECOVERY_LIMIT + LEAD) - LEAD
    assert world.logs()[:2] == ["holding: the estimate is not converged"] * 2
    assert not world.plans and world.reports()[-1].event == Kind.ENDED


def test_a_ground_site_is_flown_onto_its_law_dwelt_from_the_arrival_and_its_hold_asked_again():
    site = MissionTarget("site", 120.0, track=Site())
    visible_from = 800.0
    ex = executive(Scheduler({"site": 800.0}, visible={"site": visible_from}), [site], horizon=3000.0)
    refused_until = 1025.0              # the hold after the dwell (which ends at 919 s) is refused until then
    world = World(ex, duration=lambda action: 59.0, refuse_hold=lambda t: 900.0 < t < refused_until).run()
    (plan,) = world.plans
    # start = visibility - slew estimate, ending on the site's law (first guess: its attitude then)
    assert plan.t_start == visible_from - 60.0 and plan.end_pointing == Site.mode
    assert np.allclose(plan.q_to_BN, Site().attitudes(visible_from)[0])
    slew = world.reports(Kind.SLEW)[0]
    assert (slew.start, slew.end) == (740.0, 799.0)     # arrives 1 s before the site is trackable: flown
    maneuver = next(x for x in world.actions if isinstance(x, io.StartManeuver))
    assert maneuver.pointing_after == Site.mode
    dwell = world.reports(Kind.DWELL)[0]
    assert (dwell.start, dwell.end) == (799.0, 799.0 + 120.0) and dwell.pointing == Site.mode
    # after the dwell the hold (the attitude of the moment) is asked every step until accepted
    after = [x for x in world.actions if isinstance(x, io.SetPointing)][1:]
    assert all(h.q_BN is None for h in after)
    assert len(after) == 1 + math.ceil((refused_until - 919.0) / exe.RECOVERY_STEP)
    assert sum("refused the hold site" in text for text in world.logs()) == 1


def test_a_ground_site_reached_at_rest_is_dwelt_after_the_blend():
    site = MissionTarget("site", 120.0, track=Site())
    ex = executive(Scheduler({"site": 800.0}, visible={"site": 800.0}), [site], on_law=False)
    world = World(ex, duration=lambda action: 59.0).run()
    (plan,) = world.plans
    # aimed at the visibility: the goal the law's attitude then, at rest; start = aim - slew estimate
    assert plan.t_start == 800.0 - 60.0 and plan.end_pointing is None
    assert np.allclose(plan.q_to_BN, Site().attitudes(800.0)[0])
    slew = world.reports(Kind.SLEW)[0]
    assert (slew.start, slew.end) == (740.0, 799.0)              # within the match of the aim: flown
    maneuver = next(x for x in world.actions if isinstance(x, io.StartManeuver))
    assert maneuver.pointing_after == Site.mode
    end = 799.0
    dwell = world.reports(Kind.DWELL)[0]
    assert (dwell.start, dwell.end) == (end + BLEND, end + BLEND + 120.0)
    # a plan 10 s shorter than the estimate misses the aim: planned again from its own duration
    world = World(executive(Scheduler({"site": 800.0}, visible={"site": 800.0}), [site], on_law=False),
                  duration=lambda action: 50.0).run()
    assert [p.t_start for p in world.plans] == [740.0, 750.0] and world.reports(Kind.DWELL)[0].start == 800.0 + BLEND


def test_no_target_left_holds_to_the_horizon_and_missed_ones_are_reported():
    a = source("a", 30.0)
    ex = executive(Scheduler({}, missed={"a": "a sun zone covers it until the horizon"}), [a], horizon=500.0)
    world = World(ex).run()
    assert [(e.event, e.target) for e in world.reports()] == [(Kind.MISSED, "a"), (Kind.ENDED, "")]
    assert world.reports(Kind.MISSED)[0].message == "a sun zone covers it until the horizon"
    assert world.reports(Kind.ENDED)[0].message.startswith("0 targets held for their dwell, 1 missed")


def test_a_target_observable_later_but_in_no_order_now_is_decided_again_not_given_up():
    """The scheduler finds no order that reaches the one target left (it is observable later): the
    executive holds :data:`RECOVERY_STEP` s at a time and decides again until an order fits, then flies
    it; the day does not end early."""
    a = source("a", 30.0)
    scheduler = Scheduler({"a": 800.0}, no_order_before=450.0)
    world = World(executive(scheduler, [a], horizon=3000.0)).run()
    times = [t for t, _ in scheduler.decisions]
    assert times[0] == 0.0 and np.allclose(np.diff(times[:-1]), exe.RECOVERY_STEP)
    assert times[-2] < 450.0 <= times[-1] < 450.0 + exe.RECOVERY_STEP
    assert [(e.event, e.target) for e in world.reports() if e.event != Kind.SCHEDULED] == [
        (Kind.SLEW, "a"), (Kind.DWELL, "a"), (Kind.ENDED, "")]
    assert world.reports(Kind.DWELL)[0].start == pytest.approx(800.0)
    assert sum("no order fits" in line for line in world.logs()) == len(times) - 1


def test_hostile_events_change_nothing():
    a = source("a", 30.0)
    ex = executive(Scheduler({"a": 300.0}), [a])
    assert ex.on(io.PointingSet(t=0.0, q_BN=IDENTITY, request=1, success=True)) == []    # before the first state
    actions = ex.on(io.Tick(t=0.0, q_BN=IDENTITY))
    hold = actions[-1]
    assert isinstance(hold, io.SetPointing) and ex.phase == "holding"
    # an unknown request number, a wrong kind with the right number, a state from the past
    assert ex.on(io.PointingSet(t=1.0, q_BN=IDENTITY, request=hold.request + 7, success=True)) == []
    assert ex.on(io.ManeuverEnded(t=1.0, q_BN=IDENTITY, request=hold.request, success=True)) == []
    assert ex.on(io.Tick(t=-5.0, q_BN=q_about_z(90.0))) == [] and ex.t == 1.0
    assert np.array_equal(ex.q_BN, IDENTITY) and len(ex.ignored) == 3
    answer = io.PointingSet(t=2.0, q_BN=IDENTITY, request=hold.request, success=True)
    actions = ex.on(answer)
    assert isinstance(actions[-1], io.WaitUntil) and actions[-1].t == 300.0 - 60.0 - LEAD
    assert ex.on(answer) == [] and len(ex.ignored) == 4                # the same answer again
    assert ex.on(io.Tick(t=100.0, q_BN=IDENTITY)) == []                  # before the awaited time
    plan = ex.on(io.Tick(t=140.0, q_BN=IDENTITY))[-1]
    assert isinstance(plan, io.RequestPlan) and plan.request == hold.request + 1
    # a stale health event does not undo a newer one
    ex.on(io.EstimateHealth(t=150.0, q_BN=IDENTITY, converged=False))
    ex.on(io.EstimateHealth(t=145.0, q_BN=IDENTITY, converged=True))
    assert not ex.converged and ex.phase == "planning"
    # every event after the end is ignored
    world = World(executive(Scheduler({}), [a], horizon=50.0)).run()
    assert world.ex.on(io.Tick(t=60.0, q_BN=IDENTITY)) == [] and world.ex.done


@pytest.mark.parametrize("duplicate", [io.Tick, io.EstimateHealth])
def test_repeated_states_and_health_reports_do_not_change_the_day(duplicate):
    a, b = source("a", 30.0), source("b", -45.0)
    plain = World(executive(Scheduler({"a": 300.0, "b": 900.0}), [a, b])).run()

    class Noisy(World):
        def deliver(self, event):
            extra = dict(converged=True) if duplicate is io.EstimateHealth else {}
            return self.ex.on(duplicate(t=event.t, q_BN=event.q_BN, **extra)) + self.ex.on(event) \
                + self.ex.on(duplicate(t=event.t, q_BN=event.q_BN, **extra))
    noisy = Noisy(executive(Scheduler({"a": 300.0, "b": 900.0}), [a, b])).run()
    assert [(e.t, e.event, e.target, e.start, e.end) for e in noisy.reports()] == \
        [(e.t, e.event, e.target, e.start, e.end) for e in plain.reports()]


class Site:
    """A ground site's track whose law turns about z with time."""

    mode = PointingMode("ground")

    def attitudes(self, t):
        return np.array([q_about_z(float(x) / 100.0) for x in np.atleast_1d(t)])

    def line_of_sight(self, t):
        return np.array([[1.0, 0.0, 0.0]])

    def mode_at(self, arrival):
        return self.mode


def test_a_site_plan_arriving_before_the_site_is_trackable_is_planned_again_four_times_at_most():
    site = MissionTarget("site", 120.0, track=Site())
    ex = executive(Scheduler({"site": 800.0}, visible={"site": 800.0}), [site])
    world = World(ex, duration=lambda action: 50.0).run()
    # the first start from the estimate (60 s): arrives at 790 s, 10 s early; planned again to arrive
    # half the slack after the visibility, by its own duration
    assert [p.t_start for p in world.plans] == [800.0 - 60.0, 800.0 - 50.0 + exe.SITE_ARRIVAL_SLACK / 2.0]
    assert world.reports(Kind.SLEW)[0].start == world.plans[1].t_start
    assert world.reports(Kind.DWELL)[0].start == world.plans[1].t_start + 50.0
    # a plan that arrives after the visibility's start, inside it, is flown as planned
    ex = executive(Scheduler({"site": 800.0}, visible={"site": 800.0}), [site])
    world = World(ex, duration=lambda action: 70.0).run()
    assert [p.t_start for p in world.plans] == [740.0] and world.reports(Kind.DWELL)[0].start == 810.0
    # each plan shorter than the last: never on time, refused after four
    durations = iter([50.0, 40.0, 30.0, 20.0] * exe.MAX_ATTEMPTS)
    ex = executive(Scheduler({"site": 800.0}, visible={"site": 800.0}), [site])
    world = World(ex, duration=lambda action: next(durations)).run()
    refused = [e.message for e in world.reports(Kind.REFUSED)]
    assert refused == ["4 plans did not fit the site's visibility (the last arrived at 790 s)"] * exe.MAX_ATTEMPTS
    assert len(world.plans) == exe.SITE_PLANS * exe.MAX_ATTEMPTS and not world.reports(Kind.SLEW)
    assert all(p.end_pointing == Site.mode for p in world.plans)


def test_a_site_slew_arriving_too_late_is_planned_earlier_or_refused_and_counted():
    site = MissionTarget("site", 120.0, track=Site())
    last = {"site": lambda t: max(800.0, t) if t <= 850.0 else None}     # arrivals from 800 to 850 s
    # decided for 300 s (so a start at 240 s at the earliest), aimed at 800 s: a 160 s slew from 740 s
    # arrives at 900 s, too late; it starts earlier, to arrive half the slack after 800 s
    world = World(executive(Scheduler({"site": 300.0}, visible=last), [site]), duration=lambda a: 160.0).run()
    assert [p.t_start for p in world.plans] == [740.0, 800.0 - 160.0 + exe.SITE_ARRIVAL_SLACK / 2.0]
    assert world.reports(Kind.DWELL)[0].start == 800.0 + exe.SITE_ARRIVAL_SLACK / 2.0
    # a slew too long to arrive by 850 s from the earliest start (740 s, the decision's) is refused
    world = World(executive(Scheduler({"site": 800.0}, visible=last), [site]), duration=lambda a: 120.0).run()
    refused = [e.message for e in world.reports(Kind.REFUSED)]
    assert refused[0] == ("a slew of 120 s from 740 s or later cannot arrive before the site's last visibility "
                          "before the horizon")
    assert not world.reports(Kind.SLEW) and world.reports(Kind.MISSED)[0].target == "site"
    world = World(executive(Scheduler({"site": 800.0}, visible={"site": None}), [site])).run()
    assert world.reports(Kind.REFUSED)[0].message.startswith("the slew cannot arrive before the site's last")
    assert not world.plans


def test_a_zone_about_to_cover_the_start_attitude_is_escaped_by_a_quick_park():
    a, p = source("a", 30.0), source("p", 90.0)

    def clear(q, t0, t1):               # the start attitude is covered from t = 80 s on: clear for the escape lead
        return not (np.array_equal(q, IDENTITY) and t1 > 80.0)
    ex = executive(Scheduler({"a": 900.0}, clear=clear, parks=["p"]), [a, p])
    world = World(ex).run()
    assert world.logs()[0] == "a zone is about to cover the held attitude: leaving it"
    escape = world.plans[0]
    assert (escape.target, escape.t_start, escape.time_budget) == ("p", holds.ESCAPE_LEAD, holds.ESCAPE_BUDGET)
    park = world.reports(Kind.PARK)[0]
    assert (park.start, park.end) == (holds.ESCAPE_LEAD + 50.0 + SETTLE, holds.ESCAPE_LEAD + 2.0 * LEAD)
    assert world.plans[1].target == "a" and np.array_equal(world.plans[1].q_from_BN, p.attitude)


def test_after_the_last_target_a_zone_due_at_the_held_attitude_is_left_for_a_park():
    p = source("p", 90.0)
    ex = executive(Scheduler({}, keeps=lambda q, t0, t1: not (np.array_equal(q, IDENTITY) and t1 > 150.0),
                             parks=["p"]), [p], horizon=900.0)
    world = World(ex).run()
    assert [(e.event, e.target) for e in world.reports()] == \
        [(Kind.MISSED, "p"), (Kind.SLEW, "p"), (Kind.PARK, "p"), (Kind.ENDED, "")]
    park = world.reports(Kind.PARK)[0]
    assert world.plans[0].t_start == LEAD and (park.start, park.end) == (LEAD + 50.0 + SETTLE, 900.0)
    assert world.reports(Kind.ENDED)[0].t == 900.0


def test_a_refusal_while_the_held_attitude_cannot_start_a_slew_is_not_counted():
    a = source("a", 30.0)

    def clear(q, t0, t1):               # a zone passes the start attitude's lead from t = 140 s to 200 s
        return not (np.array_equal(q, IDENTITY) and 140.0 <= t0 < 200.0 and t1 > t0)
    ex = executive(Scheduler({"a": 300.0}, clear=clear), [a])
    world = World(ex, refuse_plan=lambda action: action.request == 2).run()   # request 1 is the first hold
    assert len(world.reports(Kind.REFUSED)) == 1 and ex.attempts["a"] == 0
    assert "holding: a zone reaches the held attitude" in world.logs()[0]
    # decided again at the first check clear of the zone (200 s), a's start its arrival - slew or a lead on
    assert [p.t_start for p in world.plans] == [300.0 - 60.0, max(300.0 - 60.0, 200.0 + LEAD)]
    assert [e.target for e in world.reports(Kind.DWELL)] == ["a"]


class Strip(Site):
    """A strip's track: its mode scans it from the arrival."""

    def mode_at(self, arrival):
        return PointingMode("strip", scan_start=arrival)


def test_a_strip_is_planned_onto_its_start_and_scanned_from_the_arrival_the_planner_says():
    """The plan asks for the strip (end_pointing of kind strip); the planner's answer says the scan
    from the arrival (pointing_after), which the controller is handed and the dwell event carries."""
    strip = MissionTarget("strip", 14.0, track=Strip())
    answered = PointingMode("strip", scan_start=123.0)        # whatever the planner says, flown as said
    world = World(executive(Scheduler({"strip": 800.0}, visible={"strip": 800.0}), [strip]),
                  duration=lambda action: 59.5, after=lambda action, d: answered).run()
    (plan,) = world.plans
    assert plan.end_pointing.kind == "strip" and plan.end_pointing.scan_start == 800.0     # the aim
    maneuver = next(x for x in world.actions if isinstance(x, io.StartManeuver))
    assert maneuver.pointing_after is answered
    dwell = world.reports(Kind.DWELL)[0]
    assert dwell.pointing is answered and (dwell.start, dwell.end) == (740.0 + 59.5, 740.0 + 59.5 + 14.0)
    assert world.reports(Kind.SLEW)[0].pointing is answered
    # without the planner's word, the track's mode from the arrival
    world = World(executive(Scheduler({"strip": 800.0}, visible={"strip": 800.0}), [strip]),
                  duration=lambda action: 59.5).run()
    assert world.reports(Kind.DWELL)[0].pointing.scan_start == 740.0 + 59.5
