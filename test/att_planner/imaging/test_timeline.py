"""The imaging timeline: the along-track axis from the star trackers, and a short horizon over sites
placed on the ground track planned by both policies with verified slews, each image inside its
window and the zones clear."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.imaging import timeline

from .conftest import SCENARIO


def test_the_along_track_axis_puts_the_aeos_trackers_fore_and_aft():
    axes = [z.sensor_axis for z in SCENARIO.zones]
    assert np.allclose(timeline.along_track_axis([0.0, 0.0, 1.0], axes), [1.0, 0.0, 0.0])
    assert np.allclose(timeline.along_track_axis([0.0, 0.0, 1.0], []), [0.0, 1.0, 0.0])   # next_axis


@pytest.mark.parametrize("policy", timeline.POLICIES)
def test_a_short_horizon_is_planned_with_verified_slews_and_images_inside_their_windows(planner, policy):
    plan = planner.plan(policy)
    w = planner.windows
    assert len(plan.images) >= 3 and plan.cpu_s > 0.0
    assert len({i.site for i in plan.images}) == len(plan.images)                    # each site once
    for image in plan.images:
        assert w.site[image.window] == image.site
        assert w.open_s[image.window] <= image.time_s and image.time_s + image.dwell_s <= w.close_s[image.window]
        assert image.time_s >= image.arrival_s + timeline.SETTLE_S - 1e-9
    for leg in plan.legs:
        assert leg.check.refusal is None and leg.check.final_attitude_error < math.radians(0.05)
    times = [leg.slew.t0_s for leg in plan.legs]
    assert times == sorted(times) and plan.worst_zone_margin > 0.0
    with pytest.raises(ValueError, match="policy"):
        planner.plan("random")


def test_ours_inserts_an_earlier_image_only_when_the_closing_window_stays_reachable(planner):
    w = planner.windows
    pending = np.arange(len(w))
    image_s = planner.estimates(timeline.NADIR, 150.0, pending)
    order = np.argsort(w.close_s[pending], kind="stable")
    chosen = planner._insertion(pending, image_s, order)
    assert sorted(chosen.tolist()) == sorted(order.tolist())
    assert list(chosen[1:]) == [k for k in order if k != chosen[0]]
    if chosen[0] != order[0]:
        k, first = chosen[0], order[0]
        dcm = planner.pointing.dcm_NB(w.site[[k]], np.array([image_s[k] + planner.dwell_s]))[0]
        after = planner.estimates(int(w.site[k]), image_s[k] + planner.dwell_s, pending[[first]], dcm,
                                  timeline.SLEW_SCALE)[0]
        assert after + planner.dwell_s <= w.close_s[first]
    # with the closing window out of reach after anything else, the order is the earliest-closing one
    hopeless = image_s.copy()
    hopeless[order[0]] = w.close_s[order[0]] - planner.dwell_s
    hopeless[order[1:]] = w.close_s[order[0]]
    assert list(planner._insertion(pending, hopeless, order)) == list(order)


@pytest.fixture(scope="module")
def dense():
    """A seeded dense instance: uniform:3000 over the first 1200 s, the bench's limits and zones."""
    import time as clock

    from att_planner.imaging import access, sites, slews
    from att_planner.zones import FittedZones

    from .conftest import ENVIRONMENT

    targets = sites.from_spec("uniform:3000", 0)
    windows = access.access_windows(ENVIRONMENT, targets, 0.0, 1200.0)
    sc = SCENARIO.spacecraft
    limits = slews.Limits.of(sc, float(SCENARIO.node_params["planner"]["schedule_rate_max_rad_s"]),
                             float(sc.wheel_inertia * sc.wheel_speed_max))
    planner = timeline.Planner(ENVIRONMENT, sc, targets, windows, SCENARIO.node_params["demo"]["sensor_axis"],
                               limits, FittedZones(SCENARIO.zones, ENVIRONMENT.sky, 1200.0))
    plans = {}
    for policy in timeline.POLICIES:
        start = clock.process_time()
        plans[policy] = planner.plan(policy), clock.process_time() - start
    return planner, plans


def test_rollout_never_plans_fewer_images_than_greedy_on_a_dense_seeded_instance(dense):
    planner, plans = dense
    greedy, rollout = plans["greedy"][0], plans["rollout"][0]
    assert len(greedy.images) >= 10
    assert len(rollout.images) >= len(greedy.images)
    assert len(rollout.images) >= len(plans["ours"][0].images) - 1


def test_every_rollout_image_is_reached_by_verified_legs_in_time_order(dense):
    planner, plans = dense
    plan = plans["rollout"][0]
    w = planner.windows
    assert len({i.site for i in plan.images}) == len(plan.images)
    for leg in plan.legs:
        assert leg.check.refusal is None and leg.check.final_attitude_error < math.radians(0.05)
    # each image is preceded by a leg onto its site arriving at its arrival, and the legs chain in time
    onto = {(leg.target, round(leg.slew.arrival_s, 9)) for leg in plan.legs}
    for image in plan.images:
        assert (image.site, round(image.arrival_s, 9)) in onto
        assert w.open_s[image.window] <= image.time_s and image.time_s + image.dwell_s <= w.close_s[image.window]
    starts = [leg.slew.t0_s for leg in plan.legs]
    assert starts == sorted(starts) and plan.worst_zone_margin > 0.0
    assert plan.attempts == len(plan.images) + plan.failed == len(plan.images) + sum(plan.failures.values())


def test_the_rollout_cpu_is_the_planners_own_and_counts_the_rollouts(dense):
    _, plans = dense
    for policy, (plan, outside) in plans.items():
        assert 0.0 < plan.cpu_s <= outside + 1e-3, policy
    # the rollouts simulate several candidates per decision: they cost more than the base rule
    assert plans["rollout"][0].cpu_s > plans["greedy"][0].cpu_s


def test_a_rollout_scores_its_images_less_the_sites_lost_and_leaves_the_state_alone(dense):
    planner, _ = dense
    w = planner.windows
    alive, imaged = np.ones(len(w), bool), np.zeros(w.n_sites, bool)
    first = int(np.argmin(w.close_s))
    image_s = float(w.open_s[first])
    score, end = planner._rollout(int(w.site[first]), image_s, alive, imaged, image_s + 300.0, "greedy")
    assert alive.all() and not imaged.any()                                          # copies only
    assert image_s + planner.dwell_s <= end <= image_s + 300.0
    assert 1.0 - len(w) <= score <= 1.0 + len(w)
    # with no time after the first image, the rollout is that image less the sites it lets close for good
    only, _ = planner._rollout(int(w.site[first]), image_s, alive, imaged, image_s + planner.dwell_s, "greedy")
    assert only <= 1.0


def test_the_rollout_order_is_the_base_order_with_the_best_candidate_first(dense):
    planner, _ = dense
    w = planner.windows
    alive, imaged = np.ones(len(w), bool), np.zeros(w.n_sites, bool)
    pending = np.flatnonzero(alive)[:planner.lookahead]
    image_s = planner.estimates(timeline.NADIR, w.t0_s, pending)
    order = np.argsort(w.close_s[pending], kind="stable")
    chosen = planner._rollout_order(timeline.NADIR, w.t0_s, pending, image_s, order, alive, imaged)
    assert sorted(chosen.tolist()) == sorted(order.tolist())
    assert list(chosen[1:]) == [k for k in order if k != chosen[0]]
