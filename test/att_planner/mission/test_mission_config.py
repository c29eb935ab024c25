"""Mission files: the shipped day loads; every key of a hostile file is refused with the
file and the key named."""
import math

import numpy as np
import pytest

from att_msgs_py.errors import ConfigError, ErrorCode
from att_planner.mission import config as mc
from att_sim.models import rotations as rot

GOOD = {"targets": "observatory", "sensor_axis": [0.0, 1.0, 0.0], "horizon_s": 3600}


def write(tmp_path, text: str):
    path = tmp_path / "mission.yaml"
    path.write_text(text)
    return str(path)


def yaml_of(doc: dict) -> str:
    import yaml
    return yaml.safe_dump(doc)


def test_the_shipped_day_loads_with_its_targets_pointed():
    m = mc.load("observatory_day")
    assert m.horizon == 6 * 3600.0 and m.scenario.name == "leo_observatory" and m.momentum_dumping
    assert m.pointing_tolerance == pytest.approx(math.radians(0.05))
    targets = m.targets()
    assert len(targets) == 16 and [z.name for z in m.zones] == ["sun", "moon", "earth"]
    for target in targets.values():
        assert not target.moving and target.dwell > 0
        assert rot.dcm_NB(target.attitude) @ m.sensor_axis == pytest.approx(target.direction, abs=1e-12)


def test_the_shipped_earth_observation_day_tracks_its_sites_without_the_payload_earth_zone():
    m = mc.load("earth_observation_day")
    assert [z.name for z in m.zones] == ["sun", "moon"] and m.secondary == "velocity"
    assert m.site_arrival == "at_rest" and m.handover_blend == 180.0
    targets = m.targets()
    assert len(targets) == 10 and all(t.moving for t in targets.values())
    singapore = targets["singapore"]
    t = np.array([6700.0, 6800.0])
    q = singapore.attitudes(t)
    for k in range(2):                           # the sensor on the line of sight, body +z nearest the velocity
        assert rot.dcm_NB(q[k]) @ m.sensor_axis == pytest.approx(singapore.direction_at(t[k]), abs=1e-9)
    assert singapore.track.mode.kind == "ground" and singapore.track.mode.latitude == pytest.approx(math.radians(1.35))


def test_the_shipped_aeos_orbit_starts_on_the_nadir_with_its_trackers_clear():
    m = mc.load("aeos_orbit")
    assert m.scenario.name == "aeos" and m.start_pointing == "nadir" and len(m.zones) == 6
    assert m.target_list.min_elevation == pytest.approx(math.radians(58.0))
    from att_planner.mission.executive import MissionExecutive
    from att_sim.models import world
    q0 = m.start_attitude()
    r = np.asarray(world.Environment.from_scenario(m.scenario).orbit.position(0.0), float).reshape(3)
    boresight = rot.dcm_NB(q0) @ m.sensor_axis
    assert np.degrees(np.arccos(boresight @ -r / np.linalg.norm(r))) < 0.2      # geodetic nadir, not geocentric
    executive = MissionExecutive.of_mission(m, 20.0, converged=True)
    assert executive.scheduler.clear(q0, 0.0, m.start_lead)                    # a slew can start from it


def test_defaults_fill_what_a_file_leaves_out(tmp_path):
    m = mc.load(write(tmp_path, yaml_of(GOOD)))
    assert (m.rate, m.start_lead, m.method, m.margin) == (5.0, 240.0, "", pytest.approx(math.radians(1.0)))
    assert np.array_equal(m.sensor_axis, [0.0, 1.0, 0.0])
    assert m.start_pointing == "scenario" and m.start_attitude() is None


@pytest.mark.parametrize("change, field", [
    ({"horizon_s": None}, "horizon_s"), ({"horizon_s": 10}, "horizon_s"), ({"horizon_s": True}, "horizon_s"),
    ({"horizon_s": float("nan")}, "horizon_s"), ({"rate_Hz": 0}, "rate_Hz"), ({"rate_Hz": "5"}, "rate_Hz"),
    ({"margin_deg": -1}, "margin_deg"), ({"start_lead_s": 1e9}, "start_lead_s"),
    ({"time_budget_s": 0}, "time_budget_s"), ({"pointing_tolerance_deg": float("inf")}, "pointing_tolerance_deg"),
    ({"sensor_axis": [0, 2, 0]}, "sensor_axis"), ({"sensor_axis": [0, 1]}, "sensor_axis"),
    ({"sensor_axis": "y"}, "sensor_axis"), ({"sensor_axis": [0, True, 0]}, "sensor_axis"),
    ({"targets": 3}, "targets"), ({"targets": "no_such_list"}, "unknown target list"),
    ({"method": "a\nb"}, "method"), ({"zones": ["sun", "pluto"]}, "zones"), ({"zones": ["sun", "sun"]}, "zones"),
    ({"zones": "sun"}, "zones"), ({"secondary": "up"}, "secondary"), ({"secondary": "inertial"}, "secondary"),
    ({"secondary_axis": [0, 1, 0]}, "parallel to sensor_axis"), ({"secondary_axis": [1, 1, 0]}, "secondary_axis"),
    ({"handover_blend_s": -1}, "handover_blend_s"), ({"handover_blend_s": "long"}, "handover_blend_s"),
    ({"momentum_dumping": "yes"}, "momentum_dumping"), ({"colour": "red"}, "unknown key(s) colour"),
    ({"rate_max_deg_per_s": 0}, "rate_max_deg_per_s"), ({"rate_max_deg_per_s": "fast"}, "rate_max_deg_per_s"),
    ({"start_pointing": "zenith"}, "start_pointing"), ({"start_pointing": 1}, "start_pointing"),
    ({"start_pointing": ["nadir"]}, "start_pointing"), ({"method": "warp_drive"}, "method: one of"),
    ({"site_arrival": "blended"}, "site_arrival"), ({"site_arrival": True}, "site_arrival"),
    ({"method": "graph_smooth", "rate_max_deg_per_s": 3.0}, "method graph_smooth takes no rate bound"),
])
def test_a_bad_key_is_refused_with_the_file_and_the_key_named(tmp_path, change, field):
    doc = {**GOOD, **change}
    doc = {k: v for k, v in doc.items() if v is not None}
    path = write(tmp_path, yaml_of(doc))
    with pytest.raises(ConfigError) as err:
        mc.load(path)
    assert err.value.code == ErrorCode.INVALID_CONFIG
    assert path in str(err.value) and field in str(err.value)


@pytest.mark.parametrize("method", ["eigenaxis", "mssa", "constrained_axis"])
def test_a_ground_mission_whose_method_plans_rest_to_rest_only_is_refused(tmp_path, method):
    """Every slew to a site ends on the site's law: a method that cannot is refused when the file loads,
    not at each slew of the day; an end-pointing method and the planner's default load."""
    ground = {"targets": "earth_observation", "sensor_axis": [0.0, 1.0, 0.0], "horizon_s": 3600}
    path = write(tmp_path, yaml_of({**ground, "method": method}))
    with pytest.raises(ConfigError, match=f"method {method}: site_arrival on_law ends each slew") as err:
        mc.load(path)
    assert err.value.code == ErrorCode.INVALID_CONFIG and path in str(err.value)
    for fine in ("time_optimal", ""):
        assert mc.load(write(tmp_path, yaml_of({**ground, "method": fine}))).site_arrival == "on_law"
    at_rest = mc.load(write(tmp_path, yaml_of({**ground, "method": method, "site_arrival": "at_rest"})))
    assert at_rest.method == method and at_rest.site_arrival == "at_rest"
    assert mc.load(write(tmp_path, yaml_of({**GOOD, "method": method}))).method == method     # sources: any


def test_strips_scanned_from_a_rest_arrival_are_refused(tmp_path):
    """A strip is scanned from the slew's arrival, on its law: site_arrival at_rest is refused naming
    the strips; the shipped orbit (on_law) loads them."""
    path = write(tmp_path, yaml_of({"targets": "aeos_orbit", "sensor_axis": [0.0, 0.0, 1.0], "horizon_s": 600,
                                    "site_arrival": "at_rest"}))
    with pytest.raises(ConfigError, match=r"site_arrival at_rest: the target list's strips \(rio_grande, kashgar\)") \
            as err:
        mc.load(path)
    assert err.value.code == ErrorCode.INVALID_CONFIG
    assert {n for n, t in mc.load("aeos_orbit").targets().items() if t.track.mode_at(0.0).kind == "strip"} == \
        {"rio_grande", "kashgar"}


@pytest.mark.parametrize("text", ["", "[1, 2]", "just a string", "targets: [unclosed"])
def test_a_file_that_is_not_a_mapping_is_refused(tmp_path, text):
    with pytest.raises(ConfigError):
        mc.load(write(tmp_path, text))


def test_an_unknown_mission_names_the_known_ones():
    with pytest.raises(KeyError, match="observatory_day"):
        mc.find("no_such_mission")


def test_the_default_rate_bound_keeps_the_gyroscopic_torque_within_the_wheels_margin():
    m = mc.load("observatory_day")
    sc = m.scenario.spacecraft
    a = mc.gyroscopic_rate_limit(sc)
    assert m.rate_max == a and 0.0 < a < 0.01
    J = np.asarray(sc.inertia, float)
    omega = np.random.default_rng(3).uniform(-a, a, (20_000, 3))
    omega[:4] = [[a, a, a], [a, -a, a], [-a, a, a], [a, a, -a]]       # the corners bound it
    gyroscopic = np.abs(np.cross(omega, omega @ J.T)).max()
    margin = sc.wheel_torque_max - sc.body_torque_max
    assert gyroscopic <= mc.GYROSCOPIC_SHARE * margin + 1e-12
    assert gyroscopic >= 0.9 * mc.GYROSCOPIC_SHARE * margin               # and it is not needlessly slow
    spherical = type("Sc", (), {"inertia": np.eye(3) * 10.0, "wheel_torque_max": 0.3, "body_torque_max": 0.25})
    assert mc.gyroscopic_rate_limit(spherical) == math.inf
