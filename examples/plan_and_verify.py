"""Plan a keep-out slew and verify it, without ROS: the Swift maneuver, 135 deg about body z."""
import numpy as np

from att_msgs_py.types import Cone
from att_planner.methods.time_optimal.planner import plan_time_optimal
from att_planner.problem import ManeuverProblem
from att_planner.verification import rejection, verify
from att_sim.models import rotations as rot
from att_sim.models import scenario

spacecraft = scenario.load("swift_demo").spacecraft          # J = diag(100, 100, 100) kg m², 0.1 N m
goal = rot.from_axis_angle([0, 0, 1], np.radians(135))
sun = Cone([0.5, 0.866, 0], np.radians(47), "sun")           # keep the sensor (body x) 47 deg off the Sun
problem = ManeuverProblem(spacecraft, rot.IDENTITY, goal, sensor_axis=np.array([1.0, 0, 0]), cones=[sun])
plan = plan_time_optimal(problem, intervals=40)
check = verify(problem, plan)                                # the controls integrated through the dynamics
print(f"plan: {plan.status} in {plan.duration:.1f} s, computed in {plan.wall_time:.2f} s")
print(f"verified: final error {np.degrees(check.final_attitude_error):.4f} deg, "
      f"min margin {np.degrees(check.min_cone_margin):.2f} deg, torque {check.torque_ratio:.3f} x limit")
print("accepted" if rejection(check) is None else f"rejected: {rejection(check)}")
