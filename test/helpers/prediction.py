"""Plans checked the way the suite checks them: predicted with verification's prediction model."""
from att_planner.verification import measure, predict


def prediction_check(problem, plan, dense_fraction=400):
    """Verification figures and predicted trajectory of ``plan`` with ``dense_fraction`` RK4 steps
    (semi-free problems are judged on the boresight)."""
    traj = predict(problem, plan, steps=dense_fraction)
    return measure(problem, plan, traj), traj
