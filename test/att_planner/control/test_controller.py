"""The controller core without ROS: modes, plan checks, a maneuver flown closed loop on the simulator."""
import math
from dataclasses import replace
from datetime import UTC, datetime

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Cone, ControlKind, ControlMode, Plan, Status, Zone
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario
from att_sim.models.ephemeris import Ephemeris
from att_sim.models.orbit import CircularOrbit
from att_sim.truth.simulation import Simulation
from helpers.signed_plans import context, issue

GOAL = rot.from_axis_angle([0.3, -0.5, 1.0], 1.2)
EPOCH = datetime(2026, 12, 21, tzinfo=UTC)
CONFIG = ControllerConfig(control_period=0.1, settle_time=10.0, tracking_kp=1.0, tracking_kd=16.0)


@pytest.fixture
def world():
    s = scenario.load("swift_demo")
    sim = Simulation(s.spacecraft, s.orbit)
    ctx = context()
    plan, payload = issue(plan_eigenaxis_smooth(ManeuverProblem(s.spacecraft, rot.IDENTITY, GOAL)), ctx)
    return sim, Controller(ctx, CONFIG, body_frame_id="body"), (plan, payload)


def fly(sim, core, seconds, dt=0.05, states=None):
    """Closed loop: the simulator's state into the core, its command back, as the nodes do (the
    state of each output appended to ``states`` when given)."""
    outputs = []
    for _ in range(int(round(seconds / dt))):
        assert core.accept_state(sim.state("eci", "body"), wall=sim.t).refused is None
        if core.due():
            out = core.step()
            assert sim.set_command(out.command) is None
            outputs.append(out)
            if states is not None:
                states.append(core.state)
        sim.advance(dt)
        if outputs and outputs[-1].result is not None:
            return outputs
    return outputs


def test_a_plan_is_flown_to_its_goal_with_feedback_then_held(world):
    sim, core, (plan, payload) = world
    assert core.receive_plan(plan, payload) is None
    fly(sim, core, 0.05)
    resolved, refused = core.resolve("p1")
    assert refused is None and core.start(resolved) is None
    assert core.mode == ControlMode.PLAN_TRACKING
    outputs = fly(sim, core, plan.duration + CONFIG.settle_time + 5)
    result = outputs[-1].result
    assert result is not None and result.success and result.error_code == ErrorCode.OK
    assert result.duration == pytest.approx(plan.duration + CONFIG.settle_time, abs=CONFIG.control_period + 1e-9)
    assert result.final_attitude_error < math.radians(0.05) and result.final_rate < 1e-3
    feedback = [o.feedback for o in outputs if o.feedback is not None]
    assert len(feedback) == pytest.approx(result.duration / CONFIG.feedback_period, abs=1)
    assert all(np.diff([f.elapsed for f in feedback]) > 0) and feedback[-1].progress <= 1.0
    assert all(o.command.plan_id == "p1" and o.command.mode == ControlMode.PLAN_TRACKING for o in outputs)
    assert all(o.command.frame_id == "body" for o in outputs)
    # after the maneuver: the final attitude is held
    held = fly(sim, core, 5.0)
    assert core.maneuver is None and held[-1].status.message.startswith("holding")
    assert rot.angle_between(sim.x[:4], GOAL) < math.radians(0.05)


def test_mode_changes_are_checked_and_safe_mode_aborts_a_maneuver(world):
    sim, core, (plan, _) = world
    assert core.set_mode(7)[0] == ErrorCode.INVALID_MODE
    assert core.set_mode(ControlMode.PLAN_TRACKING)[0] == ErrorCode.INVALID_MODE
    assert core.start(plan).code == ErrorCode.NO_STATE
    fly(sim, core, 0.2)
    assert core.start(plan) is None
    fly(sim, core, 2.0)
    code, message, ended = core.set_mode(ControlMode.MAGNETORQUER_PD)
    assert code == ErrorCode.BUSY and "'p1' is executing" in message and ended is None
    code, _, ended = core.set_mode(ControlMode.SAFE)
    assert code == ErrorCode.OK and not ended.success and ended.error_code == ErrorCode.ABORTED
    assert core.mode == ControlMode.SAFE and core.maneuver is None
    # safe mode damps the rate through the wheels
    w0 = np.linalg.norm(sim.x[4:7])
    fly(sim, core, 20.0)
    assert np.linalg.norm(sim.x[4:7]) < 0.2 * w0


def test_cancellation_ends_the_maneuver_in_safe_mode(world):
    sim, core, (plan, _) = world
    fly(sim, core, 0.2)
    core.start(plan)
    core.next_control = -math.inf
    out = core.step(cancel_requested=True)
    assert out.result.error_code == ErrorCode.ABORTED and out.result.message == "cancelled"
    assert core.mode == ControlMode.SAFE and core.hold_q_RN is None


@pytest.mark.parametrize("change, code, words", [
    (dict(t=np.array([0.0, 2.0, 1.0])), ErrorCode.INVALID_PLAN, "do not increase"),
    (dict(q=np.zeros((2, 4))), ErrorCode.INVALID_PLAN, "attitudes has 2 entries"),
    (dict(torque=np.full((3, 3), np.nan)), ErrorCode.INVALID_PLAN, "NaN or Inf"),
    (dict(control_kind="warp_drive"), ErrorCode.INVALID_PLAN, "control_kind 'warp_drive'"),
    (dict(status=Status.FAILED), ErrorCode.INVALID_PLAN, "status 'failed'"),
])
def test_bad_inline_plans_are_refused(world, change, code, words):
    _, core, _ = world
    good = Plan(t=np.array([0.0, 1.0, 2.0]), torque=np.zeros((3, 3)), q=np.tile(rot.IDENTITY, (3, 1)),
                omega=np.zeros((3, 3)), control_kind=ControlKind.BODY_TORQUE, status=Status.OPTIMAL)
    assert core.resolve("", *issue(good, core.context, "good"))[1] is None
    plan, refused = core.resolve("", *issue(replace(good, **change), core.context, "bad"))
    assert plan is None and refused.code == code and words in refused.message


def test_unknown_plans_and_the_cache_bounds(world):
    _, core, (plan, _) = world
    assert core.resolve("nope")[1].code == ErrorCode.UNKNOWN_PLAN
    n = CONFIG.max_cached_plans
    for i in range(n + 5):
        assert core.receive_plan(*issue(replace(plan), core.context, f"p{i}")) is None
    assert len(core.plans) == n
    assert core.resolve("p0")[1].code == ErrorCode.UNKNOWN_PLAN and core.resolve(f"p{n + 4}")[1] is None
    size = next(iter(core.plans.values())).size
    small = Controller(core.context, replace(CONFIG, max_cache_bytes=3 * size))
    for i in range(6):
        small.receive_plan(*issue(replace(plan), core.context, f"q{i}"))
    assert list(small.plans) == ["q3", "q4", "q5"] and small.cache_bytes <= 3 * size


def test_control_instants_follow_the_control_period(world):
    sim, core, _ = world
    outputs = fly(sim, core, 1.0, dt=0.025)
    assert len(outputs) == pytest.approx(1.0 / CONFIG.control_period, abs=1)
    assert np.allclose(np.diff([o.command.t for o in outputs]), CONFIG.control_period)
    assert all(o.command.mode == ControlMode.IDLE and not np.any(o.command.wheel_torques) for o in outputs)


def test_magnetorquer_mode_commands_the_pd_law_and_non_finite_states_are_ignored():
    s = scenario.load("bruni_celani")
    core = Controller(context("bruni_celani"), ControllerConfig(kp=2e5, kd=1e8, control_period=1.0),
                      ControlMode.MAGNETORQUER_PD, s.body_frame_id)
    sim = Simulation(s.spacecraft, s.orbit, omega0=[0.02, 0.02, -0.03])
    sim.advance(0.5)
    state = sim.state(s.frame_id, s.body_frame_id)
    refused = core.accept_state(replace(state, q=np.array([np.nan, 0, 0, 1]))).refused
    assert refused.code == ErrorCode.INVALID_STATE and "state.attitude" in refused.message
    assert core.accept_state(state).refused is None and core.due()
    m = core.step().command.dipole
    assert np.all(np.abs(m) <= s.spacecraft.dipole_max) and np.any(m)


def test_feedback_margin_covers_the_zones_at_their_true_position_now():
    """The cone, an Earth-limb keep-in and a Sun keep-out zone, checked by hand from the sky at the
    state's time (the maneuver starts 30 s into the sim, the plan's epoch says 0 s: the truth wins)."""
    s = scenario.load("swift_demo")
    sky = Ephemeris(EPOCH, CircularOrbit(s.orbit))
    cone = Cone([0.0, 0.0, -1.0], 0.5, "cone")
    sun, limb = Zone("sun", "sun", [1.0, 0, 0], 0.3), Zone("limb", "earth_limb", [0, 0, 1.0], 0.05, True)
    plan = plan_eigenaxis_smooth(ManeuverProblem(s.spacecraft, rot.IDENTITY, GOAL), samples=101)
    plan.cones, plan.zones, plan.epoch = [cone], [sun, limb], EPOCH
    ctx = context()
    flown = {}
    for name, controller_sky in (("sky", sky), ("none", None)):
        sim, core = Simulation(s.spacecraft, s.orbit), Controller(ctx, CONFIG, body_frame_id="body", sky=controller_sky)
        fly(sim, core, 30.0)
        assert core.start(core.resolve("", *issue(replace(plan), ctx, "z"))[0]) is None
        states = []
        outputs = fly(sim, core, 2.0, states=states)
        flown[name] = [(o.feedback, x) for o, x in zip(outputs, states) if o.feedback is not None]
    for (fb, state), (fb_none, _) in zip(flown["sky"], flown["none"]):
        b = rot.dcm_NB(state.q)
        cone_m = math.acos(np.dot(b[:, 0], cone.direction)) - cone.half_angle
        sun_m = math.acos(np.dot(b[:, 0], sky.sun_direction(state.t))) - sun.half_angle
        limb_m = sky.earth_angular_radius(state.t) + limb.half_angle - math.acos(np.dot(b[:, 2], sky.nadir(state.t)))
        assert state.t > 30.0 and fb.min_cone_margin == pytest.approx(min(cone_m, sun_m, limb_m), abs=1e-9)
        assert fb_none.min_cone_margin == pytest.approx(cone_m, abs=1e-9)     # no sky: the cone only
    assert min(limb_m, sun_m) < cone_m            # the zones decide the margin here
