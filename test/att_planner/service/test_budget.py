"""Every method honours the time budget (+ 1 s) with its most expensive allowed options, through
the service logic and the runners the planner node uses (in-process for cheap methods, a child
process otherwise); oversize plans are refused before they are verified or sent."""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest
from rclpy.serialization import serialize_message

from att_msgs_py import convert
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Cone, Plan, Status
from att_msgs_py.validation import MAX_NAME_LENGTH, MAX_PLAN_BYTES, MAX_PLAN_SAMPLES, MAX_TEXT_LENGTH
from att_planner import methods
from att_planner.service import planning
from att_planner.service.planning import plan_maneuver, prepare, run_method
from att_planner.service.requests import MAX_CONES, ManeuverRequest, validate_maneuver
from att_planner.service.worker import run_isolated, warm_up
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen

BUDGET = 0.5            # s
GRACE = 1.0             # s an answer may come after the budget
SENSOR = np.array([1.0, 0.0, 0.0])
GOAL = rot.from_axis_angle(np.array([0.0, 0.3, 1.0]) / math.hypot(0.3, 1.0), math.radians(170))


def most_expensive(method: methods.Method) -> dict:
    """Every option at the top of its range: the largest sizes, counts and rounds (the limits among
    them are then at their loosest, and the Slepian half-bandwidth allows the largest basis), the
    swarm first (``global_stage``). ``boundary_cone`` is left out: it names a cone whose boundary
    both ends lie on, which these skies do not have (a forced arc adds one row per point)."""
    return {name: spec.high for name, spec in method.options.items() if name != "boundary_cone"}


def sky(kind: str) -> list:
    """No cones, or ``MAX_CONES`` small cones clear of both ends: scattered over the sky, or along
    the eigenaxis path (so the cone-aware methods have to search and the fallback is blocked)."""
    if kind == "none":
        return []
    rng = np.random.default_rng(3)
    ends = [SENSOR, rot.dcm_NB(GOAL) @ SENSOR]
    path = rot.dcm_NB(rot.slerp(rot.IDENTITY, GOAL, np.linspace(0.15, 0.85, MAX_CONES))) @ SENSOR
    cones = []
    while len(cones) < MAX_CONES:
        d = path[len(cones)] if kind == "blocking" else rng.normal(size=3)
        d = d / np.linalg.norm(d)
        if all(math.acos(np.clip(e @ d, -1, 1)) > math.radians(12) for e in ends):
            cones.append((d, math.radians(6), f"c{len(cones)}"))
        elif kind == "blocking":
            cones.append((-d, math.radians(6), f"c{len(cones)}"))
    return cones


CASES = [(m.name, kind) for m in methods.REGISTRY for kind in ("none", "scattered", "blocking")]


@pytest.fixture(scope="module", autouse=True)
def started_planner():
    warm_up()                                           # as the planner node does at start-up
    prepare(scen.load("swift_demo").spacecraft)


@pytest.mark.slow
@pytest.mark.parametrize("name, kind", CASES, ids=[f"{n}-{k}" for n, k in CASES])
def test_every_method_answers_within_its_budget_with_its_most_expensive_options(name, kind):
    method = methods.get(name)
    options = most_expensive(method)
    req = ManeuverRequest("eci", rot.IDENTITY, GOAL, SENSOR, sky(kind), method=name, time_budget=BUDGET,
                          option_names=list(options), option_values=[float(v) for v in options.values()])
    start = time.monotonic()
    valid = validate_maneuver(req, frame_id="eci", default_spacecraft="swift_demo", default_method=name,
                              default_budget=BUDGET)
    outcome = plan_maneuver(valid, cone_padding=math.radians(1.0), runner=run_method if method.cheap else run_isolated)
    elapsed = time.monotonic() - start
    assert elapsed < BUDGET + GRACE, f"{name} {options}: answered after {elapsed:.2f} s ({outcome.message})"
    assert outcome.code in ErrorCode, outcome
    if outcome.code == ErrorCode.OK:
        assert outcome.verification is not None and outcome.verification.min_cone_margin >= 0


def test_plan_samples_are_capped_by_the_registry():
    """No method option can ask for more samples than a plan may carry."""
    assert methods.get("eigenaxis_smooth").options["samples"].high <= MAX_PLAN_SAMPLES
    for name in ("slepian_minimum_time", "mssa", "dfsp"):
        assert methods.get(name).options["N"].high + 1 <= MAX_PLAN_SAMPLES


def test_a_plan_above_the_sample_cap_is_refused_before_verification():
    n = MAX_PLAN_SAMPLES + 1
    huge = Plan(t=np.linspace(0, 10, n), torque=np.zeros((n, 3)), q=np.tile(rot.IDENTITY, (n, 1)),
                omega=np.zeros((n, 3)), method="bloat", status=Status.OPTIMAL)
    req = ManeuverRequest("eci", rot.IDENTITY, GOAL, SENSOR, [], method="eigenaxis", time_budget=2.0)
    valid = validate_maneuver(req, frame_id="eci", default_spacecraft="swift_demo", default_method="eigenaxis",
                              default_budget=2.0)
    start = time.monotonic()
    outcome = plan_maneuver(valid, runner=lambda method, problem, options, wait: huge)
    assert time.monotonic() - start < 0.5                  # not verified (that would take seconds)
    assert outcome.code == ErrorCode.SIZE_LIMIT and outcome.plan is None
    assert f"{n} samples" in outcome.message and str(MAX_PLAN_SAMPLES) in outcome.message


def test_a_plan_too_late_to_verify_is_replaced_by_the_first_plan(monkeypatch):
    def late(method, problem, options, wait):
        time.sleep(max(0.0, problem.deadline - time.monotonic()) + 0.4)       # wait-ok: a method past its budget
        # the verification cost is estimated from measured steps: pin it (1 ms a step, 6 s for this plan)
        # so the plan is too late on a fast idle machine as on a busy one (the first plan was verified)
        monkeypatch.setattr(planning, "_step_seconds", 1e-3)
        return run_method(methods.get("eigenaxis_smooth"), problem, {"samples": 4001}, wait)

    req = ManeuverRequest("eci", rot.IDENTITY, GOAL, SENSOR, [], method="time_optimal", time_budget=1.0)
    valid = validate_maneuver(req, frame_id="eci", default_spacecraft="swift_demo", default_method="time_optimal",
                              default_budget=1.0)
    outcome = plan_maneuver(valid, runner=late)
    assert outcome.code == ErrorCode.OK and outcome.plan.status == Status.BUDGET_EXPIRED
    assert "too late to verify" in outcome.message and outcome.plan.method == "graph_smooth"


def test_the_largest_plan_fits_the_message_size_cap():
    """A plan of MAX_PLAN_SAMPLES samples, the most cones, the longest strings: below MAX_PLAN_BYTES."""
    n = MAX_PLAN_SAMPLES
    name = "n" * MAX_NAME_LENGTH
    plan = Plan(t=np.linspace(0, 10, n), torque=np.ones((n, 3)), q=np.tile(rot.IDENTITY, (n, 1)),
                omega=np.ones((n, 3)), method=name, status=Status.OPTIMAL, message="m" * MAX_TEXT_LENGTH,
                plan_id=name, spacecraft=name, frame_id=name, spacecraft_digest="d" * 64, key_id="k" * 16,
                signature=b"s" * 64, cones=[Cone(np.array([0.0, 0, 1]), 0.1, name)] * MAX_CONES)
    size = len(serialize_message(convert.plan_msg(replace(plan))))
    assert size < MAX_PLAN_BYTES, f"{size} bytes"
