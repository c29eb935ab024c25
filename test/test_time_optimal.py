"""Time-optimal keep-out slews (issue 4): collocation toolkit, planner and baselines.

Every plan is checked by integrating its torque through the truth dynamics (verify_profile).
"""
import time
from dataclasses import replace

import casadi as ca
import numpy as np
import pytest

from att_planner import collocation as col
from att_planner.baselines import plan_constrained_axis, plan_eigenaxis
from att_planner.bench_time_optimal import case_problem
from att_planner.cones import Cone
from att_planner.problem import (STATUS_BUDGET, STATUS_FAILED, STATUS_FEASIBLE, STATUS_OPTIMAL,
                                 ManeuverProblem)
from att_planner.time_optimal import plan_time_optimal
from att_planner.verify import verify_profile
from att_sim import rotations as rot
from att_sim.dynamics import Spacecraft

VALID = (STATUS_OPTIMAL, STATUS_FEASIBLE)


def truth_check(problem, plan, dense_fraction=400, q_goal=None):
    ver, traj = verify_profile(problem.spacecraft, problem.q_initial,
                               problem.q_final if q_goal is None else q_goal, plan.t, plan.torque,
                               interpolation=plan.interpolation, sensor_axis=problem.sensor_axis,
                               cones=problem.cones, dense_step=plan.duration / dense_fraction)
    return ver, traj


@pytest.fixture(scope="module")
def bw_plans():
    problem = case_problem("bilimoria_wie")
    return problem, plan_time_optimal(problem), plan_eigenaxis(problem)


@pytest.fixture(scope="module")
def swift_plan():
    problem = case_problem("swift")
    return problem, plan_time_optimal(problem)


# -- collocation toolkit ---------------------------------------------------------------------------

def _double_integrator(control, intervals=10):
    x, u = ca.SX.sym("x", 2), ca.SX.sym("u", 1)
    f = ca.Function("f", [x, u], [ca.vertcat(x[1], u)])
    phase = col.Phase(f, col.uniform_mesh(intervals), control=control, control_bounds=(-1, 1),
                      duration_bounds=(0.1, 10))
    tr = col.Transcription([phase])
    tr.bound_state(0, 0, [0, 0])
    tr.bound_state(0, -1, [1, 0])
    tr.minimize(tr.variables(0).duration)
    tr.build()
    guess = col.guess_from_functions(phase, 3.0, lambda t: np.stack([t / 3, np.full_like(t, 1 / 3)], -1),
                                     lambda t: np.zeros((len(t), 1)))
    return tr, tr.solve(tr.pack([guess]))


def test_collocation_double_integrator_minimum_time_is_exact_with_zoh_control():
    # rest-to-rest over a unit distance with |u| ≤ 1: t_f = 2 sqrt(1) = 2, switch at mid-time
    tr, res = _double_integrator("constant")
    assert res.success
    sol = tr.phase_solution(res.w)
    assert sol.duration == pytest.approx(2.0, abs=1e-6)
    assert np.allclose(sol.u[:5], 1.0, atol=1e-5) and np.allclose(sol.u[5:], -1.0, atol=1e-5)
    # the Hermite interpolant reproduces x = t²/2 on the first half
    assert sol.state_at(np.array([0.25]))[0, 0] == pytest.approx(0.5 * 0.5**2, abs=1e-9)


def test_collocation_linear_control_cannot_beat_the_bang_bang_bound():
    tr, res = _double_integrator("linear")
    assert res.success
    assert 2.0 - 1e-6 <= tr.phase_solution(res.w).duration < 2.1


def test_refine_mesh_bisects_only_the_listed_intervals_within_the_cap():
    mesh = col.uniform_mesh(4)
    assert np.allclose(col.refine_mesh(mesh, [1, 3]), [0, 0.25, 0.375, 0.5, 0.75, 0.875, 1])
    assert len(col.refine_mesh(mesh, [0, 1, 2, 3], max_intervals=6)) == 7


# -- time-optimal planner --------------------------------------------------------------------------

def test_unconstrained_symmetric_slew_beats_eigenaxis_by_8_percent(bw_plans):
    problem, plan, eig = bw_plans
    assert plan.status in VALID and eig.status in VALID
    assert eig.duration == pytest.approx(2 * np.sqrt(np.pi), rel=1e-9)
    assert plan.duration <= 0.92 * eig.duration
    assert plan.duration <= 3.25                    # literature ≈ 3.243 (Bilimoria & Wie)
    ver, _ = truth_check(problem, plan)
    assert plan.interpolation == "zoh"
    assert ver.final_attitude_error <= np.deg2rad(0.5) and ver.final_rate <= 1e-2
    assert ver.torque_ratio <= 1.0 + 1e-9
    # a bang-bang answer with precession: the off-axis torques are used
    assert np.abs(plan.torque[:, :2]).max() > 0.9


def test_cone_constraints_hold_on_a_dense_grid(swift_plan):
    problem, plan = swift_plan
    assert plan.status in VALID
    ver, traj = truth_check(problem, plan)
    assert ver.dense_samples >= 400
    assert ver.min_cone_margin >= 0.0
    assert ver.final_attitude_error <= np.deg2rad(0.5) and ver.final_rate <= 1e-2
    assert ver.torque_ratio <= 1.0 + 1e-9
    assert plan.duration <= 3.5
    # the eigenaxis slew of the same problem goes through the Sun cone: the constraint is active
    eig = plan_eigenaxis(problem)
    assert eig.status == STATUS_FAILED and eig.stats["verification"]["min_cone_margin"] < 0
    # every start is reported
    assert len(plan.stats["starts"]) >= 2 and all("tf" in s for s in plan.stats["starts"])


@pytest.mark.parametrize("case", ["bilimoria_wie", "swift"])
def test_semi_free_final_attitude_is_never_slower(case, bw_plans, swift_plan):
    problem, full = (bw_plans[0], bw_plans[1]) if case == "bilimoria_wie" else swift_plan
    target = rot.dcm(problem.q_final) @ problem.sensor_axis
    semi = plan_time_optimal(replace(problem, sensor_target=target))
    assert semi.status in VALID
    assert semi.duration <= full.duration + 1e-6
    ver, traj = truth_check(problem, semi, q_goal=semi.q[-1])
    pointing = np.arccos(np.clip(rot.dcm(traj.q[-1]) @ problem.sensor_axis @ target, -1, 1))
    assert pointing <= np.deg2rad(0.5) and ver.final_rate <= 1e-2 and ver.min_cone_margin >= 0


def test_arbitrary_initial_attitude_gives_the_same_time(swift_plan):
    problem, plan = swift_plan
    frame = rot.from_axis_angle([0.3, -0.5, 0.8], 1.1)        # rotate the whole scene
    R = rot.dcm(frame)
    moved = replace(problem, q_initial=rot.multiply(frame, problem.q_initial),
                    q_final=rot.multiply(frame, problem.q_final),
                    cones=[Cone(R @ c.direction, c.half_angle, c.name) for c in problem.cones])
    other = plan_time_optimal(moved)
    assert other.status in VALID
    assert other.duration == pytest.approx(plan.duration, rel=1e-3)
    ver, _ = truth_check(moved, other)
    assert ver.min_cone_margin >= 0 and ver.final_attitude_error <= np.deg2rad(0.5)


def test_rate_and_wheel_momentum_bounds_hold_on_the_truth_trajectory_and_cost_time(bw_plans):
    problem, free, _ = bw_plans
    plan = plan_time_optimal(problem, rate_max=1.5, wheel_momentum_max=1.2, starts=1)
    assert plan.status in VALID
    _, traj = truth_check(problem, plan)
    assert np.abs(traj.omega).max() <= 1.5                      # per-axis body rate
    assert np.abs(traj.omega @ problem.spacecraft.inertia).max() <= 1.2   # wheel momentum, G = I
    assert plan.duration > free.duration
    assert plan.stats["verification"]["wheel_momentum_ratio"] <= 1.0


def test_plans_of_other_methods_serve_as_warm_starts():
    problem = case_problem("swift")
    seed = plan_constrained_axis(problem)
    plan = plan_time_optimal(problem, starts=1, warm_starts=[seed])
    labels = [s["route"] for s in plan.stats["starts"]]
    assert labels[-1] == "warm start: constrained_axis" and len(labels) == 2
    assert plan.status in VALID and plan.duration < seed.duration


def test_deadline_returns_quickly_with_a_status_that_says_so():
    problem = case_problem("swift")
    problem.deadline = time.monotonic() + 1.5
    t0 = time.monotonic()
    plan = plan_time_optimal(problem)
    assert time.monotonic() - t0 < 4.0
    assert plan.status in (STATUS_BUDGET, STATUS_FAILED)
    if plan.status == STATUS_BUDGET:
        ver, _ = truth_check(problem, plan, dense_fraction=500)
        assert ver.min_cone_margin >= 0


def test_infeasible_request_fails_without_raising():
    problem = case_problem("swift")
    # goal puts the sensor on the Sun: no plan exists
    sun = problem.cones[0].direction
    problem.q_final = rot.from_axis_angle([0, 0, 1], np.arctan2(sun[1], sun[0]))
    plan = plan_time_optimal(problem)
    assert plan.status == STATUS_FAILED and "inside keep-out cone sun" in plan.message


def test_null_maneuver_is_answered_without_solving():
    problem = case_problem("swift")
    problem.q_final = -problem.q_initial                      # the same attitude
    plan = plan_time_optimal(problem)
    assert plan.status == STATUS_OPTIMAL and plan.duration == 0.0


def test_solver_failure_is_reported_not_raised():
    plan = plan_time_optimal(case_problem("swift"), starts=2, max_iter=3)
    assert plan.status == STATUS_FAILED and "no start converged" in plan.message
    assert len(plan.stats["starts"]) == 2


def test_invalid_options_raise_value_error():
    problem = case_problem("bilimoria_wie")
    with pytest.raises(ValueError, match="interpolation"):
        plan_time_optimal(problem, interpolation="cubic")
    with pytest.raises(ValueError, match="rate_max"):
        plan_time_optimal(problem, rate_max=-1.0)


# -- baselines -------------------------------------------------------------------------------------

def test_constrained_axis_rides_a_cone_and_verifies(swift_plan):
    problem, best = swift_plan
    plan = plan_constrained_axis(problem)
    assert plan.status == STATUS_FEASIBLE
    ver, _ = truth_check(problem, plan)
    assert ver.min_cone_margin >= 0 and ver.final_attitude_error <= np.deg2rad(0.5)
    assert any("ride" in leg["label"] for leg in plan.stats["legs"])
    # each leg takes 2 sqrt(φ I_a / T_a) (J = I: T_a = T̄ / max|e_j|)
    assert plan.duration == pytest.approx(sum(leg["duration"] for leg in plan.stats["legs"]))
    assert plan.duration > best.duration


def test_eigenaxis_with_a_gyroscopic_term_stays_within_limits_and_arrives():
    sc = Spacecraft(np.diag([1.0, 2.0, 3.0]), body_torque_max=0.5)
    problem = ManeuverProblem(sc, rot.from_axis_angle([1, 0, 0], 0.3), rot.from_axis_angle([1, 1, 1], 2.0))
    plan = plan_eigenaxis(problem)
    ver, _ = truth_check(problem, plan, dense_fraction=200)
    assert plan.status == STATUS_FEASIBLE
    assert ver.torque_ratio <= 1.0 + 1e-9 and ver.final_attitude_error <= np.deg2rad(0.5)
    assert ver.final_rate <= 1e-2


def test_smooth_plan_warm_starts_the_collocation():
    problem = case_problem("swift")
    plan = plan_time_optimal(replace(problem, deadline=time.monotonic() + 40), starts=1, smooth_warm_start=True)
    labels = [start["route"] for start in plan.stats["starts"]]
    assert any("slepian" in label for label in labels), labels
    assert plan.status in ("optimal", "feasible") and plan.duration < 3.5
