"""``att-bench speed``: an INDEPENDENT check of the committed benchmarks/speed.json, and the
study's plumbing on one quick run.

For every case and every plan of the JSON (the first, the best smooth and the time-optimal one) the
check flies the torque samples from rest at ``q_initial`` with its own RK4 of the rigid body (8
steps per knot interval, the samples held or interpolated linearly as the plan's ``interpolation``
says, :mod:`helpers.own_rk4`) and the zones' true directions from skyfield (:mod:`helpers.independent`:
nothing of the suite), then confirms: the final attitude error and every zone's smallest margin are the JSON's
(to 0.01°), the plan reaches the goal (0.5°, 1e-3 rad/s) and stays clear, the torque keeps its
limit and the smooth plans' torque vanishes at both ends; the best smooth plan is within 1.25 × the
time-optimal t_f. ``ATT_SPEED_BENCHMARKS=DIR`` checks the speed.json of another directory.
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from helpers.independent import attitude_error, margins
from helpers.own_rk4 import integrate

BENCHMARKS = Path(os.environ.get("ATT_SPEED_BENCHMARKS", Path(__file__).resolve().parents[3] / "benchmarks"))
KINDS = ("first", "best", "time_optimal")
TOL = math.radians(0.01)


@pytest.fixture(scope="module")
def flown():
    """The committed JSON and, per case and plan, its own dense integration and true margins."""
    payload = json.loads((BENCHMARKS / "speed.json").read_text())
    out = {}
    for case in payload["cases"]:
        for kind in KINDS:
            plan = case[kind]
            t, states = integrate(case["J"], np.asarray(plan["t"], float), plan["torque"], case["q_initial"],
                                  substeps=8, dense=True, interpolation=plan["interpolation"])
            out[case["case"], kind] = (t, states, margins(case, t, states[:, :4]))
    return payload, out


def test_format_is_the_issues(flown):
    payload, _ = flown
    assert [c["case"] for c in payload["cases"]] == ["swift", "earth_obs", "leo_observatory"]
    for case in payload["cases"]:
        for key in ("case", "first", "best", "time_optimal_tf", "J", "torque_limit", "q_initial", "q_final",
                    "sensor_axis", "cones", "zones"):
            assert key in case, key
        for kind in KINDS:
            plan = case[kind]
            for key in ("method", "tf", "t", "torque", "interpolation", "solve_seconds", "verification"):
                assert key in plan, (kind, key)
            assert len(plan["t"]) == len(plan["torque"]) and plan["t"][-1] == pytest.approx(plan["tf"])
            assert plan["verification"]["passes"], (case["case"], kind)
        assert case["first"]["method"] == "graph_smooth" and case["time_optimal"]["method"] == "time_optimal"
        assert case["time_optimal_tf"] == case["time_optimal"]["tf"]


def test_each_plan_flies_as_the_json_says(flown):
    payload, own = flown
    for case in payload["cases"]:
        for kind in KINDS:
            t, states, zone_margins = own[case["case"], kind]
            ver = case[kind]["verification"]
            error = attitude_error(states[-1, :4], case["q_final"])
            assert error == pytest.approx(ver["final_attitude_error"], abs=TOL), (case["case"], kind)
            assert error < math.radians(0.5) and np.linalg.norm(states[-1, 4:]) < 1e-3, (case["case"], kind)
            assert list(zone_margins) == ver["zone_names"]
            for m, reported in zip(zone_margins.values(), ver["cone_margins"]):
                assert m.min() == pytest.approx(reported, abs=TOL), (case["case"], kind)
                assert m.min() >= -1e-9, (case["case"], kind)


def test_torque_limits_smooth_ends_and_the_best_against_the_time_optimal(flown):
    payload, _ = flown
    for case in payload["cases"]:
        limit = case["torque_limit"]
        for kind in KINDS:
            torque = np.abs(np.asarray(case[kind]["torque"], float))
            applied = torque[:-1] if case[kind]["interpolation"] == "zoh" else torque
            assert applied.max() <= limit * (1 + 1e-6), (case["case"], kind)
        for kind in ("first", "best"):
            torque = np.abs(np.asarray(case[kind]["torque"], float))
            assert torque[0].max() < 1e-9 * limit and torque[-1].max() < 1e-9 * limit, (case["case"], kind)
        assert case["best"]["tf"] <= 1.25 * case["time_optimal_tf"], case["case"]


def test_study_plumbing_on_one_quick_run(tmp_path):
    from att_planner.tools.bench import main

    path = tmp_path / "speed.json"
    assert main(["speed", "--case", "swift", "--repeats", "1", "--best-repeats", "1", "--json", str(path)]) == 0
    (case,) = json.loads(path.read_text())["cases"]
    assert case["case"] == "swift" and case["first"]["verification"]["passes"]
    assert case["first"]["stage"] == "first" and len(case["first"]["solve_seconds_all"]) == 1
    assert case["best"]["verification"]["passes"] and case["time_optimal"]["verification"]["passes"]


def test_benchmarks_speed_section_is_generated_from_the_json():
    """BENCHMARKS.md's speed table, machine and targets are the committed JSON's (speed_report), and
    a time-optimal method stage above its target reads as not met."""
    from att_planner.tools.bench import speed_report

    payload = json.loads((BENCHMARKS / "speed.json").read_text())
    block = speed_report.section(payload)
    markdown = (BENCHMARKS.parent / "BENCHMARKS.md").read_text()
    assert block.split("\n\n")[0] in markdown                       # the table as generated
    for row in payload["cases"]:
        assert f"| {row['case']} | " in block
    slow = json.loads(json.dumps(payload))
    slow["cases"][0]["time_optimal_seconds"] = 2 * slow["targets"]["time_optimal_seconds"]
    assert "time-optimal ≤ 0.3 s — **not met**" in speed_report.section(slow)
    again = speed_report.replace_section(markdown, block)
    assert again.count(speed_report.MARKER) == 1 and again.split(speed_report.MARKER)[0] == markdown.split(
        speed_report.MARKER)[0]
