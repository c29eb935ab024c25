"""A plan starts near the current state: its first attitude, and its first rate compared in body
axes; a plan onto a moving goal at its planned instant."""
import math
from datetime import UTC, datetime, timedelta

import numpy as np
from scipy.spatial.transform import Rotation

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Plan, State, Verification
from att_planner.control.plan_checks import PlanContext, check_start, plan_start
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


def test_a_plan_onto_a_moving_goal_starts_at_its_planned_instant():
    """A plan at rest starts now; one onto a moving goal at its epoch's sim time (epoch 100 s after the
    scenario's; sim time 0 without an epoch), sent up to max_start_epoch_error early or late, and is
    refused beyond, saying by how much."""
    epoch = datetime(2025, 1, 1, tzinfo=UTC)
    ctx = PlanContext(SC, "swift_demo", "eci", None, epoch=epoch, max_start_epoch_error=10.0)
    moving = Verification(0.0, 0.0, math.inf, [], 0.0, 0.0, 0.0, 2, goal="ground")
    plan = Plan(t=np.array([0.0, 10.0]), q=np.array([rot.IDENTITY] * 2), omega=np.zeros((2, 3)), plan_id="p",
                epoch=epoch + timedelta(seconds=100.0))
    state = State(t=104.5, q=rot.IDENTITY, omega=np.zeros(3), wheel_speeds=np.zeros(SC.n_wheels))
    assert plan_start(plan, state, ctx) == 104.5                                 # at rest: now
    plan.verification = moving
    for t in (90.0, 104.5, 110.0):
        state.t = t
        assert plan_start(plan, state, ctx) == 100.0
    state.t = 110.5
    late = plan_start(plan, state, ctx)
    assert isinstance(late, RequestError) and late.code == ErrorCode.PLAN_CONTEXT and "10.5 s later" in late.message
    state.t = 89.0
    assert "11.0 s earlier" in plan_start(plan, state, ctx).message
    plan.epoch, state.t = None, 3.0
    assert plan_start(plan, state, ctx) == 0.0
