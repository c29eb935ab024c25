"""The λ-rotation baselines: eigenaxis bang-bang and the constrained rotation axis, verified."""
import numpy as np
import pytest

from att_msgs_py.types import Status
from att_planner.methods.constrained_axis import plan_constrained_axis
from att_planner.methods.eigenaxis import plan_eigenaxis
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft
from helpers.prediction import prediction_check


def test_constrained_axis_rides_a_cone_and_verifies(swift_plan):
    problem, best = swift_plan
    plan = plan_constrained_axis(problem)
    assert plan.status == Status.FEASIBLE
    ver, _ = prediction_check(problem, plan)
    assert ver.min_cone_margin >= 0 and ver.final_attitude_error <= np.deg2rad(0.5)
    assert any("ride" in leg["label"] for leg in plan.stats["legs"])
    # each leg takes 2 sqrt(φ I_a / T_a) (J = I: T_a = T̄ / max|e_j|)
    assert plan.duration == pytest.approx(sum(leg["duration"] for leg in plan.stats["legs"]))
    assert plan.duration > best.duration


def test_eigenaxis_with_a_gyroscopic_term_stays_within_limits_and_arrives():
    sc = Spacecraft(np.diag([1.0, 2.0, 3.0]), body_torque_max=0.5)
    problem = ManeuverProblem(sc, rot.from_axis_angle([1, 0, 0], 0.3), rot.from_axis_angle([1, 1, 1], 2.0))
    plan = plan_eigenaxis(problem)
    ver, _ = prediction_check(problem, plan, dense_fraction=200)
    assert plan.status == Status.FEASIBLE
    assert ver.torque_ratio <= 1.0 + 1e-9 and ver.final_attitude_error <= np.deg2rad(0.5)
    assert ver.final_rate <= 1e-2
