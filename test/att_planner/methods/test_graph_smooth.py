"""graph_smooth, the constructive first plan: exact arc checks, verified plans round fixed and moving
zones, a C¹ torque that vanishes at every leg's ends, and an honest failure when no way exists."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.types import Cone, Status
from att_planner.methods.graph_smooth import EDGE_MARGIN, arc_cosines, plan_graph_smooth, septic
from att_planner.problem import ManeuverProblem
from att_planner.reference.celani_bruni import benchmark_problem
from att_planner.tools.bench.sky import case_problem
from att_planner.verification import rejection, verify
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft


def test_arc_extremes_are_those_of_the_sampled_arc():
    rng = np.random.default_rng(3)
    b = rot.normalize(rng.normal(size=(200, 3)))[:, :3]
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    n = rng.normal(size=(200, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    a = rng.normal(size=(200, 3))
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    phi = rng.uniform(0.0, 2 * np.pi, 200)
    low, high = arc_cosines(b, n, phi, a)
    theta = np.linspace(0.0, 1.0, 20001)[None, :] * phi[:, None]
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    nb = np.sum(n * b, axis=1)[:, None, None]
    path = b[:, None] * c + np.cross(n, b)[:, None] * s + n[:, None] * nb * (1 - c)
    dots = np.einsum("kij,kj->ki", path, a)
    np.testing.assert_allclose(high, dots.max(axis=1), atol=1e-7)
    np.testing.assert_allclose(low, dots.min(axis=1), atol=1e-7)
    assert np.all(high >= dots.max(axis=1) - 1e-12) and np.all(low <= dots.min(axis=1) + 1e-12)


def _knot_checks(plan, tmax):
    """The torque vanishes at both ends and at every leg's ends, and stays within the limit."""
    legs = plan.stats["legs"]
    ends = np.cumsum([0.0] + [leg["duration"] for leg in legs])
    at_ends = np.abs(plan.torque[np.searchsorted(plan.t, ends - 1e-9 * ends[-1])]).max()
    assert at_ends < 1e-12 * tmax
    assert np.abs(plan.torque).max() <= tmax * (1 + 1e-12)


@pytest.mark.parametrize("case", ["swift", "earth_obs"])
def test_published_cases_plan_round_the_cones_and_verify(case):
    problem = benchmark_problem(case)
    plan = plan_graph_smooth(problem)
    assert plan.status == Status.FEASIBLE and plan.interpolation == "linear"
    ver = verify(problem, plan)
    assert rejection(ver) is None, rejection(ver)
    assert ver.min_cone_margin > 0.5 * EDGE_MARGIN
    _knot_checks(plan, problem.spacecraft.body_torque_max)
    # the eigenaxis slew enters a cone here, so the plan is not one leg about the eigenaxis
    assert len(plan.stats["legs"]) >= 2


def test_moving_zones_are_cleared_at_their_true_positions():
    """leo_observatory: the Earth limb rises over the start; the plan is verified against the true sky."""
    _, problem = case_problem("leo_observatory")
    plan = plan_graph_smooth(problem)
    ver = verify(problem, plan)
    assert rejection(ver) is None, rejection(ver)
    _knot_checks(plan, problem.spacecraft.body_torque_max)


def test_without_zones_it_is_the_smooth_eigenaxis_slew():
    """One leg about the eigenaxis; with J = I its duration is sqrt(φ max_j |e_j| max|p''| / T̄) (the
    gyroscopic term vanishes) and the attitude reached is the goal."""
    sc = Spacecraft(np.eye(3), body_torque_max=2.0)
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    problem = ManeuverProblem(sc, rot.IDENTITY, rot.from_axis_angle(axis, 2.0))
    plan = plan_graph_smooth(problem)
    (leg,) = plan.stats["legs"]
    s = np.linspace(0.0, 1.0, 64)
    assert leg["duration"] == pytest.approx(math.sqrt(2.0 * np.abs(axis).max() * np.abs(septic(s)[2]).max() / 2.0))
    assert rot.angle_between(plan.q[-1], problem.q_final) < 1e-12
    assert rejection(verify(problem, plan)) is None


def test_semi_free_goal_points_the_sensor_at_its_target():
    swift = benchmark_problem("swift")
    problem = replace(swift, sensor_target=rot.dcm_NB(swift.q_final) @ [1, 0, 0])
    plan = plan_graph_smooth(problem)
    ver = verify(problem, plan)
    assert rejection(ver) is None, rejection(ver)
    assert ver.final_attitude_error < 1e-3


def test_a_start_walled_in_by_cones_fails_with_a_reason():
    """Six cones round the start direction (+x) leave it no way out."""
    ring = [Cone(np.array([math.cos(0.35), math.sin(0.35) * math.cos(k * math.pi / 3),
                           math.sin(0.35) * math.sin(k * math.pi / 3)]), math.radians(15.0), f"wall{k}")
            for k in range(6)]
    problem = ManeuverProblem(Spacecraft(np.eye(3), body_torque_max=1.0), rot.IDENTITY,
                              rot.from_axis_angle([0, 0, 1], 2.5), np.array([1.0, 0.0, 0.0]), ring)
    plan = plan_graph_smooth(problem)
    assert plan.status == Status.FAILED and "no sequence of legs" in plan.message and not len(plan.t)
