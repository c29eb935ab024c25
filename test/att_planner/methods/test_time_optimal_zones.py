"""Time-optimal slews among zones that move, keep-in zones and several sensors.

The zones move in a synthetic sky (a "Sun" turning about the inertial z axis at a known rate), so
the expected geometry is known by hand; every plan is judged by att_planner.verification, which
checks each zone at its true position at every dense sample.
"""
from dataclasses import replace

import casadi as ca
import numpy as np
import pytest

from att_msgs_py.types import Status, Zone
from att_planner.methods.time_optimal import plan_time_optimal
from att_planner.methods.time_optimal.model import (
    ZONE_PARAMETERS,
    boundary_case,
    motion_parameters,
    path_function,
    path_values,
    scaling,
)
from att_planner.problem import ManeuverProblem
from att_planner.verification import rejection, verify
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

VALID = (Status.OPTIMAL, Status.FEASIBLE)
TU = 50.0                                   # s: J = TU² I with T̄ = 1 N m, so 1 TU = 50 s
RATE = np.deg2rad(-40.0) / TU               # rad/s: the Sun's azimuth rate (−40° per TU)
X = np.array([1.0, 0.0, 0.0])


class TurningEphemeris:
    """A sky whose Sun lies in the inertial xy-plane at azimuth ψ0 + RATE t (the zones' interface
    of :class:`att_planner.zones.FittedZones`; the Moon and the Earth are not used)."""

    def __init__(self, psi0: float):
        self.psi0 = psi0

    def sun_direction(self, t):
        psi = self.psi0 + RATE * np.asarray(t, float)
        return np.stack([np.cos(psi), np.sin(psi), np.zeros_like(psi)], axis=-1)

    moon_direction = sun_direction

    def nadir(self, t):
        return np.broadcast_to([0.0, 0.0, -1.0], np.shape(t) + (3,))

    def earth_angular_radius(self, t):
        return np.full(np.shape(t), 0.5)


def _sweep_problem() -> ManeuverProblem:
    """The sensor x turns 135° about z (azimuth 0 → 135°, about 3 TU) while a 25° Sun zone starts
    at azimuth 200° (65° beyond the goal: clear of the whole path at t = 0) and sweeps back at
    40°/TU, across the sensor's path: at 1.5 TU it is at 140°, at 3 TU at 80°."""
    sc = Spacecraft(TU**2 * np.eye(3), body_torque_max=1.0)
    sun = Zone("sun", "sun", X, np.deg2rad(25.0))
    return ManeuverProblem(sc, rot.IDENTITY.copy(), rot.from_axis_angle([0.0, 0.0, 1.0], np.deg2rad(135.0)), X,
                           zones=[sun], sky=TurningEphemeris(np.deg2rad(200.0)))


@pytest.fixture(scope="module")
def sweep():
    moving = _sweep_problem()
    frozen = replace(moving, zones=moving.zone_sky().frozen_zones(), sky=None)
    options = {"starts": 2, "intervals": 16}
    return moving, plan_time_optimal(frozen, **options), plan_time_optimal(moving, **options)


def test_the_frozen_plan_enters_the_moving_zone_and_the_moving_plan_clears_it(sweep):
    moving, frozen_plan, moving_plan = sweep
    assert moving.zone_sky().moving
    assert frozen_plan.status in VALID and moving_plan.status in VALID, moving_plan.message
    # the frozen zone blocks nothing: the frozen plan is the unconstrained optimum, and the zone,
    # at its true position at each instant, catches it deep inside
    caught = verify(moving, frozen_plan)
    assert caught.min_cone_margin < -np.deg2rad(5.0)
    assert rejection(caught).startswith("enters keep-out zone sun")
    # the moving plan clears the true zone at every dense sample and reaches the goal at rest
    ver = verify(moving, moving_plan)
    assert rejection(ver) is None, rejection(ver)
    assert ver.min_cone_margin >= 0.0
    # dodging the zone costs time, and the frozen plan was itself optimal
    assert moving_plan.duration > frozen_plan.duration * 1.02
    assert moving_plan.duration < 4.0 * TU


def test_zone_constraints_are_exact_functions_of_time():
    """The path function of a moving zone takes the normalised time t (t_f enters through
    t = τ t_f): its value and its t-derivative are the FittedZones' series and their exact rate."""
    problem = _sweep_problem()
    s = scaling(problem)
    margin = np.deg2rad(0.05)
    assert not boundary_case(problem, margin)               # no end on a boundary: no end ramp
    path, degree = path_function(problem, s, 7, margin)
    assert degree is not None and path.n_in() == 4          # (x, u, t, p): the series' coefficients are parameters
    values = path_values(problem, s, margin)
    assert values.size == motion_parameters(degree)
    x, u, t = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("t")
    dgdt = ca.Function("dgdt", [x, u, t], [ca.jacobian(path(x, u, t, values), t)])
    zs = problem.zone_sky()
    q = rot.from_axis_angle([0.2, 0.3, 1.0], 1.1)
    b = rot.dcm_NB(q) @ X
    state = np.concatenate([q, np.zeros(3)])
    for tn in (0.0, 1.3, 2.9):
        ts = tn * s.tu
        a, th = zs.axes(ts)[0], zs.half_angles(ts)[0]
        assert float(path(state, np.zeros(3), tn, values)) == pytest.approx(a @ b - np.cos(th + margin), abs=1e-12)
        rate = s.tu * (zs.axes_rate(ts)[0] @ b + np.sin(th + margin) * zs.half_angles_rate(ts)[0])
        assert float(dgdt(state, np.zeros(3), tn)) == pytest.approx(rate, abs=1e-12)
        # the Sun's direction turns at RATE: |da/dt| = |RATE|, and the fit holds it
        assert np.linalg.norm(zs.axes_rate(ts)[0]) == pytest.approx(abs(RATE), rel=1e-6)
    # inertial zones build no time dependence; their data are the function's parameters
    frozen = replace(problem, zones=zs.frozen_zones(), sky=None)
    path, _ = path_function(frozen, s, 7, margin)
    assert path.n_in() == 3 and path_values(frozen, s, margin).size == ZONE_PARAMETERS       # (x, u, p)
    a, th = zs.at(0.0, true=True)
    assert float(path(state, np.zeros(3), path_values(frozen, s, margin))) == pytest.approx(
        a[0] @ b - np.cos(th[0] + margin), abs=1e-12)


def test_keep_in_zone_of_a_second_sensor_is_kept(bw_plans):
    """Bilimoria & Wie's 180° slew about z: the time-optimal answer tilts the body z axis well away
    from inertial z (it is not an eigenaxis turn). A keep-in zone of 10° about inertial z on the
    second sensor, body z, forbids that; the keep-out cones of the first sensor (x) are unchanged."""
    problem, free, eig = bw_plans
    z = np.array([0.0, 0.0, 1.0])
    kept = replace(problem, zones=[Zone("antenna", "inertial", z, np.deg2rad(10.0), True, z)])
    assert verify(kept, free).min_cone_margin < 0          # the free optimum leaves the keep-in cone
    plan = plan_time_optimal(kept, starts=2, intervals=20)
    assert plan.status in VALID, plan.message
    ver = verify(kept, plan)
    assert rejection(ver) is None and ver.min_cone_margin >= 0.0
    assert ver.zone_keep_in == [True]
    assert free.duration < plan.duration <= eig.duration * (1 + 1e-6)


def test_inertial_zones_plan_like_the_cones(swift_plan):
    """The keep-out cones given as inertial keep-out zones of the same sensor: the same NLP, the same plan."""
    problem, plan = swift_plan
    as_zones = replace(problem, cones=[], zones=problem.zone_sky().zones)
    assert not as_zones.zone_sky().moving
    other = plan_time_optimal(as_zones)
    assert other.status == plan.status
    assert other.duration == pytest.approx(plan.duration, rel=1e-12)
    assert other.stats["best_start"] == plan.stats["best_start"]
