"""Plans that respect the wheels: the wheels' speeds along a body-torque plan from momentum
conservation, a plan that would saturate a wheel slowed in time and verified, one that saturates at
any speed refused, and the request's wheel speeds checked."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import ControlKind
from att_planner.problem import ManeuverProblem
from att_planner.service.wheels import smallest_slowdown, time_scaled
from att_planner.tools.closed_loop import plan_in_process
from att_planner.verification import body_plan_wheel_speeds, predict, verify
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from helpers.own_rk4 import integrate as own_rk4

SLEW = rot.from_axis_angle([0, 0, 1], math.radians(90))


def plan(name: str, wheel_speeds=(), goal=SLEW, method="eigenaxis_smooth"):
    return plan_in_process(scen.load(name), rot.IDENTITY, goal, [1, 0, 0], method=method, time_budget=10,
                           wheel_speeds=wheel_speeds)


def test_smallest_slowdown_is_the_least_factor_that_keeps_every_sample_within_the_limit():
    static = np.array([[0.0, 300.0], [-100.0, 0.0]])
    slew = np.array([[1200.0, 0.0], [-800.0, 500.0]])
    c = smallest_slowdown(static, slew, 600.0)
    assert c == pytest.approx(2.0)                      # 0 + 1200 / c = 600
    assert np.abs(static + slew / c).max() == pytest.approx(600.0)
    assert np.abs(static + slew / (0.99 * c)).max() > 600.0
    assert smallest_slowdown(static, 0.1 * slew, 600.0) == 1.0
    assert smallest_slowdown(np.array([[601.0]]), np.array([[0.0]]), 600.0) == math.inf


@pytest.mark.parametrize("name", ["swift_demo", "leo_momentum"])
def test_the_wheels_of_a_body_torque_plan_conserve_the_total_momentum_and_keep_their_null_space_spin(name):
    """Independent of the formula: R (J ω + G I_w Ω) is the same at every sample, and (four wheels)
    the null-space component of the wheels' momentum never changes."""
    s = scen.load(name)
    sc = s.spacecraft
    speeds0 = np.linspace(-0.6, 0.7, sc.n_wheels) * sc.wheel_speed_max
    p = plan(name)
    problem = ManeuverProblem(sc, rot.IDENTITY, SLEW, wheel_speeds=speeds0)
    traj = predict(problem, p)
    stored, slew = body_plan_wheel_speeds(problem, traj.q_BN, traj.omega_BN_B)
    relative = stored + slew
    assert relative[0] == pytest.approx(speeds0, abs=1e-9)
    inertial = relative + traj.omega_BN_B @ sc.wheel_axes
    H_B = traj.omega_BN_B @ sc.inertia.T + inertial @ (sc.wheel_inertia * sc.wheel_axes.T)
    H_N = np.einsum("kij,kj->ki", rot.dcm_NB(traj.q_BN), H_B)
    assert np.abs(H_N - H_N[0]).max() <= 1e-9 * np.linalg.norm(H_N[0])
    assert np.abs(slew).max() > 10.0            # the slew moves the wheels: the check above means something
    if sc.n_wheels > 3:
        null = np.linalg.svd(sc.wheel_axes)[2][-1]
        assert np.abs((inertial - inertial[0]) @ null).max() <= 1e-9 * sc.wheel_speed_max


def test_time_scaling_flies_the_same_path_slower_through_the_dynamics():
    s = scen.load("swift_demo")
    p = plan("swift_demo")
    slow = time_scaled(p, 2.5)
    assert slow.duration == pytest.approx(2.5 * p.duration) and slow.control_kind == ControlKind.BODY_TORQUE
    J = s.spacecraft.inertia
    fast_states = own_rk4(J, p.t, p.torque, rot.IDENTITY, interpolation=str(p.interpolation))
    slow_states = own_rk4(J, slow.t, slow.torque, rot.IDENTITY, interpolation=str(p.interpolation))
    assert slow_states[:, :4] == pytest.approx(fast_states[:, :4], abs=1e-12)      # the same attitudes
    assert slow_states[:, 4:] * 2.5 == pytest.approx(fast_states[:, 4:], abs=1e-12)


def test_a_plan_that_would_saturate_a_wheel_is_slowed_verified_and_says_so():
    s = scen.load("leo_momentum")
    fast = plan("leo_momentum")
    speeds0 = [0.95 * s.spacecraft.wheel_speed_max, 0.0, 0.0, 0.0]
    slowed = plan("leo_momentum", speeds0)
    ver = slowed.verification
    assert slowed.stats["slowdown"] > 1.0 and "slowed" in slowed.message and "wheels" in slowed.message
    assert slowed.duration == pytest.approx(slowed.stats["slowdown"] * fast.duration)
    assert ver.wheel_speed_ratio <= 1.0 and ver.final_attitude_error < math.radians(0.5)
    # independently: the same plan unslowed passes the limit with these wheels
    problem = ManeuverProblem(s.spacecraft, rot.IDENTITY, SLEW, wheel_speeds=np.array(speeds0))
    assert verify(problem, fast).wheel_speed_ratio > 1.0
    assert "slowdown" not in fast.stats


def test_stored_momentum_that_saturates_a_wheel_at_any_speed_is_refused_with_202():
    """Wheels x and y at 600 rad/s hold 8.5 N m s along (1, 1, 0) in inertial space; turned 45 deg
    about z the body would need it all on wheel x: 849 rad/s > 630."""
    goal = rot.from_axis_angle([0, 0, 1], math.radians(45))
    with pytest.raises(RequestError) as err:
        plan("swift_demo", [600.0, 600.0, 0.0], goal=goal)
    assert err.value.code == ErrorCode.WHEEL_SATURATION and "any speed" in err.value.message


@pytest.mark.parametrize("speeds, words", [([1.0, 2.0], "3 wheels"), ([0.0, math.nan, 0.0], "NaN"),
                                           ([0.0, 0.0, 631.0], "wheel_speeds[2]"), ([0.0] * 70, "70 values")])
def test_bad_wheel_speeds_are_refused_naming_the_field(speeds, words):
    with pytest.raises(RequestError) as err:
        plan("swift_demo", speeds)
    assert err.value.code == ErrorCode.INVALID_WHEEL_SPEEDS and words in err.value.message
    assert "wheel_speeds" in err.value.message
