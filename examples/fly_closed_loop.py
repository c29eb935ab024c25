"""Fly a plan in the closed loop, in one process: simulator, estimator and controller cores as their nodes wire them."""
import numpy as np

from att_msgs_py.types import Cone
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process
from att_sim.models import rotations as rot
from att_sim.models import scenario

swift = scenario.load("swift_demo")
goal = rot.from_axis_angle([0, 0, 1], np.radians(135))
sun = Cone([0.5, 0.866, 0], np.radians(47), "sun")
plan = plan_in_process(swift, rot.IDENTITY, goal, [1, 0, 0], [sun], method="time_optimal")   # padded, verified
loop = ClosedLoop(swift)            # the controller flies on the estimator's attitude (noisy sensors, friction)
loop.run(10.0)                      # the estimate converges on the star tracker
result = loop.fly(plan)             # the plan, then its settle time
truth = loop.trace.arrays("t", "q_true")
error = np.degrees(rot.angle_between(truth["q_true"][-1], goal)) * 3600
print(f"plan: {plan.status} by {plan.method}, {plan.duration:.1f} s")
print(f"flown: {result.success} {result.message}; final error {error:.1f} arcsec after {truth['t'][-1]:.1f} s")
