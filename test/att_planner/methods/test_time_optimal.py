"""Time-optimal keep-out slews: the collocation planner against its baselines.

Every plan is checked by integrating its torque through the prediction model (att_planner.verification).
"""
import time
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.types import Cone, Status
from att_planner import methods
from att_planner.methods.constrained_axis import plan_constrained_axis
from att_planner.methods.eigenaxis import plan_eigenaxis
from att_planner.methods.time_optimal import collocation as col
from att_planner.methods.time_optimal import mesh as meshes
from att_planner.methods.time_optimal import model, plan_time_optimal
from att_planner.reference.time_optimal_cases import case_problem
from att_sim.models import rotations as rot
from helpers.prediction import prediction_check

VALID = (Status.OPTIMAL, Status.FEASIBLE)


# -- time-optimal planner --------------------------------------------------------------------------

def test_unconstrained_symmetric_slew_beats_eigenaxis_by_8_percent(bw_plans):
    problem, plan, eig = bw_plans
    assert plan.status in VALID and eig.status in VALID
    assert eig.duration == pytest.approx(2 * np.sqrt(np.pi), rel=1e-9)
    assert plan.duration <= 0.92 * eig.duration
    assert plan.duration <= 3.25                    # literature ≈ 3.243 (Bilimoria & Wie)
    ver, _ = prediction_check(problem, plan)
    assert plan.interpolation == "zoh"
    assert ver.final_attitude_error <= np.deg2rad(0.5) and ver.final_rate <= 1e-2
    assert ver.torque_ratio <= 1.0 + 1e-9
    # a bang-bang answer with precession: the off-axis torques are used
    assert np.abs(plan.torque[:, :2]).max() > 0.9


def test_cone_constraints_hold_on_a_dense_grid(swift_plan):
    problem, plan = swift_plan
    assert plan.status in VALID
    ver, traj = prediction_check(problem, plan)
    assert ver.dense_samples >= 400
    assert ver.min_cone_margin >= 0.0
    assert ver.final_attitude_error <= np.deg2rad(0.5) and ver.final_rate <= 1e-2
    assert ver.torque_ratio <= 1.0 + 1e-9
    assert plan.duration <= 3.5
    # the eigenaxis slew of the same problem goes through the Sun cone: the constraint is active
    eig = plan_eigenaxis(problem)
    assert eig.status == Status.FAILED and eig.verification.min_cone_margin < 0
    # every start is reported
    assert len(plan.stats["starts"]) >= 2 and all("tf" in s for s in plan.stats["starts"])


def test_swift_plan_is_within_half_a_percent_of_its_optimum_after_one_refinement(swift_plan):
    """One refinement round in quarters (the default) instead of three bisections; t_f
    within 0.5 % of the 3.06648 TU those reached, and the plan verified."""
    problem, plan = swift_plan
    assert plan.duration == pytest.approx(3.06648, rel=5e-3) and plan.duration >= 3.06648 * (1 - 1e-4)
    assert [m["intervals"] for m in plan.stats["mesh"]][:1] == [16] and len(plan.stats["mesh"]) == 2
    ver, _ = prediction_check(problem, plan)
    assert ver.min_cone_margin >= 0 and ver.final_attitude_error <= np.deg2rad(0.5)


def test_an_nlp_is_built_once_per_shape_and_shared(monkeypatch):
    """Two problems of one shape (other cones, the same count) share one built NLP, each with its
    own parameters; the bang-bang NLP watches its deadline only (no incumbent), the smooth one keeps it."""
    monkeypatch.setattr(model, "_NLPS", {})
    built = []
    build = col.Transcription.build
    monkeypatch.setattr(col.Transcription, "build", lambda self, **kw: built.append(kw) or build(self, **kw))
    problem = case_problem("swift")
    other = replace(problem, cones=[Cone(-c.direction, c.half_angle, c.name) for c in problem.cones])
    s, mesh = model.scaling(problem), meshes.uniform_mesh(8)
    first, second = (model.transcription(p, s, mesh, "constant", 1e-3, (0.1, 10.0)) for p in (problem, other))
    assert len(built) == 1 and first._solver is second._solver
    assert not np.allclose(first.phases[0].path_parameters, second.phases[0].path_parameters)
    assert not first._callback.incumbents
    smooth = model.transcription(problem, s, mesh, "constant", 1e-3, (0.1, 10.0), torque_accel=10.0)
    assert len(built) == 2 and smooth._callback.incumbents


@pytest.mark.parametrize("case", ["bilimoria_wie", "swift"])
def test_semi_free_final_attitude_is_never_slower(case, bw_plans, swift_plan):
    problem, full = (bw_plans[0], bw_plans[1]) if case == "bilimoria_wie" else swift_plan
    target = rot.dcm_NB(problem.q_final) @ problem.sensor_axis
    semi = plan_time_optimal(replace(problem, sensor_target=target))
    assert semi.status in VALID
    assert semi.duration <= full.duration + 1e-6
    ver, traj = prediction_check(problem, semi)
    pointing = np.arccos(np.clip(rot.dcm_NB(traj.q_BN[-1]) @ problem.sensor_axis @ target, -1, 1))
    assert pointing <= np.deg2rad(0.5) and ver.final_rate <= 1e-2 and ver.min_cone_margin >= 0


def test_arbitrary_initial_attitude_gives_the_same_time(swift_plan):
    problem, plan = swift_plan
    frame = rot.from_axis_angle([0.3, -0.5, 0.8], 1.1)        # rotate the whole scene
    R = rot.dcm_NB(frame)
    moved = replace(problem, q_initial=rot.multiply(frame, problem.q_initial),
                    q_final=rot.multiply(frame, problem.q_final),
                    cones=[Cone(R @ c.direction, c.half_angle, c.name) for c in problem.cones])
    other = plan_time_optimal(moved)
    assert other.status in VALID
    assert other.duration == pytest.approx(plan.duration, rel=1e-3)
    ver, _ = prediction_check(moved, other)
    assert ver.min_cone_margin >= 0 and ver.final_attitude_error <= np.deg2rad(0.5)


def test_rate_and_wheel_momentum_bounds_hold_on_the_truth_trajectory_and_cost_time(bw_plans):
    problem, free, _ = bw_plans
    bounded = replace(problem, rate_max=1.5, wheel_momentum_max=1.2)
    plan = plan_time_optimal(bounded, starts=1)
    assert plan.status in VALID
    _, traj = prediction_check(problem, plan)
    assert np.abs(traj.omega_BN_B).max() <= 1.5                      # per-axis body rate
    assert np.abs(traj.omega_BN_B @ problem.spacecraft.inertia).max() <= 1.2   # wheel momentum, G = I
    assert plan.duration > free.duration
    assert plan.verification.wheel_momentum_ratio <= 1.0


def test_momentum_bound_on_a_spacecraft_without_wheels_binds_nothing():
    """No wheels hold no wheel momentum: the bound neither constrains the NLP nor breaks the
    route warm starts (they raised on the empty G⁺)."""
    problem = case_problem("bilimoria_wie")
    wheelless = replace(problem, spacecraft=replace(problem.spacecraft, wheel_axes=np.zeros((3, 0))))
    free = plan_time_optimal(wheelless, starts=1)
    bounded = plan_time_optimal(replace(wheelless, wheel_momentum_max=1e-3), starts=1)
    assert bounded.status in VALID, bounded.message
    assert bounded.verification.wheel_momentum_ratio == 0.0
    assert bounded.duration == pytest.approx(free.duration, rel=1e-9)


def test_plans_of_other_methods_serve_as_warm_starts():
    problem = case_problem("swift")
    seed = plan_constrained_axis(problem)
    plan = plan_time_optimal(problem, starts=1, warm_starts=[seed])
    labels = [s["route"] for s in plan.stats["starts"]]
    assert labels[-1] == "warm start: constrained_axis" and len(labels) == 2
    assert plan.status in VALID and plan.duration < seed.duration


def test_deadline_returns_quickly_with_a_status_that_says_so():
    problem = case_problem("swift")
    problem.deadline = time.monotonic() + 1.02        # 20 ms to solve (a second is kept for the verification)
    t0 = time.monotonic()
    plan = plan_time_optimal(problem)
    assert time.monotonic() - t0 < 4.0
    assert plan.status in (Status.BUDGET_EXPIRED, Status.FAILED)
    if plan.status == Status.BUDGET_EXPIRED:
        ver, _ = prediction_check(problem, plan, dense_fraction=500)
        assert ver.min_cone_margin >= 0


def test_infeasible_request_fails_without_raising():
    problem = case_problem("swift")
    # goal puts the sensor on the Sun: no plan exists
    sun = problem.cones[0].direction
    problem.q_final = rot.from_axis_angle([0, 0, 1], np.arctan2(sun[1], sun[0]))
    plan = plan_time_optimal(problem)
    assert plan.status == Status.FAILED and "inside keep-out cone sun" in plan.message


def test_null_maneuver_is_answered_without_solving():
    problem = case_problem("swift")
    problem.q_final = -problem.q_initial                      # the same attitude
    plan = plan_time_optimal(problem)
    assert plan.status == Status.OPTIMAL and plan.duration == 0.0


def test_solver_failure_is_reported_not_raised():
    plan = plan_time_optimal(case_problem("swift"), starts=2, max_iter=3)
    assert plan.status == Status.FAILED and "no start converged" in plan.message
    assert len(plan.stats["starts"]) == 2


def test_invalid_options_raise_value_error():
    problem = case_problem("bilimoria_wie")
    with pytest.raises(ValueError, match="interpolation"):
        plan_time_optimal(problem, interpolation="cubic")
    with pytest.raises(ValueError, match="intervals"):
        plan_time_optimal(problem, intervals=0)                 # not silently the default 30
    with pytest.raises(ValueError, match="rate_max"):
        methods.run("time_optimal", problem, rate_max=-1.0)      # the registry holds the ranges


def test_smooth_plan_warm_starts_the_collocation():
    problem = case_problem("swift")
    plan = plan_time_optimal(replace(problem, deadline=time.monotonic() + 40), starts=1, smooth_warm_start=True)
    labels = [start["route"] for start in plan.stats["starts"]]
    assert any("slepian" in label for label in labels), labels
    assert plan.status in ("optimal", "feasible") and plan.duration < 3.5
