"""A plan starts near the current state: its first attitude, and its first rate compared in body axes."""
import math

import numpy as np
from scipy.spatial.transform import Rotation

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Plan, State
from att_planner.control.plan_checks import PlanContext, check_start
from att_sim.models import rotations as rot
from att_sim.models import scenario

SC = scenario.load("swift_demo").spacecraft
CTX = PlanContext(SC, "swift_demo", "eci", None, max_start_attitude_error=math.radians(5.0), max_start_rate_error=0.01)


def test_the_start_rate_is_compared_in_body_axes():
    """4° off a plan starting at 0.2 rad/s: a body turning with the plan's first reference state
    ([BR] ω_RN_R, from scipy's matrices) may start (the unrotated rates differ by 0.014 rad/s); the
    same rate unrotated is 0.014 rad/s off and refused."""
    q_RN, omega_RN_R = rot.IDENTITY, np.array([0.0, 0.0, 0.2])
    q_BN = rot.from_axis_angle([1.0, 0.0, 0.0], math.radians(4.0))
    plan = Plan(t=np.array([0.0, 10.0]), q=np.array([q_RN, q_RN]), omega=np.array([omega_RN_R, omega_RN_R]),
                plan_id="p")
    dcm_BR = Rotation.from_quat(q_BN).as_matrix().T @ Rotation.from_quat(q_RN).as_matrix()
    turning = dcm_BR @ omega_RN_R
    assert np.linalg.norm(turning - omega_RN_R) > CTX.max_start_rate_error
    state = State(t=0.0, q=q_BN, omega=turning, wheel_speeds=np.zeros(SC.n_wheels))
    assert check_start(plan, state, CTX) is None
    state.omega = omega_RN_R
    refused = check_start(plan, state, CTX)
    assert refused is not None and refused.code == ErrorCode.PLAN_CONTEXT and "rate" in refused.message
