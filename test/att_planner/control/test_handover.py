"""A slew that ends on a moving reference hands over to the pointing mode without a jump (issue 15):
a smooth rest-to-rest slew aimed at where the nadir reference will be at its arrival, entered
through the time-warp blend, then nadir pointing; in process, on the truth."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import ControlMode, PointingMode
from att_planner.guidance import reference
from att_planner.guidance.laws import BlendedLaw, Sky
from att_planner.guidance.modes import law_of
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_planner.tools.closed_loop import ClosedLoop
from att_sim import rotations as rot
from att_sim import scenario as scen
from att_sim import world

SWIFT = scen.load("swift_demo")


def test_the_blend_starts_at_rest_on_the_law_and_joins_it():
    law = law_of(PointingMode("nadir"), Sky.of(world.Environment.from_scenario(SWIFT)), 0.0, rot.IDENTITY)
    blended = BlendedLaw(law, 100.0, 60.0)
    start = reference(blended.attitude, 100.0, h=0.05)
    assert rot.angle_between(start.q, law.attitude(100.0)) < 1e-12
    assert np.linalg.norm(start.omega) < 0.05 * np.linalg.norm(reference(law.attitude, 100.0).omega)
    for t in (160.0, 200.0):
        assert rot.angle_between(blended.attitude(t), law.attitude(t)) < 1e-12
    middle = reference(blended.attitude, 140.0)
    assert np.linalg.norm(middle.omega) == pytest.approx(4 / 3 * SWIFT.orbit.mean_motion, rel=1e-3)


@pytest.mark.slow
def test_a_slew_onto_nadir_hands_over_without_a_jump():
    loop = ClosedLoop(SWIFT, overrides={"controller": {"state_source": "truth", "settle_time": 0.0}})
    loop.run(1.0)
    law = law_of(PointingMode("nadir"), Sky.of(world.Environment.from_scenario(SWIFT)), loop.sim.t, rot.IDENTITY)
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
