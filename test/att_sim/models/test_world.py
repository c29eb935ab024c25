"""The simulator's world: scenarios without the real sky's keys fly the circular world, the real sky composed from the
scenario, the field and position published at the published state, the real-sky scenario keys checked."""
import math
import time
from dataclasses import replace

import numpy as np
import pytest
import yaml

from att_msgs_py.errors import ConfigError, ErrorCode
from att_msgs_py.types import Command, ControlMode
from att_sim.models import atmosphere, scenario, world
from att_sim.models import disturbances as dist
from att_sim.models import environment as env
from att_sim.models import rotations as rot
from att_sim.models.actuator_specs import ActuatorSpecs
from att_sim.models.orbit import CircularOrbit, TLEOrbit
from att_sim.truth.simulation import Simulation

Q = rot.normalize(np.array([0.2, -0.4, 0.1, 0.9]))


@pytest.fixture(scope="module")
def leo():
    return scenario.load("leo_observatory")


# ------------------------------------------------------------------- scenarios without the real sky
def test_a_scenario_without_the_real_sky_keys_is_the_circular_world():
    s = scenario.load("swift_demo")
    assert s.epoch is None and s.field_model == "dipole" and s.zones == []
    assert isinstance(s.orbit_model, CircularOrbit) and s.orbit_model.params == s.orbit
    assert not any(s.environment[k] for k in ("gravity_gradient", "solar_pressure", "drag"))
    for gravity_gradient in (False, True):
        e = world.Environment.from_scenario(s, gravity_gradient)
        for t in (0.0, 123.4, 5000.0):
            got = e.sample(t, Q)
            b = env.field_body(s.orbit, t, Q)
            np.testing.assert_allclose(got.field_B, b, rtol=0, atol=1e-15 * np.linalg.norm(b))
            np.testing.assert_array_equal(got.position, env.position(s.orbit, t))
            gg = env.gravity_gradient_torque(s.orbit, t, Q, s.spacecraft.inertia) if gravity_gradient else np.zeros(3)
            np.testing.assert_allclose(got.torque_B, gg, rtol=1e-12, atol=1e-16)
            assert got.shadow == 1.0


def test_the_state_carries_the_field_and_position_at_the_published_state():
    s = scenario.load("bruni_celani")
    sim = Simulation(s.spacecraft, s.orbit, omega0=[0.02, 0.02, -0.03])
    state = sim.state()                           # t = 0: the field at t = 0, not zero
    np.testing.assert_allclose(state.field_body, env.field_body(s.orbit, 0.0, sim.x[:4]), rtol=1e-14)
    sim.set_command(Command(mode=ControlMode.MAGNETORQUER_PD, wheel_torques=np.zeros(0),
                            dipole=np.array([5.0, -3.0, 2.0])))
    for _ in range(7):
        q_before = sim.x[:4].copy()
        sim.advance(0.5)
    state = sim.state()
    assert state.t == pytest.approx(3.5)
    np.testing.assert_allclose(state.field_body, env.field_body(s.orbit, 3.5, state.q), rtol=1e-14)
    np.testing.assert_array_equal(state.position, env.position(s.orbit, 3.5))
    # the applied torque is the step's mean m x B (RK4 weights), close to m x B mid-step
    mid = np.cross([5.0, -3.0, 2.0], env.field_body(s.orbit, 3.25, rot.slerp(q_before, state.q, 0.5)))
    np.testing.assert_allclose(state.applied_torque, mid, rtol=0, atol=2e-3 * np.linalg.norm(mid))


def test_circular_orbit_phase_resets_and_element_orbits_refuse_a_phase(leo):
    s = scenario.load("swift_demo")
    sim = Simulation(s.spacecraft, s.orbit)
    sim.advance(0.5)
    assert sim.reset(rot.IDENTITY, [0, 0, 0], [], 1.0) is None
    np.testing.assert_allclose(sim.state().position, env.position(s.orbit, 0.0, 1.0), rtol=1e-12)
    sim = Simulation.for_scenario(leo)
    assert sim.reset(rot.IDENTITY, [0, 0, 0], [], 0.0) is None
    refusal = sim.reset(rot.IDENTITY, [0, 0, 0], [], 0.5)
    assert refusal.code == ErrorCode.INVALID_RESET and "orbit_phase must be 0" in refusal.message


def test_reset_wheel_speeds_are_limited_relative_to_the_body():
    s = scenario.load("swift_demo")                # wheel_speed_max 630 rad/s
    sim = Simulation(s.spacecraft, s.orbit)
    assert sim.reset(rot.IDENTITY, [0, 0, 0.5], [0, 0, 630.4], 0.0) is None          # 629.9 relative
    refusal = sim.reset(rot.IDENTITY, [0, 0, -0.5], [0, 0, 629.8], 0.0)             # 630.3 relative
    assert refusal.code == ErrorCode.INVALID_RESET and "relative to the body" in refusal.message


# ------------------------------------------------------------------------------ the real sky
def test_leo_observatory_is_the_issues_scenario(leo):
    assert leo.epoch.isoformat() == "2026-12-21T00:00:00+00:00" and leo.frame_id == "gcrs"
    assert isinstance(leo.orbit_model, TLEOrbit) and leo.orbit is None and leo.field_model == "igrf14"
    np.testing.assert_array_equal(np.diag(leo.spacecraft.inertia), [3000.0, 4500.0, 6000.0])
    assert leo.spacecraft.body_torque_max == 0.25 and leo.spacecraft.n_wheels == 3
    assert all(leo.environment[k] for k in ("gravity_gradient", "solar_pressure", "drag"))
    assert len(leo.environment["facets"]) == 6
    assert [(z.body, round(math.degrees(z.half_angle), 9), z.keep_in) for z in leo.zones] == [
        ("sun", 47.0, False), ("moon", 23.0, False), ("earth_limb", 10.0, False)]
    assert all(z.sensor_axis.tolist() == [0.0, 1.0, 0.0] for z in leo.zones)
    altitude = np.linalg.norm(leo.orbit_model.position(0.0)) - env.EARTH_RADIUS
    assert 570e3 < altitude < 600e3


def test_each_torque_is_its_model_at_the_stage_state(leo):
    """The environment hands each disturbance model the orbit's, the sky's and the field's values."""
    e = world.Environment.from_scenario(leo)
    t = 1234.5
    r, v = leo.orbit_model.state(t)
    tq = e.torques(t, Q)
    assert set(tq) == {"gravity_gradient", "solar_pressure", "drag", "residual_dipole"}
    facets = leo.environment["facets"]
    sun = e.sky.sun(t) - r
    b_body = rot.dcm_BN(Q) @ e.field.field_inertial(t, r)
    v_rel = v - np.cross([0.0, 0.0, 7.292115e-5], r)           # the air co-rotates
    rho = atmosphere.density(np.linalg.norm(r) - env.EARTH_RADIUS)
    expected = {
        "gravity_gradient": dist.gravity_gradient_torque(r, Q, leo.spacecraft.inertia),
        "solar_pressure": dist.srp_torque(facets, Q, sun / np.linalg.norm(sun), np.linalg.norm(sun), e.sky.shadow(t)),
        "drag": dist.drag_torque(facets, Q, v_rel, rho, 2.2),
        "residual_dipole": np.cross([0.5, -0.3, 1.0], b_body)}
    for name, value in expected.items():
        np.testing.assert_allclose(tq[name], value, rtol=1e-6, atol=1e-12 * np.linalg.norm(value), err_msg=name)
    sample = e.sample(t, Q)
    np.testing.assert_allclose(sample.field_B, b_body, rtol=0, atol=1e-12)      # the track: < 1e-3 nT
    np.testing.assert_allclose(sample.torque_B, sum(expected.values()), rtol=1e-6)
    assert 1e-5 < np.linalg.norm(sample.field_B) < 6e-5           # LEO: 20..50 µT
    assert 1e-4 < np.linalg.norm(tq["gravity_gradient"]) < 1e-2
    for name in ("solar_pressure", "drag", "residual_dipole"):
        assert 1e-8 < np.linalg.norm(tq[name]) < 1e-3, name


def test_a_real_sky_step_is_cheap_and_fourth_order(leo):
    """TLE + IGRF-14 + every disturbance: per-step cost well under the 6 ms of step 0.05 s at RTF 8,
    and a constant-dipole run converges at fourth order in the step (ideal actuators: the drives'
    noise, drawn per step, differs between step sizes)."""
    leo = replace(leo, actuators=ActuatorSpecs())
    sim = Simulation.for_scenario(leo, omega0=[0.002, -0.001, 0.003])
    sim.set_command(Command(mode=ControlMode.MAGNETORQUER_PD, wheel_torques=np.zeros(0),
                            dipole=np.array([40.0, -30.0, 20.0])))
    sim.advance(0.05)                                  # first IGRF track and tables
    costs = []
    for _ in range(200):
        start = time.perf_counter()
        sim.advance(0.05)
        costs.append(time.perf_counter() - start)
    assert not sim.halted
    assert np.median(costs) < 3e-3, np.median(costs)

    def run(dt):
        s = Simulation.for_scenario(leo, omega0=[0.02, -0.01, 0.03])
        s.set_command(Command(mode=ControlMode.MAGNETORQUER_PD, wheel_torques=np.zeros(0),
                              dipole=np.array([40.0, -30.0, 20.0])))
        for _ in range(int(round(120.0 / dt))):
            s.advance(dt)
        return s.x
    ref = run(0.5)
    e = [np.linalg.norm(run(dt) - ref) for dt in (4.0, 2.0)]
    assert e[0] / e[1] > 12, e


# ------------------------------------------------------------------------- scenario keys checked
def _file(tmp_path, **shared):
    """leo_observatory as one self-contained file with ``shared`` keys changed (``...``: removed);
    without its sensors unless given (their Sun and Moon exclusions need the epoch some cases take away)."""
    resolved = scenario.read(scenario.find("leo_observatory")).shared    # its scenario and spacecraft files resolved
    doc = {"/**": {"ros__parameters": {**resolved.model_dump(mode="json", exclude_none=True, exclude={"orbit"}),
                                       "orbit": resolved.orbit.model_dump(mode="json")}}}
    p = doc["/**"]["ros__parameters"]
    p.pop("sensors")
    for key, value in shared.items():
        group, _, sub = key.partition("__")
        if sub:
            if value is ...:
                del p[group][sub]
            else:
                p[group][sub] = value
        elif value is ...:
            del p[group]
        else:
            p[group] = value
    path = tmp_path / "sky_case.yaml"
    path.write_text(yaml.safe_dump(doc))
    return str(path)


FACET = {"area_m2": 1.0, "normal": [1.0, 0.0, 0.0], "center_m": [0.1, 0.0, 0.0], "specular": 0.1, "diffuse": 0.2}
BAD = {
    "unknown shared key": (dict(feild_model="dipole"), "unknown key(s) feild_model"),
    "epoch naive": (dict(epoch="2026-12-21T00:00:00"), "epoch"),
    "epoch out of DE421": (dict(epoch="2060-01-01T00:00:00Z"), "epoch"),
    "tle checksum": (dict(orbit__line1="1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    08"),
                     "checksum"),
    "tle without epoch": (dict(epoch=..., field_model="dipole", zones=[],
                               environment={"gravity_gradient": True}),
        "expected an epoch (the Sun, Moon and Earth depend on the date) for orbit type tle"),
    "orbit type unknown": (dict(orbit={"type": "hyperbolic"}), "orbit.type"),
    "kepler key missing": (dict(orbit={"type": "kepler", "semi_major_axis_m": 7e6}), "orbit"),
    "field model unknown": (dict(field_model="wmm"), "field_model: expected 'dipole' or 'igrf14'; found 'wmm'"),
    "igrf14 beyond 2035": (dict(epoch="2040-01-01T00:00:00Z", orbit={"altitude_m": 5e5}, zones=[]), "field_model"),
    "orbit below 150 km": (dict(orbit={"type": "kepler", "semi_major_axis_m": 6.45e6, "eccentricity": 0.0,
                                       "inclination_deg": 50.0, "raan_deg": 0.0, "arg_perigee_deg": 0.0,
                                       "mean_anomaly_deg": 0.0}), "below the minimum"),
    "igrf14 without epoch": (dict(epoch=..., orbit={"altitude_m": 5e5}, zones=[],
                                  environment={"drag": False}),
        "expected an epoch (the Sun, Moon and Earth depend on the date) for field_model igrf14"),
    "environment typo": (dict(environment__gravity_gradiant=True), "unknown key(s) gravity_gradiant"),
    "environment flag text": (dict(environment__drag="yes"), "environment.drag: expected a valid boolean"),
    "residual dipole of 2": (dict(environment__residual_dipole_Am2=[1.0, 2.0]), "environment.residual_dipole"),
    "drag coefficient zero": (dict(environment__drag_coefficient=0.0), "environment.drag_coefficient"),
    "facet absorbs negatively": (dict(environment__facets=[dict(FACET, specular=0.9, diffuse=0.5)]),
                                 "environment.facets"),
    "facets not a list": (dict(environment__facets={"area": 1.0}), "environment.facets"),
    "pressure without facets": (dict(environment__facets=[]),
        "environment: expected facets (the surfaces solar_pressure acts on)"),
    "zone body unknown": (dict(zones=[{"name": "x", "body": "mars", "sensor_axis": [0, 1, 0],
                                       "half_angle_deg": 10.0}]), "zones[0].body"),
    "zone axis not unit": (dict(zones=[{"name": "x", "body": "sun", "sensor_axis": [0, 2, 0],
                                        "half_angle_deg": 10.0}]), "zones[0].sensor_axis"),
    "zone angle 180": (dict(zones=[{"name": "x", "body": "moon", "sensor_axis": [0, 1, 0],
                                    "half_angle_deg": 180.0}]),
        "zones[0]: expected half_angle_deg a cone half-angle in (0, 180) deg"),
    "negative limb margin": (dict(zones=[{"name": "x", "body": "earth_limb", "sensor_axis": [0, 1, 0],
                                          "half_angle_deg": -5.0}]),
        "zones[0]: expected half_angle_deg the margin beyond the Earth limb in [0, 90) deg"),
    "inertial zone without direction": (dict(zones=[{"name": "x", "body": "inertial", "sensor_axis": [0, 1, 0],
                                                     "half_angle_deg": 10.0}]),
        "zones[0]: expected direction (a unit inertial vector) for body inertial"),
    "direction on a sun zone": (dict(zones=[{"name": "x", "body": "sun", "sensor_axis": [0, 1, 0],
                                             "half_angle_deg": 10.0, "direction": [1, 0, 0]}]),
        "zones[0]: expected direction (a unit inertial vector) for body inertial, and only"),
    "zone typo": (dict(zones=[{"name": "x", "body": "sun", "sensor_axis": [0, 1, 0], "half_angle": 10.0}]),
        "zones[0].half_angle: expected one of the keys"),
    "zone keep_in text": (dict(zones=[{"name": "x", "body": "sun", "sensor_axis": [0, 1, 0], "half_angle_deg": 9,
                                       "keep_in": "no"}]), "zones[0].keep_in"),
    "duplicate zone names": (dict(zones=[{"name": "x", "body": "sun", "sensor_axis": [0, 1, 0], "half_angle_deg": 9},
                                         {"name": "x", "body": "moon", "sensor_axis": [0, 1, 0],
        "half_angle_deg": 9}]), "zones: expected distinct zone names, got 'x' twice"),
}


@pytest.mark.parametrize("changes, words", BAD.values(), ids=BAD.keys())
def test_bad_real_sky_keys_are_config_errors_naming_file_and_field(tmp_path, changes, words):
    with pytest.raises(ConfigError) as err:
        scenario.load(_file(tmp_path, **changes))
    assert err.value.code == ErrorCode.INVALID_CONFIG
    assert "sky_case.yaml" in err.value.message and words in err.value.message, err.value.message


def test_sun_and_moon_zones_need_an_epoch_and_earth_limb_does_not(tmp_path):
    base = dict(epoch=..., orbit={"altitude_m": 5e5}, field_model="dipole", environment={"gravity_gradient": True})
    zone = {"name": "x", "body": "sun", "sensor_axis": [0, 1, 0], "half_angle_deg": 30.0}
    with pytest.raises(ConfigError, match=r"expected an epoch \(the Sun, Moon and Earth depend on the "
                                          r"date\) for zone x \(body sun\)"):
        scenario.load(_file(tmp_path, **base, zones=[zone]))
    s = scenario.load(_file(tmp_path, **base, zones=[dict(zone, body="earth_limb", half_angle_deg=5.0),
                                                     dict(zone, name="y", body="inertial", direction=[0, 0, 1])]))
    assert [z.body for z in s.zones] == ["earth_limb", "inertial"] and s.zones[0].half_angle == math.radians(5.0)
    assert s.zones[1].direction.tolist() == [0.0, 0.0, 1.0] and s.environment["gravity_gradient"]
