"""Slepian smooth maneuver planner: conventions, exact gradients, plans checked by the
prediction model, smooth ends, refusals. Kept small (coarse N) so the file runs in well under 60 s."""
import time

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.signal.windows import dpss

from att_msgs_py.types import Cone, Status
from att_planner import methods
from att_planner.methods import slepian as S
from att_planner.problem import ManeuverProblem
from att_planner.reference.celani_bruni import CASES, benchmark_problem
from att_planner.verification import measure, predict
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

N_SMALL, W_SMALL = 120, 7.5 / 120      # same time-bandwidth product as the paper's N = 500, W = 0.015


def _reference_tf(problem, alpha, N, W):
    """The conventions of Celani & Bruni (2021) written out naively (loop, scipy expm), independent of the module."""
    alpha = np.asarray(alpha)
    V = dpss(N, N * W, Kmax=alpha.shape[1]).T
    w = V @ alpha.T
    J = problem.spacecraft.inertia
    dw = np.vstack([np.zeros(3), np.diff(w, axis=0) * N])
    T = dw @ J.T + np.cross(w, w @ J.T)
    R = rot.dcm_NB(problem.q_initial)
    Rs = [R]
    for k in range(N):
        R = R @ expm(rot.hat(w[k] / N))
        Rs.append(R)
    return np.sqrt(np.abs(T).max() / problem.spacecraft.body_torque_max), np.array(Rs)


def _verify(problem, plan):
    traj = predict(problem, plan, steps=4 * (len(plan.t) - 1))
    trace = 3.0 - np.trace(rot.dcm_BN(problem.q_final) @ rot.dcm_NB(traj.q_BN[-1]))
    return measure(problem, plan, traj), trace


def test_basis_is_the_issue_dpss():
    V = S.slepian_basis(500, 0.015, 4)
    np.testing.assert_allclose(V, dpss(500, 7.5, Kmax=4).T)
    np.testing.assert_allclose(np.sum(V**2, axis=0), 1.0)


@pytest.mark.parametrize("case", CASES)
def test_exact_gradients_match_finite_differences(case):
    man = S.build_maneuver(benchmark_problem(case), M=6, N=80, W=7.5 / 80)
    alpha = np.random.default_rng(3).normal(size=(3, 6)) * 15.0
    ev = S.evaluate(man, alpha, jac=True)
    h = 1e-6
    for p in range(alpha.size):
        d = np.zeros(alpha.size)
        d[p] = h
        up, dn = S.evaluate(man, alpha.ravel() + d), S.evaluate(man, alpha.ravel() - d)
        np.testing.assert_allclose(ev.torque_jac[..., p], (up.torque - dn.torque) / (2 * h), atol=1e-5, rtol=1e-5)
        np.testing.assert_allclose(ev.final_jac[:, p], (up.final - dn.final) / (2 * h), atol=1e-7)
        np.testing.assert_allclose(ev.cones_jac[..., p], (up.cones - dn.cones) / (2 * h), atol=1e-7)


def test_semi_free_final_gradient_matches_finite_differences():
    pb = benchmark_problem("swift")
    pb.sensor_target = np.array([0.0, -1.0, 0.2])
    man = S.build_maneuver(pb, M=4, N=60, W=7.5 / 60)
    alpha = np.random.default_rng(4).normal(size=12) * 10.0
    ev = S.evaluate(man, alpha, jac=True)
    assert ev.final.shape == (2,)
    h = 1e-6
    fd = np.stack([(S.evaluate(man, alpha + h * e).final - S.evaluate(man, alpha - h * e).final) / (2 * h)
                   for e in np.eye(12)], axis=1)
    np.testing.assert_allclose(ev.final_jac, fd, atol=1e-7)


def test_gradient_is_regular_at_alpha_zero():
    """α = 0 (MSSA's paper start): the exp derivative must be defined, J_r(0) = I."""
    man = S.build_maneuver(benchmark_problem("earth_obs"), M=4, N=60, W=7.5 / 60)
    ev = S.evaluate(man, np.zeros(12), jac=True)
    assert np.all(np.isfinite(ev.final_jac)) and np.linalg.matrix_rank(ev.final_jac) == 3


def test_evaluation_follows_the_issue_conventions():
    pb = benchmark_problem("earth_obs")
    pb.q_initial = rot.from_axis_angle([0.3, -0.5, 0.8], 0.7)
    man = S.build_maneuver(pb, M=4, N=N_SMALL, W=W_SMALL)
    alpha = np.random.default_rng(5).normal(size=(3, 4)) * 20.0
    ev = S.evaluate(man, alpha)
    tf_ref, R_ref = _reference_tf(pb, alpha, N_SMALL, W_SMALL)
    assert man.tf_from_peak(ev.peak_torque) == pytest.approx(tf_ref, rel=1e-12)
    np.testing.assert_allclose(ev.R, R_ref, atol=1e-12)
    np.testing.assert_allclose(ev.torque[0] * man.inertia_scale,
                               np.cross(ev.omega[0], pb.spacecraft.inertia @ ev.omega[0]), atol=1e-12)


def test_minimum_time_plan_is_verified_smooth_and_reproducible():
    """Arbitrary start attitude; torque ZOH from rest through the prediction model meets the goal,
    stays outside the cones on a dense grid, and starts/ends at (nearly) zero torque."""
    pb = benchmark_problem("swift")
    q0 = rot.from_axis_angle([0.0, 0.0, 1.0], -0.4)           # sensor still clear of the cones
    pb.q_initial = q0
    pb.q_final = rot.multiply(q0, benchmark_problem("swift").q_final)
    plan = S.plan_slepian(pb, M=8, N=N_SMALL, W=W_SMALL, starts=3)
    assert plan.status in ("optimal", "feasible"), plan.message
    ver, trace = _verify(pb, plan)
    assert trace <= 1e-3
    assert ver.final_rate <= 1e-3 * ver.rate_max
    assert ver.min_cone_margin >= 0.0
    assert ver.torque_ratio <= 1.0 + 1e-9
    tmax = pb.spacecraft.body_torque_max
    assert np.abs(plan.torque[[0, 1, -3, -2, -1]]).max() <= 2e-3 * tmax      # smooth ends
    assert np.abs(plan.torque).max() == pytest.approx(tmax, rel=1e-9)         # time-optimal: T* hits T̄
    # the reported t_f and α reproduce each other under the conventions of Celani & Bruni (2021)
    tf_ref, _ = _reference_tf(pb, np.array(plan.stats["alpha"]), N_SMALL, W_SMALL)
    assert plan.duration == pytest.approx(tf_ref, rel=1e-9) == pytest.approx(plan.stats["tf"], rel=1e-9)
    # the references are the rigid-body response to the torque
    assert rot.angle_between(plan.q[-1], pb.q_final) < 0.03


def test_mssa_without_cones_from_alpha_zero_is_an_eigenaxis_rotation():
    pb = benchmark_problem("earth_obs")
    pb.cones = []
    man = S.build_maneuver(pb, M=4, N=N_SMALL, W=W_SMALL)
    res = S.solve_mssa(man)
    assert res.feasible and res.status == "optimal"
    ev = S.evaluate(man, res.alpha)
    axis = ev.omega / np.linalg.norm(ev.omega, axis=1, keepdims=True)
    big = np.linalg.norm(ev.omega, axis=1) > 0.1 * np.linalg.norm(ev.omega, axis=1).max()
    np.testing.assert_allclose(np.abs(axis[big] @ [1.0, 0.0, 0.0]), 1.0, atol=1e-6)


def test_dfsp_never_worsens_a_feasible_start_and_respects_budget():
    pb = benchmark_problem("swift")
    man = S.build_maneuver(pb, M=4, N=60, W=7.5 / 60, cone_margin=1e-3)
    start = S.solve_mssa(man, restarts=4)
    assert start.feasible
    t0 = time.perf_counter()
    res = S.solve_dfsp(man, start.alpha, time_budget=2.0)
    assert time.perf_counter() - t0 < 6.0
    assert res.feasible and res.tf <= start.tf + 1e-9
    assert [h["phase"] for h in res.stats["phases"]] == ["mmt", "mssa", "mmt", "mssa", "mmt"]


def test_goal_inside_a_cone_is_refused_with_a_clear_message():
    pb = benchmark_problem("swift")
    goal_boresight = rot.dcm_NB(pb.q_final) @ pb.sensor_axis
    pb.cones = list(pb.cones) + [Cone(goal_boresight, np.radians(10.0), "star")]
    plan = S.plan_slepian(pb, N=N_SMALL, W=W_SMALL)
    assert plan.status == Status.FAILED
    assert "goal sensor direction is inside keep-out cone star" in plan.message
    assert plan.t.size == 0


def test_start_inside_a_cone_is_refused():
    sc = Spacecraft(inertia=np.eye(3), body_torque_max=1.0)
    pb = ManeuverProblem(sc, rot.IDENTITY.copy(), rot.from_axis_angle([0, 0, 1], 1.0), np.array([1.0, 0, 0]),
                         [Cone(np.array([1.0, 0.1, 0.0]), np.radians(20.0), "sun")])
    plan = S.plan_slepian(pb, method="mssa", N=N_SMALL, W=W_SMALL)
    assert plan.status == Status.FAILED and "start sensor direction" in plan.message


def test_expired_deadline_returns_without_a_plan_or_exception():
    pb = benchmark_problem("earth_obs")
    pb.deadline = time.monotonic() - 1.0
    plan = S.plan_slepian(pb, N=N_SMALL, W=W_SMALL)
    assert plan.status in (Status.BUDGET_EXPIRED, Status.FAILED)
    assert plan.wall_time < 5.0


@pytest.mark.parametrize("kwargs, name", [
    ({"M": 40}, "M (basis size)"), ({"M": 0}, "M (basis size)"), ({"N": 5}, "N (samples)"),
    ({"W": 0.7}, "W (half-bandwidth)"), ({"method": "magic"}, "method"), ({"cone_margin": -1.0}, "cone_margin"),
    ({"bogus": 1}, "bogus"), ({"method": "mssa", "starts": 3}, "starts"),
])
def test_invalid_options_raise_value_error_naming_the_option(kwargs, name):
    """Through the registry, the one place option ranges are written."""
    kwargs = dict(kwargs)
    method = kwargs.pop("method", S.DEFAULT_METHOD)
    with pytest.raises(ValueError, match=name.replace("(", r"\(").replace(")", r"\)")):
        methods.run(method, benchmark_problem("swift"), **kwargs)
