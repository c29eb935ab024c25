"""Plans shared by the method tests (each solved once per session)."""
import pytest

from att_planner.methods.eigenaxis import plan_eigenaxis
from att_planner.methods.time_optimal import plan_time_optimal
from att_planner.reference.time_optimal_cases import case_problem


@pytest.fixture(scope="session")
def bw_plans():
    problem = case_problem("bilimoria_wie")
    return problem, plan_time_optimal(problem), plan_eigenaxis(problem)


@pytest.fixture(scope="session")
def swift_plan():
    problem = case_problem("swift")
    return problem, plan_time_optimal(problem)
