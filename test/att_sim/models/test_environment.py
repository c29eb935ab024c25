"""Orbit, tilted-dipole field and gravity-gradient helpers of att_sim.models.environment."""
import math

import numpy as np
import pytest

from att_sim.models import environment as env
from att_sim.models import rotations as rot

ORBIT = env.OrbitParams(altitude=450e3, inclination=math.radians(87.0), raan=0.0)


def test_orbit_radius_period_and_circularity():
    assert ORBIT.radius == pytest.approx(6378.137e3 + 450e3)
    # T = 2π sqrt(R³/μ): about 5615 s at 450 km with the WGS-84 radius (the paper quotes ≈5609 s)
    assert ORBIT.period == pytest.approx(2 * math.pi * math.sqrt(ORBIT.radius**3 / env.EARTH_MU))
    assert 5600.0 < ORBIT.period < 5620.0
    t = np.linspace(0.0, ORBIT.period, 50)
    r = env.position(ORBIT, t)
    np.testing.assert_allclose(np.linalg.norm(r, axis=1), ORBIT.radius, rtol=1e-12)
    np.testing.assert_allclose(r[0], r[-1], atol=1e-3)            # periodic
    # angular momentum direction = orbit normal R_z(Ω) R_x(i) e3
    h = np.cross(r[0], r[5]) / np.linalg.norm(np.cross(r[0], r[5]))
    np.testing.assert_allclose(h, [0.0, -math.sin(ORBIT.inclination), math.cos(ORBIT.inclination)], atol=1e-12)


def test_position_matches_rotated_plane_and_arg0_is_a_phase():
    o = env.OrbitParams(inclination=0.7, raan=1.1, arg0=0.3)
    t = 123.0
    u = o.mean_motion * t + 0.3
    rz = np.array([[math.cos(1.1), -math.sin(1.1), 0], [math.sin(1.1), math.cos(1.1), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, math.cos(0.7), -math.sin(0.7)], [0, math.sin(0.7), math.cos(0.7)]])
    np.testing.assert_allclose(env.position(o, t), o.radius * rz @ rx @ [math.cos(u), math.sin(u), 0.0], rtol=1e-12)
    # per-case ψ broadcasts against a scalar time
    psis = np.array([0.0, 0.3, 2.0])
    p = env.position(o, t, arg0=psis)
    assert p.shape == (3, 3)
    np.testing.assert_allclose(p[1], env.position(o, t), rtol=1e-12)


def test_dipole_field_magnitude_and_direction():
    # at the magnetic equator |B| = μm/R³, at the magnetic poles 2 μm/R³, and B_i = k(3(m·r)r − m)
    t = np.linspace(0.0, 3 * ORBIT.period, 400)
    b = env.field_inertial(ORBIT, t)
    r = env.position(ORBIT, t) / ORBIT.radius
    m = env.DEFAULT_DIPOLE.axis(t)
    k = env.DIPOLE_STRENGTH / ORBIT.radius**3
    np.testing.assert_allclose(b, k * (3 * np.sum(m * r, 1)[:, None] * r - m), rtol=1e-12)
    mag = np.linalg.norm(b, axis=1)
    assert k * 0.999 < mag.min() and mag.max() < 2 * k * 1.001
    assert 2.3e-5 < k < 2.5e-5                                     # ≈ 24 µT at 450 km
    # dipole axis: θm = 170° from +z (southern), rotating with the Earth at 360.99°/day
    np.testing.assert_allclose(env.DEFAULT_DIPOLE.axis(0.0),
                               [math.sin(math.radians(170)), 0, math.cos(math.radians(170))])
    one_day = env.DEFAULT_DIPOLE.axis(86400.0)
    ang = math.atan2(one_day[1], one_day[0])
    assert ang == pytest.approx(math.radians(0.99), abs=1e-9)


def test_field_body_is_C_of_q_times_field():
    rng = np.random.default_rng(0)
    q = rot.normalize(rng.normal(size=(5, 4)))
    t = rng.uniform(0, 1e4, 5)
    bi = env.field_inertial(ORBIT, t)
    bb = env.field_body(ORBIT, t, q)
    for n in range(5):
        np.testing.assert_allclose(bb[n], rot.dcm_BN(q[n]) @ bi[n], rtol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(bb[n]), np.linalg.norm(bi[n]), rtol=1e-12)


def test_paper_attitude_matrix_is_dcm_transpose():
    """C(q) = (q4² − q_vᵀq_v) I + 2 q_v q_vᵀ − 2 q4 q_v× (Bruni & Celani) equals dcm_BN(q)."""
    rng = np.random.default_rng(1)
    for q in rot.normalize(rng.normal(size=(20, 4))):
        qv, q4 = q[:3], q[3]
        c = (q4**2 - qv @ qv) * np.eye(3) + 2 * np.outer(qv, qv) - 2 * q4 * rot.hat(qv)
        np.testing.assert_allclose(c, rot.dcm_BN(q), atol=1e-14)


def test_gravity_gradient_torque():
    j = np.diag([27.0, 17.0, 25.0])
    # principal axis along the radius: no torque
    t = 0.0
    r = env.position(ORBIT, t) / ORBIT.radius
    axis = np.cross([1.0, 0, 0], r)
    angle = math.acos(np.clip(r[0], -1, 1))
    q_aligned = rot.from_axis_angle(axis, angle) if np.linalg.norm(axis) > 1e-12 else rot.IDENTITY
    np.testing.assert_allclose(env.gravity_gradient_torque(ORBIT, t, q_aligned, j), 0.0, atol=1e-12)
    # general attitude: 3μ/R³ r_b × J r_b and perpendicular to r_b
    q = rot.normalize(np.array([0.2, -0.4, 0.1, 0.9]))
    rb = rot.dcm_BN(q) @ r
    tau = env.gravity_gradient_torque(ORBIT, t, q, j)
    np.testing.assert_allclose(tau, 3 * env.EARTH_MU / ORBIT.radius**3 * np.cross(rb, j @ rb), rtol=1e-12)
    assert abs(tau @ rb) < 1e-18
    assert 1e-7 < np.linalg.norm(tau) < 1e-4
