"""``att-bench time-optimal --case {ba1,ba2,bp1,bp2}``: an INDEPENDENT check of the
committed benchmarks/time_optimal_<case>.json, and the study's plumbing.

The check uses nothing of the suite: it integrates the plan's ZOH torque from rest at ``q_initial``
with its own RK4 (:mod:`helpers.own_rk4`, 40 steps per interval: about 2000 over the plan) and
measures the boresight against the JSON's cone itself. It confirms the benchmark's claims: the final
boresight within 0.01° of ``sensor_target`` and at rest; for BA the boresight within 1e-4 rad of the
cone's boundary at every sample; for BP margins ≥ −1e-6 rad within 0.01 rad of the path's ends (the
boundary points; docs/errors.md, 112) and ≥ 0 everywhere else; BP ≤ BA ≤ λ-rotation for
each cone. ``ATT_TO_BENCHMARKS=DIR`` checks the JSONs of another directory.
"""
from __future__ import annotations

import json
import math
import os
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from helpers.own_rk4 import dcm_NB, integrate

BENCHMARKS = Path(os.environ.get("ATT_TO_BENCHMARKS", Path(__file__).resolve().parents[3] / "benchmarks"))
CASES = ("ba1", "ba2", "bp1", "bp2")
SUBSTEPS = 40
END_RADIUS = 0.01          # rad: the documented neighbourhood of an end direction
END_TOLERANCE = 1e-6       # rad: how far inside a boundary an end may lie
ARC_TOLERANCE = 1e-4       # rad: a boundary arc's band


@cache
def _checked(case: str):
    """The committed JSON, the dense boresight path and its margins from the JSON's cone."""
    payload = json.loads((BENCHMARKS / f"time_optimal_{case}.json").read_text())
    times, states = integrate(payload["J"], np.asarray(payload["t"], float), payload["torque"],
                              payload["q_initial"], SUBSTEPS, dense=True)
    b = dcm_NB(states[:, :4]) @ np.asarray(payload["sensor_axis"], float)
    cone = payload["cones"][0]
    margin = np.arccos(np.clip(b @ np.asarray(cone["direction"], float), -1.0, 1.0)) - cone["half_angle"]
    return payload, times, states, b, margin


@pytest.mark.parametrize("case", CASES)
def test_format_is_the_issues(case):
    payload = _checked(case)[0]
    for key in ("case", "method", "tf", "t", "torque", "interpolation", "solve_seconds", "verification",
                "sensor_axis", "cones", "semi_free", "sensor_target", "J", "q_initial", "plans"):
        assert key in payload, key
    assert payload["semi_free"] is True and payload["interpolation"] == "zoh" and payload["case"] == case
    assert payload["boundary_arc"] == case.startswith("ba")
    assert set(payload["cones"][0]) >= {"direction", "half_angle"}
    assert np.abs(payload["torque"]).max() <= payload["torque_limit"] * (1 + 1e-9)
    assert payload["tf"] == pytest.approx(payload["t"][-1], rel=1e-12) and payload["verification"]["passes"]


@pytest.mark.parametrize("case", CASES)
def test_the_final_boresight_reaches_its_target_at_rest(case):
    payload, times, states, b, _ = _checked(case)
    target = np.asarray(payload["sensor_target"], float)
    assert math.degrees(math.acos(min(1.0, float(b[-1] @ target)))) <= 0.01
    assert np.linalg.norm(states[-1, 4:]) <= 1e-3 and len(times) >= 1500


@pytest.mark.parametrize("case", ("ba1", "ba2"))
def test_a_boundary_arc_stays_on_the_boundary(case):
    margin = _checked(case)[4]
    assert np.abs(margin).max() <= ARC_TOLERANCE, f"{np.abs(margin).max():.3g} rad off the boundary"


@pytest.mark.parametrize("case", ("bp1", "bp2"))
def test_boundary_points_touch_the_cone_only_at_the_ends(case):
    _, _, _, b, margin = _checked(case)
    near_end = np.zeros(len(b), bool)
    for end in (b[0], b[-1]):
        near_end |= np.arccos(np.clip(b @ end, -1.0, 1.0)) <= END_RADIUS
    assert abs(margin[0]) <= END_TOLERANCE and abs(margin[-1]) <= END_TOLERANCE     # the ends lie on the boundary
    assert margin[near_end].min() >= -END_TOLERANCE
    assert margin[~near_end].min() >= 0.0
    assert margin.max() > 10 * ARC_TOLERANCE            # in between it leaves the boundary (BP2: by 0.21° at most)


@pytest.mark.parametrize("cone", ("1", "2"))
def test_boundary_points_are_not_slower_than_the_arc_nor_the_arc_than_the_lambda_rotation(cone):
    ba, bp = _checked("ba" + cone)[0], _checked("bp" + cone)[0]
    assert bp["tf"] <= ba["tf"] <= ba["plans"]["lambda_rotation"]["tf"]
    assert ba["plans"]["lambda_rotation"]["passes"]


def test_study_plumbing_of_a_boundary_case(tmp_path):
    """The study end to end on BP2 (every plan verified, the JSON written)."""
    from att_planner.tools.bench import main

    path = tmp_path / "bp2.json"
    assert main(["time-optimal", "--case", "bp2", "--json", str(path)]) == 0
    payload = json.loads(path.read_text())
    assert set(payload["plans"]) == {"time_optimal", "time_optimal_two_stage", "constrained_axis", "lambda_rotation"}
    assert all(p["passes"] for p in payload["plans"].values())
    assert payload["plans"]["time_optimal_two_stage"]["swarm_iterations"] > 0
    assert payload["tf"] <= payload["plans"]["lambda_rotation"]["tf"]
