"""Track-to-track slews: the Jacobians, the path's exact ends and kinematics, and one slew between two
sites of the aeos scenario found within the bounds and verified."""
from __future__ import annotations

import math

import numpy as np

from att_planner.guidance.ground_arrival import ground_motion, site_in_view
from att_planner.guidance.laws import PointingGeometry, directions
from att_planner.imaging import slews
from att_planner.mission.targets import next_axis
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

RNG = np.random.default_rng(7)


def test_the_right_jacobian_and_its_inverse_are_inverses_and_give_the_body_rate():
    r = RNG.normal(size=(5, 3)) * np.array([[1e-8], [1e-3], [0.5], [1.5], [2.8]])
    eye = np.einsum("kij,kjl->kil", slews.right_jacobian(r), slews.right_jacobian_inverse(r))
    assert np.allclose(eye, np.eye(3), atol=1e-9)
    # the body rate of q0 ⊗ exp(r + ṙ t) at t = 0 is J_r(r) ṙ
    q0, v, h = rot.normalize(RNG.normal(size=4)), RNG.normal(size=3), 1e-6
    for ri in r:
        qa, qb = rot.multiply(q0, rot.exp_map(ri - h * v)), rot.multiply(q0, rot.exp_map(ri + h * v))
        numeric = rot.log_map(rot.multiply(rot.conjugate(qa), qb)) / (2 * h)
        assert np.allclose(numeric, slews.right_jacobian(ri)[0] @ v, atol=1e-6)


def test_the_path_starts_and_ends_exactly_on_the_given_states_and_its_rate_is_its_attitudes_derivative():
    q0, q1 = rot.normalize(RNG.normal(size=4)), rot.normalize(RNG.normal(size=4))
    w0, w1 = RNG.normal(size=3) * 0.01, RNG.normal(size=3) * 0.01
    t, q, omega, torque = slews.profile(q0, w0, q1, w1, 40.0, np.diag([82.1, 98.4, 121.0]), knots=4001)
    assert rot.angle_between(q[0], q0) < 1e-12 and rot.angle_between(q[-1], q1) < 1e-9
    assert np.allclose(omega[0], w0, atol=1e-12) and np.allclose(omega[-1], w1, atol=1e-9)
    k, dt = 2000, t[1] - t[0]
    numeric = rot.log_map(rot.multiply(rot.conjugate(q[k - 1]), q[k + 1])) / (2 * dt)
    assert np.allclose(numeric, omega[k], atol=1e-8)
    J = np.diag([82.1, 98.4, 121.0])       # τ = J ω̇ + ω × J ω against a difference of the rates
    omega_dot = (omega[k + 1] - omega[k - 1]) / (2 * dt)
    assert np.allclose(J @ omega_dot + np.cross(omega[k], J @ omega[k]), torque[k], atol=1e-6)


def test_a_slew_between_two_sites_is_the_shortest_within_the_bounds_and_verifies():
    scenario = scen.load("aeos")
    geometry = PointingGeometry.of(world.Environment.from_scenario(scenario))
    boresight = np.array([0.0, 0.0, 1.0])
    along, velocity = next_axis(boresight), directions(geometry)["velocity"]

    def site(t, off_nadir_deg, azimuth_deg):
        lat, lon = site_in_view(geometry, t, math.radians(off_nadir_deg), math.radians(azimuth_deg))
        return ground_motion(geometry, lat, lon, 0.0, boresight, along, velocity)

    first, second = site(300.0, 25.0, 90.0), site(330.0, 25.0, -90.0)
    limits = slews.Limits.of(scenario.spacecraft, math.radians(5.0), 50.0)
    slew = slews.fastest(first(250.0), 250.0, second, limits)
    assert slew is not None and 10.0 < slew.duration_s < 120.0
    check = slews.verify(slew, scenario.spacecraft, second, limits)
    assert check.refusal is None, check
    assert check.final_attitude_error < math.radians(0.05) and check.final_rate_error < math.radians(0.01)
    assert 1.0 - 2 * slews.BOUND_MARGIN < check.torque_ratio <= 1.0       # the torque bound is what limits it
    shorter = slews.build(first(250.0), 250.0, second, 0.9 * slew.duration_s, limits)
    assert limits.ratio(shorter.plan.omega, shorter.plan.torque) > 1.0
