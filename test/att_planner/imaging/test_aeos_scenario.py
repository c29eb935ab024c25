"""The aeos scenario (bsk-rl's agile imaging setup) as the suite reads it, and a short hold on it
in process on the estimate: the spacecraft flies nadir pointing with every sensor and imperfect actuator."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_msgs_py.types import ControlMode, PointingMode
from att_planner.guidance import reference
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

AEOS = scen.load("aeos")


def test_the_scenario_states_bsk_rls_orbit_and_spacecraft():
    r, v = AEOS.orbit_model.state(np.linspace(0.0, 6000.0, 7))
    assert np.linalg.norm(r, axis=1) == pytest.approx(7_171_000.0, abs=1e-3)
    assert r[0] == pytest.approx([7_171_000.0, 0.0, 0.0], abs=1e-3)     # argument of latitude 0 on the node, Ω = 0
    h = np.cross(r[0], v[0])
    # r × v is the osculating plane's normal: the node's J2 drift (Kepler orbit) tilts it by ~0.01 deg
    assert math.degrees(math.acos(h[2] / np.linalg.norm(h))) == pytest.approx(97.8, abs=0.02)
    sc = AEOS.spacecraft
    assert np.allclose(np.diag(sc.inertia), [82.1, 98.4, 121.0]) and sc.n_wheels == 3
    assert sc.wheel_inertia * sc.wheel_speed_max == pytest.approx(50.0)
    assert sc.wheel_torque_max == pytest.approx(0.4)
    assert AEOS.epoch.isoformat() == "2025-01-01T00:00:00+00:00" and AEOS.field_model == "igrf14"
    assert {e.body for t in AEOS.sensors.star_trackers for e in t.exclusions} == {"sun", "moon", "earth_limb"}
    assert math.degrees(AEOS.node_params["planner"]["schedule_rate_max_rad_s"]) == pytest.approx(5.0)


def test_the_spacecraft_holds_nadir_on_the_estimate():
    law = law_of(PointingMode("nadir"), PointingGeometry.of(world.Environment.from_scenario(AEOS)), 0.0, rot.IDENTITY)
    loop = ClosedLoop(AEOS, q0=law.attitude(0.0), omega0=reference(law.attitude, 0.0).omega_RN_R)
    assert loop.estimator is not None               # the controller flies on the estimate
    loop.run(2.0)
    code, message, _ = loop.controller.set_mode(ControlMode.POINTING, PointingMode("nadir"))
    assert code == 0, message
    loop.run(60.0)
    trace = loop.trace.arrays("t", "q_true", "mode")
    t = trace["t"]
    assert np.all(trace["mode"][t > 3.0] == ControlMode.POINTING)
    late = t > 40.0
    truth = [rot.angle_between(q, law.attitude(tt)) for q, tt in zip(trace["q_true"][late], t[late])]
    assert max(truth) < math.radians(0.05), np.degrees(max(truth))


def test_the_demo_maneuver_plans_among_the_star_trackers_zones():
    """att-demo's slew: off nadir by 25° across track, a verified plan among the six zones at its time."""
    demo = AEOS.node_params["demo"]
    plan = plan_in_process(AEOS, demo["initial_attitude"], demo["final_attitude"], demo["sensor_axis"],
                           zones=AEOS.zones, time_budget=demo["time_budget_s"], epoch=(int(demo["start_time_s"]), 0))
    assert 0.0 < plan.duration < 60.0
    assert rot.angle_between(plan.q[-1], np.asarray(demo["final_attitude"])) < math.radians(0.5)
