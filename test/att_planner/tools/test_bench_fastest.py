"""``att-bench fastest``: an INDEPENDENT check of the committed benchmarks/fastest*.json.

The check uses nothing of the suite: from each set's problem in the JSON it integrates the
time-optimal answer's torque (and, on a few sets, the first and smooth plans') from rest with its
own RK4 (:mod:`helpers.own_rk4`) and measures the final attitude, the final rate, the torque against
its limit and the boresight against the JSON's cones; and it recounts the violations from the t_f of
the answers. ``ATT_FASTEST_BENCHMARKS=DIR`` checks the JSONs of another directory.
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

BENCHMARKS = Path(os.environ.get("ATT_FASTEST_BENCHMARKS", Path(__file__).resolve().parents[3] / "benchmarks"))
SUBSTEPS = 20
ATTITUDE_RAD = math.radians(0.5)       # final attitude error accepted (the suite's tolerance, written again)
RATE_RAD_S = 1e-3                      # final rate accepted
PENETRATION_RAD = 1e-4                 # a boresight sample between knots may graze a cone by this
ALL_PLANS = (0, 1, 2)                  # sets whose first and smooth plans are integrated too
FILES = ("fastest.json", "fastest_coarse.json")


@cache
def payload(name: str) -> dict:
    return json.loads((BENCHMARKS / name).read_text())


def flown(problem: dict, plan: dict) -> dict:
    """The plan's torque integrated from rest: final attitude error, final rate, torque ratio, least cone margin."""
    profile = plan["profile"]
    times, states = integrate(problem["J"], np.asarray(profile["t"], float), profile["torque"], problem["q_initial"],
                              SUBSTEPS, dense=True, interpolation=plan["interpolation"])
    qf = np.asarray(problem["q_final"], float)
    error = 2.0 * math.acos(min(1.0, abs(float(states[-1, :4] @ qf))))
    b = dcm_NB(states[:, :4]) @ np.asarray(problem["sensor_axis"], float)
    margins = [np.arccos(np.clip(b @ np.asarray(c["direction"], float), -1.0, 1.0)) - math.radians(c["half_angle_deg"])
               for c in problem["cones"]]
    return {"error": error, "rate": float(np.linalg.norm(states[-1, 4:])), "margin": float(np.min(margins)),
            "torque": float(np.abs(profile["torque"]).max()) / problem["torque_limit"]}


@pytest.mark.parametrize("name", FILES)
def test_every_time_optimal_answer_flies_to_its_goal_clear_of_every_cone(name):
    sets = payload(name)["sets"]
    assert len(sets) == payload(name)["fastest_sets"] >= 1
    for s in sets:
        names = ("graph_smooth", "smooth_collocation", "time_optimal") if s["seed"] in ALL_PLANS else ("time_optimal",)
        for name in names:
            plan = s["plans"][name]
            assert plan["verified"], (s["seed"], name)
            got = flown(s, plan)
            assert got["error"] < ATTITUDE_RAD and got["rate"] < RATE_RAD_S, (s["seed"], name, got)
            assert got["torque"] <= 1 + 1e-6 and got["margin"] > -PENETRATION_RAD, (s["seed"], name, got)
            assert plan["tf"] == pytest.approx(plan["profile"]["t"][-1], rel=1e-9)


@pytest.mark.parametrize("name", FILES)
def test_the_violations_are_recounted_from_the_answers(name):
    p = payload(name)
    recount = []
    for s in p["sets"]:
        plans = s["plans"]
        bound = min(plans[m]["tf"] for m in ("graph_smooth", "smooth_collocation") if plans[m]["verified"])
        to = plans["time_optimal"]
        if not to["verified"] or to["tf"] > bound + 1e-9:
            recount.append(s["seed"])
    assert recount == [v["seed"] for v in p["violations"]]
    assert p["passed"] == (not p["violations"] and not p["unverified"])
