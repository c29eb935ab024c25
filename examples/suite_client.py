"""Start the nodes on a private ROS domain, then plan and execute a keep-out slew through SuiteClient."""
import numpy as np

from att_msgs_py.types import Cone
from att_planner.nodes.client import client_session, maneuver_request
from att_planner.tools.launch import join_env, start_suite
from att_sim.models import rotations as rot

# recorder, simulator (as fast as the loop goes), estimator, controller and planner; stopped at the end
with start_suite("swift_demo", "runs/quickstart/run.mcap", "runs/quickstart",
                 params={"simulator": {"real_time_factor": 0.0}}) as suite:
    join_env(suite.env)               # this process on the nodes' random ROS_DOMAIN_ID, localhost discovery
    with client_session() as client:
        client.wait_for_servers(timeout=60, estimate=True)     # ... and a converged attitude estimate
        goal, sun = rot.from_axis_angle([0, 0, 1], np.radians(135)), Cone([0.5, 0.866, 0], np.radians(47), "sun")
        response = client.plan(maneuver_request(rot.IDENTITY, goal, [1, 0, 0], [sun], method="time_optimal"))
        print("plan:", response.success, response.error_code, response.message, f"{response.plan.duration:.1f} s")
        result = client.execute(response.plan.plan_id)     # waits for the maneuver and its settle time
        print("execution:", result.success, result.error_code, result.message,
              f"final error {np.degrees(result.final_attitude_error):.4f} deg")
