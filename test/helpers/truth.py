"""Plans checked the way the suite checks them: integrated through the truth dynamics."""
from att_planner.verification import integrate, measure


def truth_check(problem, plan, dense_fraction=400):
    """Verification figures and trajectory of ``plan`` integrated with ``dense_fraction`` RK4 steps
    (semi-free problems are judged on the boresight)."""
    traj = integrate(problem, plan, steps=dense_fraction)
    return measure(problem, plan, traj), traj
