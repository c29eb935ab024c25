"""A slew that ends on a moving reference hands over to the pointing mode without a jump:
a smooth rest-to-rest slew aimed at where the nadir reference will be at its arrival, entered
through the time-warp blend, then nadir pointing; in process, on the truth."""
from __future__ import annotations

import math
from datetime import timedelta

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import ControlMode, PointingMode
from att_planner.guidance import reference
from att_planner.guidance.laws import BlendedLaw, PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

SWIFT = scen.load("swift_demo")


def test_the_blend_starts_at_rest_on_the_law_and_joins_it():
    law = law_of(PointingMode("nadir"), PointingGeometry.of(world.Environment.from_scenario(SWIFT)), 0.0, rot.IDENTITY)
    blended = BlendedLaw(law, 100.0, 60.0)
    start = reference(blended.attitude, 100.0, h=0.05)
    assert rot.angle_between(start.q_RN, law.attitude(100.0)) < 1e-12
    assert np.linalg.norm(start.omega_RN_R) < 0.05 * np.linalg.norm(reference(law.attitude, 100.0).omega_RN_R)
    for t in (160.0, 200.0):
        assert rot.angle_between(blended.attitude(t), law.attitude(t)) < 1e-12
    middle = reference(blended.attitude, 140.0)
    assert np.linalg.norm(middle.omega_RN_R) == pytest.approx(4 / 3 * SWIFT.orbit.mean_motion, rel=1e-3)


def test_a_plan_ending_on_the_law_is_matched_at_its_end_not_at_the_step_that_sees_it():
    """The control step that sees a plan's end comes up to a step after it: the law has moved on by
    then (2 s of LEO nadir: 0.13 deg, above the attitude match), so the match is judged at the plan's
    end. A plan ending at rest there is entered through the blend, from the step's time."""
    from types import SimpleNamespace

    from att_planner.control.pointing import HANDOVER_ATTITUDE_MATCH, handover_law
    law = law_of(PointingMode("nadir"), PointingGeometry.of(world.Environment.from_scenario(SWIFT)), 0.0, rot.IDENTITY)
    t_end, t_step = 300.0, 302.0
    end = reference(law.attitude, t_end)
    assert rot.angle_between(end.q_RN, law.attitude(t_step)) > 2 * HANDOVER_ATTITUDE_MATCH
    on_law = SimpleNamespace(q=[end.q_RN], omega=[end.omega_RN_R])
    assert handover_law(law, on_law, t_end, t_step, 60.0) is law
    at_rest = SimpleNamespace(q=[end.q_RN], omega=[np.zeros(3)])
    blended = handover_law(law, at_rest, t_end, t_step, 60.0)
    assert isinstance(blended, BlendedLaw) and (blended.start, blended.duration) == (t_step, 60.0)
    late = SimpleNamespace(q=[law.attitude(t_end - 2.0)], omega=[end.omega_RN_R])     # on the law 2 s ago
    assert isinstance(handover_law(law, late, t_end, t_step, 60.0), BlendedLaw)
    assert handover_law(law, at_rest, t_end, t_step, 0.0) is law                        # no blend asked


def test_the_controller_takes_a_law_built_onboard_and_refuses_anything_else():
    """A strip's law (no PointingMode on the wire carries it) is handed over as it is; what is neither a
    mode nor a law is refused naming what it found."""
    loop = ClosedLoop(SWIFT, overrides={"controller": {"state_source": "truth"}})
    loop.run(0.2)
    law = law_of(PointingMode("nadir"), PointingGeometry.of(world.Environment.from_scenario(SWIFT)), 0.0, rot.IDENTITY)
    assert loop.controller.pointing_law(law) is law
    with pytest.raises(RequestError) as refused:
        loop.controller.pointing_law(np.zeros(4))
    assert refused.value.code == ErrorCode.INVALID_POINTING and "found a ndarray" in refused.value.message


@pytest.mark.slow
def test_a_slew_onto_nadir_hands_over_without_a_jump():
    loop = ClosedLoop(SWIFT, overrides={"controller": {"state_source": "truth", "settle_time_s": 0.0}})
    loop.run(1.0)
    geometry = PointingGeometry.of(world.Environment.from_scenario(SWIFT))
    law = law_of(PointingMode("nadir"), geometry, loop.sim.t, rot.IDENTITY)
    start, duration = loop.sim.t + 0.05, 100.0
    for _ in range(3):                   # aim at where nadir will be at the arrival
        plan = plan_eigenaxis_smooth(ManeuverProblem(SWIFT.spacecraft, loop.sim.x[:4], law.attitude(start + duration)))
        duration = plan.duration
    assert loop.execute(plan, after=PointingMode("nadir")) is None
    end = loop.sim.t + duration
    loop.run(duration + 100.0)
    trace = loop.trace.arrays()
    t, error, mode = trace["t"], trace["attitude_error"], trace["mode"]
    assert mode[-1] == ControlMode.POINTING and np.all(mode[t > end + 0.1] == ControlMode.POINTING)
    at_handover = error[(t > end - 5) & (t < end + 5)]
    assert np.max(at_handover) < math.radians(0.01), np.degrees(at_handover.max())      # no jump
    # on nadir after the blend, to the noise of swift_demo's drives (2e-4 N m 1 sigma against kp = 1 N m/rad)
    assert np.max(error[t > end + 60 + 20]) < math.radians(0.005)
    truth = [rot.angle_between(q, law.attitude(tt)) for q, tt in zip(trace["q_true"], t)]
    assert max(truth[-200:]) < math.radians(0.005)


def test_a_time_optimal_slew_ends_on_nadir_at_its_rate_and_hands_over_directly():
    """The time-optimal planner meets the moving goal (nadir at t_f, with its rate); flown when it
    was planned for, the controller takes the law itself (no blend): the error of the slew's end
    carries over without a jump and dies out."""
    s = scen.load("leo_momentum")
    law = law_of(PointingMode("nadir"), PointingGeometry.of(world.Environment.from_scenario(s)), 0.0, rot.IDENTITY)
    q0 = rot.multiply(law.attitude(0.0), rot.from_axis_angle([1, 0, 0], math.radians(40)))
    loop = ClosedLoop(s, overrides={"controller": {"state_source": "truth", "momentum_dumping": False}}, q0=q0)
    loop.run(0.5)
    t0 = loop.controller.state.t                 # the maneuver starts from the latest state
    start = s.epoch + timedelta(seconds=t0)
    epoch = (int(start.timestamp()), round(start.timestamp() % 1 * 1e9))
    plan = plan_in_process(s, q0, q0, [0, 0, 1], method="time_optimal", epoch=epoch,
                           end_pointing=PointingMode("nadir"))
    end = t0 + plan.duration
    goal = reference(law.attitude, end)
    assert rot.angle_between(plan.q[-1], goal.q_RN) < 1e-5
    assert np.linalg.norm(plan.omega[-1] - goal.omega_RN_R) < 1e-6 < 0.5 * np.linalg.norm(goal.omega_RN_R)
    assert loop.execute(plan, after=PointingMode("nadir")) is None
    loop.run(plan.duration + 120.0)
    assert loop.controller.pointing.name == "nadir" and not isinstance(loop.controller.pointing, BlendedLaw)
    trace = loop.trace.arrays()
    t, error = trace["t"], trace["attitude_error"]
    # the braking's tracking error carries over the handover (0.019 deg measured) and dies out
    around = error[(t > end - 10) & (t < end + 120)]
    assert np.max(around) < math.radians(0.03), np.degrees(around.max())
    assert np.max(error[t > end + 70]) < math.radians(0.003), np.degrees(error[t > end + 70].max())
