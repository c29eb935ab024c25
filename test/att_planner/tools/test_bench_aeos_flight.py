"""The flown imaging day's image check: a truth on the site's law passes both levels, a truth 0.1 deg
off passes (a) and fails (b), a truth 3 deg off fails both; a dwell without samples fails (b); the zone
entries are counted as runs; and a bad --policies is refused."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from att_planner.imaging import timeline
from att_planner.tools.bench import aeos_flight, history, main
from att_sim.models import rotations as rot

from ..imaging.conftest import planner  # noqa: F401  (the shared planner fixture)


def _flight(t, q, omega):
    arrays = {"t": np.asarray(t), "q_true": np.asarray(q), "omega_true": np.asarray(omega)}
    return SimpleNamespace(loop=SimpleNamespace(trace=SimpleNamespace(arrays=lambda *names: arrays)))


@pytest.mark.parametrize("offset_deg, level_a, level_b", [(0.0, True, True), (0.1, True, False), (3.0, False, False)])
def test_an_image_is_judged_at_both_levels_on_the_truth(planner, offset_deg, level_a, level_b):  # noqa: F811
    law = planner.laws(0)
    image = timeline.Image(0, 0, 200.0, 2.0, 197.0)
    t = np.arange(199.0, 203.0, 0.05)
    tilt = rot.from_axis_angle(np.array([1.0, 0.0, 0.0]), math.radians(offset_deg))   # about a body axis ⟂ boresight
    q = np.array([rot.multiply(law(s)[0], tilt) for s in t])
    omega = np.array([rot.dcm_NB(tilt).T @ law(s)[1] for s in t])     # the same motion, body axes
    plan = timeline.Timeline("greedy", images=[image])
    (check,) = aeos_flight.check(planner, plan, _flight(t, q, omega))
    assert (check.level_a, check.level_b) == (level_a, level_b)
    assert check.samples == 41 and check.a_pointing_deg == pytest.approx(offset_deg, abs=1e-6)
    assert check.b_rate_deg_s < 1e-3


def test_an_image_after_the_flight_fails_both_levels(planner):  # noqa: F811
    plan = timeline.Timeline("ours", images=[timeline.Image(0, 0, 900.0, 2.0, 897.0)])
    (check,) = aeos_flight.check(planner, plan, _flight([0.0, 0.05], [rot.IDENTITY] * 2, [[0.0] * 3] * 2))
    assert not check.level_a and not check.level_b and check.samples == 0


def test_bad_policies_are_refused(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["aeos", "--targets", "uniform:5", "--orbits", "0.05", "--fly", "--policies", "random",
              "--json", "/dev/null"])
    assert exit_.value.code == 2 and "--policies" in capsys.readouterr().err


def _policy(a: int, b: int, entries: int = 0, cpu: float = 2.0) -> dict:
    return {"status": "flown", "planned_images": b + 1, "planner_cpu_s_per_orbit": cpu, "zone_entries": entries,
            "flown_worst_zone_margin_deg": 12.0, "level_a": {"images": a, "lost": 1},
            "level_b": {"images": b, "lost": 1}}


@pytest.mark.parametrize("ours, met", [(_policy(120, 110), True), (_policy(120, 100), False),
                                       (_policy(120, 110, entries=1), False), (_policy(120, 110, cpu=11.0), False)])
def test_the_history_line_of_a_flown_day_judges_the_issue_s_criteria(ours, met):
    payload = {"study": "aeos", "targets": "uniform:300", "seed": 0, "orbits": 1.0, "accessible": {"sites": 150},
               "flown": {"greedy": _policy(100, 95), "ours": ours}}
    line = history.line(payload, json_path=None, date="2026-01-01T00:00:00Z", commit=None, source="test")
    assert line["met"] is met and line["value"] == ours["level_b"]["images"]
    assert line["metrics"]["greedy_level_a"] == 100 and line["metrics"]["accessible_sites"] == 150
    assert line["command"] == "att-bench aeos --targets uniform:300 --seed 0 --orbits 1 --fly --policies greedy,ours " \
                              "--json PATH"
    alone = history.line({**payload, "flown": {"ours": ours}}, json_path=None, date="2026-01-01T00:00:00Z",
                         commit=None, source="test")
    assert alone["met"] is None


def test_the_history_line_of_a_planned_day_is_marked_not_flown():
    planned = {"status": "planned, verified slews, not flown", "planned_images": 80, "planned_priority": 40.0,
               "planner_cpu_s_per_orbit": 1.5}
    payload = {"study": "aeos", "targets": "uniform:300", "seed": 2, "orbits": 5.0, "accessible": {"sites": 90},
               "flown": {"greedy": planned, "ours": {**planned, "planned_images": 82}}, "bound": {"images": 88.0}}
    line = history.line(payload, json_path=None, date="2026-01-01T00:00:00Z", commit=None, source="test")
    assert line["met"] is None and line["value"] == 82 and "not flown" in line["metric"]
    assert line["metrics"]["greedy_planned"] == 80 and line["metrics"]["bound_images"] == 88.0
    assert "--plan-only --bound" in line["command"]
