"""The mission's observation order: on leo_observatory's day every observable source is
ordered inside its visibility before the horizon; the two covered all day are missed with their
zone named; a late decision drops what no longer fits."""
import math

import numpy as np
import pytest

from att_planner.mission import targets as tl
from att_planner.mission.scheduler import MissionScheduler, MissionTarget, sky_parks, slew_estimate
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

HORIZON = 6 * 3600.0
SENSOR = np.array([0.0, 1.0, 0.0])                 # leo_observatory's zones are of sensor +y


@pytest.fixture(scope="module")
def day():
    sources = tl.load("observatory").targets
    targets = {s.name: (tl.pointing_attitude(SENSOR, s.direction), s.dwell) for s in sources}
    held = {k: MissionTarget(k, d, q) for k, (q, d) in targets.items()}
    return MissionScheduler(scen.load("leo_observatory"), held, HORIZON), targets


def test_every_observable_source_is_ordered_inside_its_visibility(day):
    scheduler, targets = day
    decision = scheduler.decide(0.0, rot.IDENTITY, list(targets))
    assert set(decision.missed) == {"sgr_a_star", "pleiades"}
    assert "sun zone" in decision.missed["sgr_a_star"] and "moon zone" in decision.missed["pleiades"]
    assert sorted(decision.order) == sorted(set(targets) - set(decision.missed))
    end, q = 0.0, rot.IDENTITY
    for name, arrival in zip(decision.order, decision.arrivals, strict=True):
        q_target, dwell = targets[name]
        assert arrival >= end + scheduler.leg(q, q_target) - 1e-9          # the slew fits before it
        assert any(a <= arrival and arrival + dwell <= b for a, b in scheduler.visible[name]), name
        held = np.linspace(arrival, arrival + dwell, 7)
        assert scheduler.zones.margins(held, q_target, true=True).min() > -np.deg2rad(0.5), name
        end, q = arrival + dwell, q_target
    assert end <= HORIZON


def test_a_late_decision_keeps_what_fits_and_says_why_the_rest_is_missed(day):
    scheduler, targets = day
    late = HORIZON - 2500.0
    names = ["crab_nebula", "andromeda", "cas_a", "lmc", "m87"]
    decision = scheduler.decide(late, rot.IDENTITY, names)
    assert decision.order and (decision.missed or decision.left_out)
    assert sorted([*decision.order, *decision.missed, *decision.left_out]) == sorted(names)
    for name in decision.left_out:                      # observable still, but not in this order
        assert scheduler.observable_from(name, late + scheduler.lead) is not None
    assert all(a >= late for a in decision.arrivals)
    last = decision.order[-1]
    assert decision.arrivals[-1] + targets[last][1] <= HORIZON
    assert all("horizon" in why for why in decision.missed.values())


def test_the_slew_estimate_is_the_bang_bang_eigenaxis_time():
    inertia = np.diag([3000.0, 4500.0, 6000.0])
    q = rot.from_axis_angle([0.0, 0.0, 1.0], math.radians(90.0))
    assert slew_estimate(inertia, 0.25, rot.IDENTITY, q) == pytest.approx(2 * math.sqrt(math.pi / 2 / (0.25 / 6000)))
    assert slew_estimate(inertia, 0.25, q, -q) == 0.0


def test_a_mission_needs_the_real_sky():
    with pytest.raises(ValueError, match="'swift_demo' has no epoch"):
        MissionScheduler(scen.load("swift_demo"), {}, HORIZON)


def test_observable_from_is_the_first_span_long_enough_for_the_dwell_and_the_lead_away(day):
    scheduler, targets = day
    for name, (_, dwell) in targets.items():
        assert scheduler.held(name) == dwell + scheduler.lead
        start = scheduler.observable_from(name, 600.0)
        spans = [(a, b) for a, b in scheduler.visible[name] if b - max(a, 600.0) >= dwell + scheduler.lead]
        if not spans:
            assert start is None, name
            continue
        assert start == pytest.approx(max(spans[0][0], 600.0)), name
        held = np.linspace(start, start + dwell + scheduler.lead, 9)
        assert scheduler.zones.margins(held, targets[name][0], true=True).min() >= 0


def test_a_held_attitude_is_clear_only_while_no_zone_covers_it(day):
    scheduler, targets = day
    q = targets["polaris"][0]
    (a, b), *_ = [s for s in scheduler.visible["polaris"] if s[1] - s[0] > 600.0]
    assert scheduler.clear(q, a + 10.0, b - 10.0)
    assert not scheduler.clear(targets["sgr_a_star"][0], 0.0, 60.0)          # in the Sun zone all day


def test_a_park_is_a_source_visible_from_its_arrival_until_the_wait_ends(day):
    scheduler, targets = day
    q_from, now, until = targets["sgr_a_star"][0], 1000.0, 2500.0
    names = scheduler.parks(q_from, now, until)
    assert names
    arrivals = [now + scheduler.leg(q_from, targets[name][0]) for name in names]
    assert arrivals == sorted(arrivals)
    for name, arrive in zip(names, arrivals):
        assert scheduler.zones.margins(np.linspace(arrive, until, 50), targets[name][0], true=True).min() >= 0
    assert scheduler.parks(q_from, now, HORIZON + 7200.0) == []              # nothing is visible past the horizon


def test_a_rate_bound_lengthens_the_slew_to_a_coast_at_the_bound():
    sc = scen.load("leo_observatory").spacecraft
    q1 = rot.from_axis_angle([1.0, 0.0, 0.0], math.radians(120.0))
    free = slew_estimate(sc.inertia, sc.body_torque_max, rot.IDENTITY, q1)
    w = 0.002
    bounded = slew_estimate(sc.inertia, sc.body_torque_max, rot.IDENTITY, q1, rate_max=w)
    alpha = sc.body_torque_max / sc.inertia[0, 0]
    assert free == pytest.approx(2 * math.sqrt(math.radians(120.0) / alpha))
    assert bounded == pytest.approx(math.radians(120.0) / w + w / alpha) and bounded > free
    assert slew_estimate(sc.inertia, sc.body_torque_max, rot.IDENTITY, q1, rate_max=1.0) == pytest.approx(free)


@pytest.fixture(scope="module")
def sites():
    from att_planner.mission import config as mc
    mission = mc.load("earth_observation_day")
    targets = mission.targets()
    return MissionScheduler(mission.scenario, targets, HORIZON, zones=mission.zones, margin=mission.margin,
                            lead=240.0, settle=60.0, blend=mission.handover_blend), targets


def test_a_site_arrival_keeps_the_zones_through_the_blend_and_is_trackable_through_the_dwell(sites):
    scheduler, targets = sites
    blend = scheduler.blend
    assert blend == 180.0 and scheduler.held("singapore") == blend + targets["singapore"].dwell
    for name, target in targets.items():
        for a, b in scheduler.visible[name]:
            for arrival in (a, b - scheduler.held(name)):          # the first and last arrivals
                dwell = np.arange(arrival + blend, arrival + blend + target.dwell + 1e-9, 10.0)
                assert target.track.elevation(dwell).min() >= target.track.min_elevation - 1e-12, name
                assert target.track.torque(dwell).max() <= target.track.torque_limit, name
                t = np.arange(arrival, arrival + scheduler.held(name) + 1e-9, 10.0)
                assert scheduler.zones.margins(t, target.attitudes(t), true=True).min() >= math.radians(1.0) - 1e-9
    assert scheduler.visible["toulouse"] == []                 # 43.6 deg N: never 30 deg high from a 20.56 deg orbit


def test_sites_are_ordered_inside_their_passes_and_the_rest_missed_with_why(sites):
    scheduler, targets = sites
    decision = scheduler.decide(0.0, rot.IDENTITY, list(targets))
    assert decision.order and sorted([*decision.order, *decision.missed, *decision.left_out]) == sorted(targets)
    assert "never 30 deg above its horizon" in decision.missed["toulouse"]
    for name, arrival in zip(decision.order, decision.arrivals, strict=True):
        assert any(a <= arrival and arrival + scheduler.held(name) <= b for a, b in scheduler.visible[name]), name
    first = decision.order[0]
    q_site = scheduler.attitude_near(first, 0.0)
    assert decision.arrivals[0] >= scheduler.lead + scheduler.slew(rot.IDENTITY, q_site, settle=False) - 1e-6
    assert scheduler.parks(rot.IDENTITY, 0.0, 600.0) == []     # a moving site is never a park


def test_a_visibility_too_short_after_the_lead_is_named_with_its_length(day):
    """A source visible until the horizon, decided 30 s too late for its dwell after the lead: the
    length named is what is left after the lead (the day's LMC was told 1065 s, measured from the
    decision, when 825 s were left)."""
    scheduler, targets = day
    name, (a, b) = next((k, v[-1]) for k, v in scheduler.visible.items()
                        if v and v[-1][1] >= HORIZON - 10.0 and v[-1][1] - v[-1][0] > scheduler.held(k) + 600.0)
    now = b - scheduler.held(name) - scheduler.lead + 30.0
    assert scheduler.observable_from(name, now + scheduler.lead) is None
    assert f"lasts {scheduler.held(name) - 30.0:g} s at most" in scheduler.why_missed(name, now), name


def test_sky_parks_spread_over_the_sky_and_are_parks_when_no_source_is_clear():
    """Sky parks: unit directions evenly spread (no two closer than a lattice's spacing), the sensor
    axis on each; with one source only, the parks offered after it leaves view are the sky's, each
    clear of every zone from its arrival to the end of the wait (recomputed here)."""
    parks = sky_parks(SENSOR, tl.pointing_attitude, 64)
    d = np.array([p.direction for p in parks.values()])
    assert len(parks) == 64 and np.allclose(np.linalg.norm(d, axis=1), 1.0)
    cosines = d @ d.T - 2.0 * np.eye(64)
    assert np.degrees(np.arccos(cosines.max())) > 20.0                 # 4π/64 sr: about 25 deg apart
    assert abs(d.mean(axis=0)).max() < 0.05                             # no side of the sky favoured
    for p in parks.values():
        assert np.allclose(rot.dcm_NB(p.attitude) @ SENSOR, p.direction, atol=1e-9)
    source = tl.load("observatory").targets[0]
    one = {source.name: MissionTarget(source.name, 60.0, tl.pointing_attitude(SENSOR, source.direction))}
    scheduler = MissionScheduler(scen.load("leo_observatory"), one, HORIZON, parks=parks)
    t_now, until = 5000.0, 5600.0
    offered = scheduler.parks(rot.IDENTITY, t_now, until)
    assert any(name in parks for name in offered)
    for name in offered:
        q = (one | parks)[name].attitude
        arrive = t_now + scheduler.leg(rot.IDENTITY, q)
        held = np.linspace(arrive, until, 20)
        assert scheduler.zones.margins(held, q, true=True).min() >= -np.deg2rad(0.5), name


def test_a_strip_s_spans_are_the_arrivals_that_scan_it_high_enough_clear_of_the_zones():
    """The shipped orbit's strips: from every first and last arrival of a span the strip's start is
    58 deg high at the arrival and its end at the scan's end (each recomputed as a site there), the
    scan's torque within the share and every zone kept at the scan's start, middle and end; a grid
    step before a span's start, one of those fails."""
    from att_planner.mission import config as mc
    from att_planner.mission.executive import MissionExecutive
    from att_planner.mission.ground import GroundTrack, geodetic_of
    from att_planner.mission.targets import Site

    m = mc.load("aeos_orbit")
    scheduler = MissionExecutive.of_mission(m, 20.0, converged=True).scheduler
    step = scheduler.grid[1] - scheduler.grid[0]
    for name in ("rio_grande", "kashgar"):
        target = scheduler.targets[name]
        track, strip = target.track, target.track.strip
        assert target.dwell == strip.duration_s and scheduler.held(name) == target.dwell
        lat1, lon1, _ = geodetic_of(strip.point(strip.theta_of(strip.length_m))[0][None])
        ends = [GroundTrack(m.scenario, Site(name, lat, lon, strip.altitude_m, 0.0), track.mode_at(0.0), 0.0)
                for lat, lon in ((track.site.latitude, track.site.longitude), (lat1[0], lon1[0]))]

        (span,) = scheduler.visible[name]               # one pass over each
        a, b = span
        for arrival in (a, b - scheduler.held(name)):
            assert _scans(m, scheduler, track, ends, arrival), (name, arrival)
        assert not _scans(m, scheduler, track, ends, a - step), name


def _scans(m, scheduler, track, ends, arrival: float) -> bool:
    """Whether strip ``track`` scanned from ``arrival`` is seen high enough at both ``ends`` (GroundTracks
    of its start and end), within the torque share and clear of the zones at its start, middle and end."""
    from att_planner.guidance.strip import StripLaw, tracking_demand

    strip = track.strip
    law = StripLaw(track.geometry, strip, track.primary_B, track.secondary_B, arrival)
    high = ends[0].elevation(arrival)[0] >= track.min_elevation - 1e-9 and \
        ends[1].elevation(arrival + strip.duration_s)[0] >= track.min_elevation - 1e-9
    torque = tracking_demand(m.scenario.spacecraft, track.geometry, strip, track.primary_B, track.secondary_B,
                             arrival, samples=3)[1]
    clear = all(scheduler.zones.margins([arrival + f * strip.duration_s], law.attitude(arrival + f * strip.duration_s),
                                        true=True).min() >= m.margin - 1e-9 for f in (0.0, 0.5, 1.0))
    return high and torque <= track.torque_limit and clear
