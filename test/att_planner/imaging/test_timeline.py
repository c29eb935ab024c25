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
