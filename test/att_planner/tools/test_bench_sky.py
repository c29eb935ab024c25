"""``att-bench sky``: an INDEPENDENT check of the committed benchmarks/sky_<case>.json,
and the study's plumbing on a cheap method.

The check uses nothing of the suite: it integrates each plan's ZOH body torque from rest at
``q_initial`` with its own RK4 of the rigid body (:mod:`helpers.own_rk4`), and computes the zones'
true directions with skyfield directly (:mod:`helpers.independent`: the JSON's TLE, DE421 from
skyfield-data, the Earth limb about −r̂). It then confirms, to 0.01°: the torque reproduces each
plan (final attitude, the JSON's margins), the frozen plan enters a zone, the moving one does not.
On the headline case (found by ``benchmarks/sky_search.py``) it also checks the per-knot margins of
the JSON, that the frozen plan clears the zones frozen at its start and enters the true limb by
more than :data:`HEADLINE_DEPTH`; and it plans that case both ways through the study.
``ATT_SKY_BENCHMARKS=DIR`` checks the sky_<case>.json of another directory (a fresh ``att-bench sky
--json`` run).
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from helpers.independent import margins, sky
from helpers.own_rk4 import integrate

BENCHMARKS = Path(os.environ.get("ATT_SKY_BENCHMARKS", Path(__file__).resolve().parents[3] / "benchmarks"))
CASES = ("rising_limb", "leo_observatory", "moon_parallax")
# the method and interpolation of each committed JSON
METHODS = dict.fromkeys(CASES, ("smooth_collocation", "linear"))
# the cases whose frozen plan enters a true zone with the default method (leo_observatory's start,
# found for the Slepian method, no longer shows it: both of its plans clear every true zone)
ENTERS = ("rising_limb", "moon_parallax")
HEADLINE_DEPTH = math.radians(5.0)     # the frozen plan of the headline case enters the true limb by more
TOL = math.radians(0.01)
SUBSTEPS = 4                  # RK4 steps per ZOH interval (500 intervals: 2000 steps); the sky at the knots


@pytest.fixture(scope="module", params=CASES)
def checked(request):
    """The committed JSON of a case and, per plan, its own integration and true-sky margins."""
    payload = json.loads((BENCHMARKS / f"sky_{request.param}.json").read_text())
    out = {}
    for kind, plan in payload["plans"].items():
        assert plan["t"], f"{request.param}: no {kind} plan in the JSON ({plan['message']})"
        t = np.asarray(plan["t"], float)
        states = integrate(payload["J"], t, plan["torque"], payload["q_initial"], SUBSTEPS,
                           interpolation=plan["interpolation"])
        out[kind] = (t, states, margins(payload, t, states[:, :4]))
    return payload, out


def test_format_is_the_issues(checked):
    payload, _ = checked
    for key in ("case", "epoch", "tle", "J", "torque_limit", "sensor_axis", "q_initial", "q_final", "zones", "plans"):
        assert key in payload, key
    assert set(payload["plans"]) == {"frozen", "moving"}
    for plan in payload["plans"].values():
        for key in ("method", "tf", "t", "torque", "interpolation", "solve_seconds", "verification"):
            assert key in plan, key
        assert (plan["method"], plan["interpolation"]) == METHODS[payload["case"]]
        assert len(plan["t"]) == len(plan["torque"])
        assert np.abs(plan["torque"]).max() <= payload["torque_limit"] * (1 + 1e-6)
    for z in payload["zones"]:
        assert z["body"] in ("inertial", "sun", "moon", "earth_limb")
        assert ("direction" in z) == (z["body"] == "inertial") and ("margin" in z) == (z["body"] == "earth_limb")


def test_earth_limb_half_angle_at_start(checked):
    payload, _ = checked
    _, limb = sky(payload, np.zeros(1))
    for z in payload["zones"]:
        if z["body"] == "earth_limb":
            assert z["half_angle"] == pytest.approx(limb[0] + z["margin"], abs=1e-6)


def test_torque_reproduces_each_plan(checked):
    payload, own = checked
    for kind, (times, states, zone_margins) in own.items():
        plan = payload["plans"][kind]
        assert times[-1] == pytest.approx(plan["tf"], rel=1e-12)
        qf = np.asarray(payload["q_final"], float)
        error = 2.0 * math.acos(min(1.0, abs(float(states[-1, :4] @ qf))))
        assert error == pytest.approx(plan["verification"]["final_attitude_error"], abs=TOL)
        assert error < math.radians(0.5) and np.linalg.norm(states[-1, 4:]) < 1e-3
        for name, m in zone_margins.items():
            assert m.min() == pytest.approx(plan["verification"]["zone_margins_vs_motion"][name], abs=TOL), (kind, name)


def test_frozen_plan_enters_a_zone_and_the_moving_one_does_not(checked):
    payload, own = checked
    frozen = min(m.min() for m in own["frozen"][2].values())
    if payload["case"] in ENTERS:
        assert frozen < -TOL, f"frozen plan's smallest true margin {math.degrees(frozen):.4f} deg"
        entered = payload["plans"]["frozen"]["verification"]["entered"]
        assert own["frozen"][2][entered].min() < -TOL
    else:
        assert frozen >= -TOL, f"frozen plan's smallest true margin {math.degrees(frozen):.4f} deg"
    moving = min(m.min() for m in own["moving"][2].values())
    assert moving >= -TOL, f"moving plan's smallest true margin {math.degrees(moving):.4f} deg"


def test_study_plumbing_on_a_cheap_method(tmp_path):
    """The study end to end (both plans through the service's pipeline, the JSON written) with the
    closed-form eigenaxis_smooth instead of the default method: it ignores the zones when planning,
    so its frozen plan is refused by the verification against the motion."""
    from att_planner.tools.bench import main

    path = tmp_path / "sky.json"
    assert main(["sky", "--case", "leo_observatory", "--offset", "500", "--method", "eigenaxis_smooth",
                 "--options", "samples=101", "--json", str(path)]) == 0
    payload = json.loads(path.read_text())
    assert payload["epoch"] == "2026-12-21T00:08:20.000000Z" and payload["tle"][0].startswith("1 28485U")
    assert [z["body"] for z in payload["zones"]] == ["sun", "moon", "earth_limb"]
    frozen, moving = payload["plans"]["frozen"], payload["plans"]["moving"]
    assert frozen["method"] == "eigenaxis_smooth" and len(frozen["t"]) == len(frozen["torque"]) == 101
    ver = frozen["verification"]
    assert set(ver["zone_margins_vs_motion"]) == {"sun", "moon", "earth"}
    assert ver["min_cone_margin"] == pytest.approx(min(ver["zone_margins_vs_motion"].values()))
    # 500 s after 00:00 the eigenaxis slew clears the frozen limb by 1.10 deg, the rising limb overtakes it by 1.76
    assert math.degrees(ver["zone_margins_vs_planned"]["earth"]) == pytest.approx(1.10, abs=0.01)
    assert ver["entered"] == "earth" and math.degrees(ver["entered_by"]) == pytest.approx(1.76, abs=0.01)
    assert not ver["passes"] and not moving["verification"]["passes"]


def frozen_at_start(payload) -> dict:
    """The payload with every zone frozen as the independent sky has it at the start (inertial)."""
    axes, limb = sky(payload, np.zeros(1))
    zones = []
    for z in payload["zones"]:
        half = limb[0] + z["margin"] if z["body"] == "earth_limb" else z["half_angle"]
        zones.append(dict(z, body="inertial", direction=axes[z["body"]][0], half_angle=half))
    return dict(payload, zones=zones)


def test_headline_per_knot_margins_and_frozen_zones():
    """The headline JSON's per-knot true margins are the independent ones; its frozen plan clears
    the zones frozen at the start (what it was verified against) and enters the true limb deeply."""
    payload = json.loads((BENCHMARKS / "sky_rising_limb.json").read_text())
    still = frozen_at_start(payload)
    for kind, plan in payload["plans"].items():
        t = np.asarray(plan["t"], float)
        q = integrate(payload["J"], t, plan["torque"], payload["q_initial"], SUBSTEPS,
                      interpolation=plan["interpolation"])[:, :4]
        own, samples = margins(payload, t, q), plan["samples"]
        assert np.allclose(samples["t"], t, rtol=0.0, atol=1e-9)
        for name, m in own.items():
            assert np.abs(np.asarray(samples["true_margins"][name]) - m).max() < TOL, (kind, name)
        assert plan["verification_planned"]["passes"] and plan["service"]["stage"] == "method", kind
        if kind == "frozen":
            assert min(m.min() for m in margins(still, t, q).values()) > -TOL
            assert own["earth"].min() < -HEADLINE_DEPTH
        else:
            assert min(m.min() for m in own.values()) > 0.0


def test_headline_case_is_the_searchs():
    """The case the study holds is the one benchmarks/sky_search.py kept."""
    from att_planner.tools.bench.sky import CASES, HEADLINE

    found = json.loads((Path(__file__).resolve().parents[3] / "benchmarks" / "sky_search.json").read_text())
    case = CASES[HEADLINE]
    assert found["best_case"]["offset"] == case.offset and found["best_case"]["tle"] == list(case.tle)
    assert tuple(found["best_case"]["q_initial"]) == case.q_initial
    assert tuple(found["best_case"]["q_final"]) == case.q_final
    assert found["best"]["frozen"]["entered_by_deg"] >= found["min_depth_deg"] > 0.0
    assert found["best"]["moving"]["true_margin_deg"] > 0.0


def test_headline_planned_both_ways():
    """The headline case planned now, both ways, by the default method through the study: the plan
    against the frozen zones verifies against them yet enters the true Earth limb by more than
    HEADLINE_DEPTH; the plan against the moving zones verifies and clears every true zone."""
    from att_planner import methods
    from att_planner.tools.bench.sky import HEADLINE, case_problem, plan_case

    _, problem = case_problem(HEADLINE)
    method = methods.REGISTRY[0]
    frozen, moving = (plan_case(problem, method, {}, kind) for kind in ("frozen", "moving"))
    assert frozen["method"] == moving["method"] == "smooth_collocation"
    assert frozen["verification_planned"]["passes"] and frozen["service"]["code"] == 0
    assert frozen["verification"]["entered"] == "earth" and frozen["verification"]["entered_by"] > HEADLINE_DEPTH
    assert not frozen["verification"]["passes"]
    assert moving["verification_planned"]["passes"] and moving["verification"]["passes"]
    true_margins = moving["verification"]["zone_margins_vs_motion"]
    assert moving["verification"]["entered"] is None and min(true_margins.values()) > 0.0
    # the margins the study reports per knot are those of the suite's truth at the predicted attitudes
    assert min(min(m) for m in moving["samples"]["true_margins"].values()) >= min(true_margins.values()) - TOL
    assert min(frozen["samples"]["true_margins"]["earth"]) == pytest.approx(-frozen["verification"]["entered_by"],
                                                                           abs=TOL)
