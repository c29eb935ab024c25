"""Boundary ends and forced boundary arcs: an end within BOUNDARY_TOLERANCE of a cone or
zone boundary plans with every method; one inside by more is refused (112, 154); a forced boundary
arc is planned, verified on the boundary and refused when it cannot be flown; Melton's two stages."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Zone
from att_planner import methods
from att_planner.cones import ARC_TOLERANCE, BOUNDARY_TOLERANCE, END_RADIUS
from att_planner.methods.time_optimal import plan_time_optimal
from att_planner.reference.time_optimal_cases import boundary_problem
from att_planner.service.planning import plan_maneuver, run_method
from att_planner.service.requests import ManeuverRequest, validate_maneuver
from att_planner.verification import clearances, rejection, verify
from att_sim.models import rotations as rot
from helpers.prediction import prediction_check

TH_A, TH_B = math.radians(30), math.radians(20)
SLEW = math.radians(60)                                     # about z: the sensor x sweeps the xy plane


def _cone_axis(azimuth: float) -> list:
    return [math.cos(azimuth), math.sin(azimuth), 0.0]


BUDGET = 20.0       # s, the planner's default: a loaded machine must not turn a boundary test into a budget test


def boundary_request(method: str, depth: float = 0.0, **fields) -> ManeuverRequest:
    """Sensor x from identity to 60° about z; the start on the boundary of cone 'a' and the goal on
    that of cone 'b', both ``depth`` rad inside (the path leaves the one and reaches the other from outside)."""
    cones = [(_cone_axis(-TH_A + depth), TH_A, "a"), (_cone_axis(SLEW + TH_B - depth), TH_B, "b")]
    base = dict(frame_id="eci", q_initial=rot.IDENTITY, q_final=rot.from_axis_angle([0, 0, 1], SLEW),
                sensor_axis=np.array([1.0, 0, 0]), cones=cones, method=method, time_budget=BUDGET)
    return ManeuverRequest(**(base | fields))


def validate(req: ManeuverRequest):
    return validate_maneuver(req, frame_id="eci", default_spacecraft="swift_demo", default_method=req.method,
                             default_budget=BUDGET)


@pytest.mark.parametrize("method", [m.name for m in methods.REGISTRY])
def test_ends_on_a_boundary_plan_with_every_method(method):
    """Both ends within the tolerance (half of it inside), the planner's default padding of 1°
    (which leaves those two cones as they are): the method's own plan is verified, no fallback."""
    outcome = plan_maneuver(validate(boundary_request(method, depth=0.5 * BOUNDARY_TOLERANCE)),
                            cone_padding=math.radians(1.0), runner=run_method)
    assert outcome.code == ErrorCode.OK, outcome.message
    assert outcome.plan.method == method and outcome.plan.status != "fallback"
    assert outcome.verification.min_cone_margin >= 0.0


@pytest.mark.parametrize("fields, code", [
    (dict(), ErrorCode.SENSOR_IN_CONE),                                                 # both ends 2 tol inside
    (dict(semi_free=True, sensor_target=np.array(_cone_axis(SLEW))), ErrorCode.SENSOR_IN_CONE),
])
def test_an_end_inside_by_more_than_the_tolerance_is_refused(fields, code):
    with pytest.raises(RequestError) as err:
        validate(boundary_request("time_optimal", depth=2 * BOUNDARY_TOLERANCE, **fields))
    assert err.value.code == code and "inside cone 'a'" in err.value.message
    assert "boundary tolerance of 1e-06 rad" in err.value.message


def test_zone_ends_follow_the_same_tolerance():
    """An inertial keep-out zone of another sensor with the start on its boundary is accepted; one
    1e-5 rad further in is ZONE_AT_END."""
    y = np.array([0.0, 1.0, 0.0])                     # body y points along inertial y at the start

    def zone(depth):
        axis = _cone_axis(math.pi / 2 - math.radians(40) + depth)         # the slew turns y away from it
        return Zone("radiator", "inertial", y, math.radians(40), direction=np.array(axis))
    validate(boundary_request("time_optimal", zones=[zone(0.5 * BOUNDARY_TOLERANCE)], cones=[]))
    with pytest.raises(RequestError) as err:
        validate(boundary_request("time_optimal", zones=[zone(10 * BOUNDARY_TOLERANCE)], cones=[]))
    assert err.value.code == ErrorCode.ZONE_AT_END


def test_clearance_floor_is_minus_tolerance_near_the_ends_only():
    """A path along the boundary of a cone: within END_RADIUS of its ends a margin of −tol/2 is
    acceptable, beyond it not."""
    problem = validate(boundary_request("time_optimal")).problem
    cone = replace(problem.cones[0], half_angle=problem.cones[0].half_angle + 0.5 * BOUNDARY_TOLERANCE)
    angles = np.linspace(0.0, -6 * END_RADIUS, 201)     # rides cone 'a' (turned about its own axis by 0.06 rad)
    q = rot.from_axis_angle(np.tile(cone.direction, (len(angles), 1)), angles)
    c = clearances(replace(problem, cones=[cone]), np.zeros(len(q)), q)[:, 0]
    assert c[0] == pytest.approx(0.5 * BOUNDARY_TOLERANCE, abs=1e-9) and c[100] == pytest.approx(-0.5e-6, abs=1e-9)


# -- forced boundary arcs ---------------------------------------------------------------------------

def arc_request(method: str = "time_optimal", option: float = 0.0, **fields) -> ManeuverRequest:
    """BA2 on swift_demo (J = 100 I, 0.1 N m): sensor on the 23° cone's boundary, −70° about its axis."""
    problem = boundary_problem("ba2")
    c = problem.cones[0]
    base = dict(frame_id="eci", q_initial=rot.IDENTITY, q_final=rot.IDENTITY, sensor_axis=problem.sensor_axis,
                cones=[(c.direction, c.half_angle, "moon")], method=method, time_budget=BUDGET, semi_free=True,
                sensor_target=problem.sensor_target, option_names=["boundary_cone"], option_values=[option])
    return ManeuverRequest(**(base | fields))


@pytest.mark.parametrize("method", ["time_optimal", "constrained_axis"])
def test_a_forced_boundary_arc_is_planned_and_stays_on_the_boundary(method):
    valid = validate(arc_request(method))
    assert valid.problem.boundary_cone == 0
    outcome = plan_maneuver(valid, runner=run_method)
    assert outcome.code == ErrorCode.OK and outcome.plan.method == method, outcome.message
    assert outcome.verification.boundary_arc == "moon"
    ver, traj = prediction_check(valid.problem, outcome.plan, dense_fraction=2000)
    b = rot.dcm_NB(traj.q_BN) @ valid.problem.sensor_axis
    off = np.abs(np.arccos(np.clip(b @ valid.problem.cones[0].direction, -1, 1)) - valid.problem.cones[0].half_angle)
    assert off.max() <= ARC_TOLERANCE and ver.final_attitude_error <= math.radians(0.5)


def test_leaving_the_arc_is_rejected_by_the_verification():
    """The boundary-points plan of the same cone leaves the boundary: verified against the arc it fails."""
    bp = plan_time_optimal(boundary_problem("bp2"))
    why = rejection(verify(boundary_problem("ba2"), bp))
    assert why is not None and why.startswith("leaves the boundary of cone cone by")


@pytest.mark.parametrize("fields, words", [
    (dict(option_values=[3.0]), "option boundary_cone = 3 names no cone of the request (its cones: 0: 'moon')"),
    (dict(q_initial=rot.from_axis_angle([0, 0, 1], 0.3)), None),          # still on it: turned about its axis
    (dict(sensor_target=np.array([1.0, 0.0, 0.0])), "the sensor_target direction is 67 deg outside the boundary"),
    (dict(method="eigenaxis"), "option boundary_cone is not an option of method 'eigenaxis'"),
    (dict(option_values=[0.5]), "must be an integer"),
])
def test_hostile_boundary_arcs_are_refused_with_a_sentence(fields, words):
    if words is None:
        validate(arc_request(**fields))
        return
    with pytest.raises(RequestError) as err:
        validate(arc_request(**fields))
    assert err.value.code == ErrorCode.INVALID_OPTION and words in err.value.message, err.value.message


# -- Melton's two stages ----------------------------------------------------------------------------

@pytest.mark.slow
def test_the_swarm_seed_reduces_the_collocation_iterations():
    """BP2: the swarm's plan as the one start needs fewer IPOPT iterations than the multi-start, for
    the same t_f (the benchmark's table has all four cases)."""
    problem = boundary_problem("bp2")
    multi, two = plan_time_optimal(problem), plan_time_optimal(problem, global_stage=True)
    assert multi.success and two.success
    assert two.stats["global_stage"]["iterations"] > 0 and [s["route"] for s in two.stats["starts"]] == ["swarm"]
    assert two.nit < multi.nit
    assert two.duration <= multi.duration * (1 + 1e-4)
