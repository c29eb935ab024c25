"""Disturbance torques (att_sim.models.disturbances) and the exponential atmosphere (att_sim.models.atmosphere),
each against a case computed by hand."""
import math

import numpy as np
import pytest

from att_sim.models import atmosphere as atm
from att_sim.models import disturbances as dist
from att_sim.models import environment as env
from att_sim.models import rotations as rot

P = dist.SOLAR_PRESSURE_1AU
AU = dist.ASTRONOMICAL_UNIT
Q_Z90 = np.array([0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)])   # body x -> inertial y


def _box(lx=2.0, ly=1.0, lz=0.5, specular=0.3, diffuse=0.2):
    """A rectangular box centred on the centre of mass: six facets."""
    half = np.array([lx, ly, lz]) / 2
    area = {0: ly * lz, 1: lx * lz, 2: lx * ly}
    return [dist.Facet(area[i], tuple(sign * np.eye(3)[i]), tuple(sign * half[i] * np.eye(3)[i]), specular, diffuse)
            for i in range(3) for sign in (1.0, -1.0)]


def test_srp_on_a_facet_facing_the_sun_at_1_au_by_hand():
    facet = dist.Facet(2.0, (1.0, 0.0, 0.0), (0.0, 0.5, 0.1), 0.3, 0.2)
    # cos θ = 1: F = −P A [2 (δ/3 + ρ) n̂ + (1 − ρ) ŝ] = −P·2·(2·(0.2/3 + 0.3) + 0.7) x̂
    f = -P * 2.0 * (2 * (0.2 / 3 + 0.3) + 0.7)
    expect = np.cross([0.0, 0.5, 0.1], [f, 0.0, 0.0])                      # c × F
    np.testing.assert_allclose(expect, [0.0, 0.1 * f, -0.5 * f])
    np.testing.assert_allclose(dist.srp_torque([facet], rot.IDENTITY, [1.0, 0.0, 0.0], AU, 1.0), expect, rtol=1e-14)
    # the same facet, spacecraft turned 90° about z: the Sun along inertial y is along body x
    np.testing.assert_allclose(dist.srp_torque([facet], Q_Z90, [0.0, 5.0, 0.0], AU, 1.0), expect, rtol=1e-12,
                               atol=1e-20)
    # (1 AU / d)² and the shadow fraction scale it; full shadow gives zero
    np.testing.assert_allclose(dist.srp_torque([facet], rot.IDENTITY, [1.0, 0.0, 0.0], 2 * AU, 0.5), expect / 8,
                               rtol=1e-14)
    assert np.all(dist.srp_torque([facet], rot.IDENTITY, [1.0, 0.0, 0.0], AU, 0.0) == 0.0)


def test_srp_oblique_edge_on_and_back_facets():
    absorber = dist.Facet(1.0, (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.0, 0.0)
    s = np.array([math.cos(math.pi / 3), math.sin(math.pi / 3), 0.0])     # θ = 60°
    f = -P * 1.0 * 0.5 * s                                                # −P A cos θ ŝ (absorbed)
    np.testing.assert_allclose(dist.srp_torque([absorber], rot.IDENTITY, s, AU, 1.0), np.cross([0, 0, 1.0], f),
                               rtol=1e-13)
    mirror = dist.Facet(1.0, (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), 1.0, 0.0)
    f = -P * 0.5 * 2 * 0.5 * np.array([1.0, 0.0, 0.0])                    # −P A cos θ · 2 cos θ n̂
    np.testing.assert_allclose(dist.srp_torque([mirror], rot.IDENTITY, s, AU, 1.0), np.cross([0, 0, 1.0], f),
                               rtol=1e-13)
    for sun in ([0.0, 1.0, 0.0], [-1.0, 0.2, 0.0]):                       # edge-on, behind
        assert np.all(dist.srp_torque([absorber, mirror], rot.IDENTITY, sun, AU, 1.0) == 0.0)


def test_srp_and_drag_on_a_symmetric_box_are_zero_and_broadcast():
    box = _box()
    q = rot.normalize(np.random.default_rng(4).normal(size=(20, 4)))
    d = np.random.default_rng(5).normal(size=(20, 3))
    np.testing.assert_allclose(dist.srp_torque(box, q, d, AU, 1.0), 0.0, atol=1e-20)
    np.testing.assert_allclose(dist.drag_torque(box, q, 7500.0 * d, 1e-12), 0.0, atol=1e-15)   # forces ~1e-4 N
    assert dist.srp_torque(box, q, d, AU, np.ones(20)).shape == (20, 3)
    # an offset box is not: the centre of pressure moves by 0.1 m along z
    shifted = [dist.Facet(f.area, f.normal_B, tuple(np.add(f.center_B, [0, 0, 0.1])), 0.3, 0.2) for f in box]
    assert np.linalg.norm(dist.drag_torque(shifted, rot.IDENTITY, [7500.0, 0.0, 0.0], 1e-12)) > 1e-7


def test_drag_on_a_facet_facing_the_flow_by_hand():
    facet = dist.Facet(1.5, (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.0, 0.0)
    f = -0.5 * 1e-12 * 2.2 * 1.5 * 7500.0**2                              # N along x̂
    np.testing.assert_allclose(dist.drag_torque([facet], rot.IDENTITY, [7500.0, 0.0, 0.0], 1e-12),
                               [0.0, 0.0, -f], rtol=1e-14)               # (0,1,0) × (f,0,0) = (0,0,−f)
    np.testing.assert_allclose(dist.drag_torque([facet], Q_Z90, [0.0, 7500.0, 0.0], 1e-12, cd=2.2),
                               [0.0, 0.0, -f], rtol=1e-12, atol=1e-22)
    v = 7500.0 * np.array([math.cos(0.4), 0.0, math.sin(0.4)])            # 0.4 rad off the normal
    np.testing.assert_allclose(dist.drag_torque([facet], rot.IDENTITY, v, 1e-12, cd=2.0),
                               np.cross([0, 1.0, 0], -0.5e-12 * 2.0 * 1.5 * math.cos(0.4) * 7500.0 * v), rtol=1e-13)
    assert np.all(dist.drag_torque([facet], rot.IDENTITY, [-7500.0, 0.0, 0.0], 1e-12) == 0.0)   # leeward
    assert np.all(dist.drag_torque([facet], rot.IDENTITY, [0.0, 0.0, 0.0], 1e-12) == 0.0)       # at rest


def test_one_attitude_and_a_stack_give_the_same_torques():
    facets = [dist.Facet(1.0 + k, tuple(n / np.linalg.norm(n)), tuple(c), 0.2, 0.3)
              for k, (n, c) in enumerate(np.random.default_rng(7).normal(size=(5, 2, 3)))]
    q = rot.normalize(np.random.default_rng(8).normal(size=(6, 4)))
    u = np.random.default_rng(9).normal(size=(6, 3))
    r = 7e6 * u / np.linalg.norm(u, axis=1, keepdims=True)
    inertia = np.array([[3000.0, 10.0, -5.0], [10.0, 4500.0, 2.0], [-5.0, 2.0, 6000.0]])
    stacks = (dist.srp_torque(facets, q, u, AU, 0.7), dist.drag_torque(facets, q, 7500.0 * u, 1e-12),
              dist.gravity_gradient_torque(r, q, inertia), dist.residual_dipole_torque(u, 2e-5 * u[::-1]),
              dist.relative_velocity(r, 7500.0 * u))
    for k in range(6):
        ones = (dist.srp_torque(facets, q[k], u[k], AU, 0.7), dist.drag_torque(facets, q[k], 7500.0 * u[k], 1e-12),
                dist.gravity_gradient_torque(r[k], q[k], inertia), dist.residual_dipole_torque(u[k], 2e-5 * u[5 - k]),
                dist.relative_velocity(r[k], 7500.0 * u[k]))
        for one, stack in zip(ones, stacks):
            np.testing.assert_allclose(one, stack[k], rtol=1e-12, atol=1e-20)
    assert np.any(stacks[0] != 0.0) and np.any(stacks[1] != 0.0)
    np.testing.assert_allclose(atm.density(np.array(480e3)), atm.density(480e3), rtol=1e-15)


def test_relative_velocity_removes_the_corotating_atmosphere():
    r, v = np.array([7000e3, 0.0, 0.0]), np.array([0.0, 7500.0, 0.0])
    np.testing.assert_allclose(dist.relative_velocity(r, v), [0.0, 7500.0 - 7.292115e-5 * 7000e3, 0.0])
    np.testing.assert_allclose(dist.relative_velocity([0.0, 0.0, 7e6], v), v)                  # over the pole
    assert dist.relative_velocity(np.ones((4, 3)), np.zeros((4, 3))).shape == (4, 3)


def test_residual_dipole_torque_by_hand():
    np.testing.assert_allclose(dist.residual_dipole_torque([0.0, 0.0, 1.0], [20e-6, 0.0, 0.0]), [0.0, 20e-6, 0.0])
    assert dist.residual_dipole_torque(np.ones((5, 3)), np.ones((5, 3))).shape == (5, 3)


def test_gravity_gradient_principal_axis_45_degrees_and_environment():
    inertia = np.diag([3000.0, 4500.0, 6000.0])
    r = 7000e3
    assert np.all(dist.gravity_gradient_torque([r, 0.0, 0.0], rot.IDENTITY, inertia) == 0.0)    # along a principal axis
    # r at 45° between body x and y: τ = (3μ/R³) ½ (J_y − J_x) ẑ
    q45 = np.array([0.0, 0.0, math.sin(-math.pi / 8), math.cos(-math.pi / 8)])               # body turned −45° about z
    expect = 3 * env.EARTH_MU / r**3 * 0.5 * (4500.0 - 3000.0)
    np.testing.assert_allclose(dist.gravity_gradient_torque([r, 0.0, 0.0], q45, inertia), [0.0, 0.0, expect],
                               rtol=1e-12, atol=1e-18)
    orbit = env.OrbitParams(altitude=600e3, inclination=0.9, raan=0.4)
    t = np.linspace(0.0, 3000.0, 7)
    q = rot.normalize(np.random.default_rng(6).normal(size=(7, 4)))
    np.testing.assert_allclose(dist.gravity_gradient_torque(env.position(orbit, t), q, inertia),
                               env.gravity_gradient_torque(orbit, t, q, inertia), rtol=1e-10, atol=1e-16)


def test_exponential_atmosphere_vallado_table_8_4():
    assert atm.density(0.0) == 1.225 and atm.density(400e3) == 3.725e-12 and atm.density(1000e3) == 3.019e-15
    # 580 km: band 500 km, ρ = 6.967e-13 exp(−80/63.822)
    assert atm.density(580e3) == pytest.approx(6.967e-13 * math.exp(-80.0 / 63.822), rel=1e-14)
    assert atm.density(1500e3) == pytest.approx(3.019e-15 * math.exp(-500.0 / 268.0), rel=1e-14)
    h = np.array([[0.0, 120e3], [450e3, 699e3]])
    rho = atm.density(h)
    assert rho.shape == (2, 2) and rho[1, 1] == pytest.approx(1.454e-13 * math.exp(-99.0 / 71.835))
    for bad in (-1.0, math.nan, [100e3, -5.0]):
        with pytest.raises(ValueError, match="altitude must be at least 0 m"):
            atm.density(bad)


def _scenario_facets(facets) -> list:
    """The facets a scenario's ``environment.facets`` build: validated by the schema, built by the reader."""
    from types import SimpleNamespace

    from att_sim.models import config_schema as cs
    from att_sim.models import scenario as scen
    shared = cs.Shared.model_validate({"spacecraft": {"inertia_kg_m2": [1.0, 1.0, 1.0], "wheel_axes": []},
                                       "environment": {"facets": facets}})
    return scen._Build(SimpleNamespace(shared=shared, lines={}, path="scenario.yaml")).environment()["facets"]


def test_scenario_facets_are_checked_field_by_field():
    from pydantic import ValidationError
    good = {"area_m2": 1.2, "normal": [0.0, 0.0, 1.0], "center_m": [0.1, 0.0, 0.5], "specular": 0.1, "diffuse": 0.3}
    facets = _scenario_facets([good, dict(good, normal=[0.0, 1.0005, 0.0])])
    assert facets[0] == dist.Facet(1.2, (0.0, 0.0, 1.0), (0.1, 0.0, 0.5), 0.1, 0.3)
    assert facets[1].normal_B == (0.0, 1.0, 0.0) and facets[0].absorption == pytest.approx(0.6)
    at = r"environment.facets.2"
    cases = [
        (dict(good, normal=[0.0, 0.9, 0.0]), rf"{at}.normal\n  Value error, a unit vector"),
        (dict(good, area_m2=0.0), rf"{at}.area_m2\n  Input should be greater than 0"),
        (dict(good, area_m2="big"), rf"{at}.area_m2\n  Input should be a valid number"),
        (dict(good, center_m=[0.0, math.inf, 0.0]), rf"{at}.center_m.1\n  Value error, a finite number"),
        (dict(good, normal=[0.0, 1.0]), rf"{at}.normal\n  List should have at least 3 items"),
        (dict(good, specular=-0.1), rf"{at}.specular\n  Input should be greater than or equal to 0"),
        (dict(good, diffuse=1.5), rf"{at}.diffuse\n  Input should be less than or equal to 1"),
        (dict(good, specular=0.6, diffuse=0.5), rf"{at}\n  Value error, specular \+ diffuse at most 1"),
        ({k: v for k, v in good.items() if k != "diffuse"}, rf"{at}.diffuse\n  Field required"),
        (dict(good, colour="red"), rf"{at}.colour\n  Extra inputs are not permitted"),
        ([1, 2], rf"{at}\n  Input should be a valid dictionary"),
    ]
    for item, message in cases:
        with pytest.raises(ValidationError, match=message):
            _scenario_facets([good, good, item])
    with pytest.raises(ValidationError, match=r"environment.facets\n  Input should be a valid list"):
        _scenario_facets(good)
    with pytest.raises(ValueError, match="facet.normal_B is not a unit vector"):
        dist.Facet(1.0, (2.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.0, 0.0)


def test_bad_torque_inputs_are_refused():
    box = _box()
    with pytest.raises(ValueError, match=r"shadow must be a visible fraction of the solar disc in \[0, 1\]"):
        dist.srp_torque(box, rot.IDENTITY, [1.0, 0, 0], AU, 1.2)
    with pytest.raises(ValueError, match="sun_distance_m must be > 0"):
        dist.srp_torque(box, rot.IDENTITY, [1.0, 0, 0], 0.0, 1.0)
    with pytest.raises(ValueError, match="sun_direction_N must be a nonzero vector"):
        dist.srp_torque(box, rot.IDENTITY, [0.0, 0, 0], AU, 1.0)
    with pytest.raises(ValueError, match="density must be at least 0"):
        dist.drag_torque(box, rot.IDENTITY, [7500.0, 0, 0], -1.0)
    with pytest.raises(ValueError, match="v_rel_N must be finite"):
        dist.drag_torque(box, rot.IDENTITY, [math.nan, 0, 0], 1e-12)
    with pytest.raises(ValueError, match="shadow must be"):
        dist.srp_torque(box, rot.IDENTITY, [1.0, 0, 0], AU, math.nan)
    with pytest.raises(ValueError, match="cd must be a finite drag coefficient > 0"):
        dist.drag_torque(box, rot.IDENTITY, [7500.0, 0, 0], 1e-12, cd=0.0)
    assert np.all(dist.srp_torque([], rot.IDENTITY, [1.0, 0, 0], AU, 1.0) == 0.0)          # no facets: no torque
