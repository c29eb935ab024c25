"""Target lists: the shipped observatory and Earth-observation lists, the attitude that
points the sensor at a source, and hostile files refused with the file, target and field named."""
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.errors import ConfigError, ErrorCode
from att_planner.methods.schedule.order_search import visibility
from att_planner.mission import targets as tl
from att_planner.tools.bench import sky
from att_sim.models import rotations as rot


def test_the_shipped_lists_load():
    observatory = tl.load("observatory")
    assert observatory.kind == "inertial" and observatory.scenario == "leo_observatory"
    assert 10 <= len(observatory.targets) <= 20
    for source in observatory.targets:
        assert np.linalg.norm(source.direction) == pytest.approx(1.0) and source.dwell > 0
    ground = tl.load("earth_observation")
    assert ground.kind == "ground" and len(ground.targets) == 10
    assert ground.min_elevation == pytest.approx(np.deg2rad(30.0))
    toulouse = next(s for s in ground.targets if s.name == "toulouse")
    assert (np.rad2deg(toulouse.latitude), np.rad2deg(toulouse.longitude)) == pytest.approx((43.604, 1.444))


@pytest.mark.parametrize("sensor", [[0, 1, 0], [1, 0, 0], [0, 0, 1], [0.6, 0.8, 0]])
def test_the_attitude_points_the_sensor_and_keeps_the_roll_axis_nearest_the_reference(sensor):
    rng = np.random.default_rng(7)
    sensor = np.asarray(sensor, float) / np.linalg.norm(sensor)
    for d in rng.normal(size=(50, 3)):
        d /= np.linalg.norm(d)
        R = rot.dcm_NB(tl.pointing_attitude(sensor, d))
        assert R @ sensor == pytest.approx(d, abs=1e-12)
        # the roll axis is the unit vector ⟂ d nearest north: its north component is |north ⟂ d|
        r_body = np.roll(np.eye(3), 1, axis=0)[int(np.argmax(np.abs(sensor)))]
        r_body = r_body - (r_body @ sensor) * sensor
        roll = R @ (r_body / np.linalg.norm(r_body))
        assert roll[2] == pytest.approx(np.sqrt(1.0 - d[2] ** 2), abs=1e-9)


def test_sources_beside_the_sun_and_the_moon_are_never_visible_and_the_others_are():
    _, problem = sky.case_problem("leo_observatory")
    sources = {s.name: s for s in tl.load("observatory").targets}
    problem = replace(problem, targets={k: tl.pointing_attitude(problem.sensor_axis, s.direction)
                                        for k, s in sources.items()})
    zones = problem.zone_sky(6 * 3600.0)
    seen = {k: visibility(zones, q, (0.0, np.inf)) for k, q in problem.targets.items()}
    # Sgr A* 6° from the Sun (zone 47°), the Pleiades 11-15° from the Moon (zone 23°) all day
    assert {k for k, v in seen.items() if not v} == {"sgr_a_star", "pleiades"}
    sun, moon = zones.true_axes(np.array([0.0]))[0][:2]
    assert np.degrees(np.arccos(sun @ sources["sgr_a_star"].direction)) < 47.0
    assert np.degrees(np.arccos(moon @ sources["pleiades"].direction)) < 23.0
    # the Earth limb covers some sources for part of every orbit: their visible spans are broken
    assert any(len(v) > 1 for v in seen.values())


GOOD = {"kind": "inertial", "scenario": "leo_observatory",
        "targets": [{"name": "a", "ra_deg": 10.0, "dec_deg": 20.0, "dwell_s": 60.0}]}
HOSTILE = {
    "kind unknown": ({"kind": "galactic"}, "kind: expected 'inertial' or 'ground'; found 'galactic'"),
    "unknown file key": ({"colour": 1}, "colour: expected one of the keys"),
    "unknown scenario": ({"scenario": "nowhere"}, "scenario: expected the name of a scenario; found 'nowhere'"),
    "no targets": ({"targets": []}, "targets: expected List should have at least 1 item"),
    "21 targets": ({"targets": [{"name": f"t{i}", "ra_deg": i, "dec_deg": 0, "dwell_s": 1} for i in range(21)]},
        "targets: expected List should have at most 20 items"),
    "target not a mapping": ({"targets": [5]}, "targets[0]: expected a valid dictionary"),
    "typo in a target": ({"targets": [{"name": "a", "ra_deg": 1, "dec": 2, "dwell_s": 1}]},
        "targets[0].dec: expected one of the keys"),
    "missing dwell": ({"targets": [{"name": "a", "ra_deg": 1, "dec_deg": 2}]},
        "targets[0].dwell_s: expected this key (required)"),
    "dec 95": ({"targets": [{"name": "a", "ra_deg": 1, "dec_deg": 95, "dwell_s": 1}]},
        "targets[0].dec_deg: expected less than or equal to 90; found 95"),
    "dwell nan": ({"targets": [{"name": "a", "ra_deg": 1, "dec_deg": 2, "dwell_s": float("nan")}]},
        "targets[0].dwell_s: expected less than or equal to 86400; found nan"),
    "dwell negative": ({"targets": [{"name": "a", "ra_deg": 1, "dec_deg": 2, "dwell_s": -5}]},
        "targets[0].dwell_s: expected greater than or equal to 0; found -5"),
    "ra as text": ({"targets": [{"name": "a", "ra_deg": "ten", "dec_deg": 2, "dwell_s": 1}]},
        "targets[0].ra_deg: expected a valid number; found 'ten'"),
    "ra true": ({"targets": [{"name": "a", "ra_deg": True, "dec_deg": 2, "dwell_s": 1}]},
        "targets[0].ra_deg: expected a valid number; found True"),
    "name with a control": ({"targets": [{"name": "a\x01", "ra_deg": 1, "dec_deg": 2, "dwell_s": 1}]},
        "targets[0].name: expected a printable name"),
    "names repeat": ({"targets": [{"name": "a", "ra_deg": 1, "dec_deg": 2, "dwell_s": 1}] * 2},
        "targets: expected distinct target names, got 'a' twice"),
    "roll reference zero": ({"roll_reference": [0, 0, 0]}, "roll_reference: expected a non-zero 3-vector"),
    "ground site at latitude 100": ({"kind": "ground", "targets": [{"name": "x", "lat_deg": 100, "lon_deg": 0,
                                                                    "dwell_s": 1}]},
        "targets[0].lat_deg: expected less than or equal to 90; found 100"),
    "ground elevation 90": ({"kind": "ground", "min_elevation_deg": 90, "targets": [
        {"name": "x", "lat_deg": 0, "lon_deg": 0, "dwell_s": 1}]},
        "min_elevation_deg: expected less than or equal to 89; found 90"),
    "ground site without a dwell": ({"kind": "ground", "targets": [{"name": "x", "lat_deg": 0, "lon_deg": 0}]},
        "dwell_s: a site's time tracked (or end_lat_deg, end_lon_deg and scan_speed_m_s: a strip)"),
    "strip without a speed": ({"kind": "ground", "targets": [{"name": "s", "lat_deg": 0, "lon_deg": 0, "end_lat_deg": 1,
                                                              "end_lon_deg": 0}]},
        "a strip needs end_lat_deg, end_lon_deg and scan_speed_m_s, all three"),
    "strip with a dwell": ({"kind": "ground", "targets": [{"name": "s", "lat_deg": 0, "lon_deg": 0, "end_lat_deg": 1,
                                                           "end_lon_deg": 0, "scan_speed_m_s": 7000, "dwell_s": 5}]},
        "dwell_s: a strip's dwell is its scan"),
    "strip speed zero": ({"kind": "ground", "targets": [{"name": "s", "lat_deg": 0, "lon_deg": 0, "end_lat_deg": 1,
                                                         "end_lon_deg": 0, "scan_speed_m_s": 0}]},
        "targets[0].scan_speed_m_s: expected greater than 0; found 0"),
    "strip speed nan": ({"kind": "ground", "targets": [{"name": "s", "lat_deg": 0, "lon_deg": 0, "end_lat_deg": 1,
                                                        "end_lon_deg": 0, "scan_speed_m_s": float("nan")}]},
        "targets[0].scan_speed_m_s"),
    "strip end latitude 91": ({"kind": "ground", "targets": [{"name": "s", "lat_deg": 0, "lon_deg": 0,
                                                              "end_lat_deg": 91, "end_lon_deg": 0,
                                                              "scan_speed_m_s": 7}]},
        "targets[0].end_lat_deg: expected less than or equal to 90; found 91"),
    "strip ending at its start": ({"kind": "ground", "targets": [{"name": "s", "lat_deg": 10, "lon_deg": 20,
                                                                  "end_lat_deg": 10, "end_lon_deg": 20,
                                                                  "scan_speed_m_s": 7000}]},
        "targets[0] (s): the end is the start"),
    "strip longer than a pass": ({"kind": "ground", "targets": [{"name": "s", "lat_deg": 0, "lon_deg": 0,
                                                                 "end_lat_deg": 0, "end_lon_deg": 30,
                                                                 "scan_speed_m_s": 7000}]},
        "targets[0] (s): "),
}


def test_a_strip_loads_with_its_scan_as_its_dwell():
    """A strip's dwell is its length at its scan speed, the length recomputed here on the sphere of the
    mean radius (within 0.5 % of the ellipsoid's over 100 km)."""
    import math

    from att_planner.mission import config as mc

    m = mc.load("aeos_orbit")
    (strip,) = [t for t in m.target_list.targets if t.name == "rio_grande"]
    assert strip.strip is not None and strip.dwell == pytest.approx(strip.strip.length_m / 7000.0)
    lat0, lon0, lat1, lon1 = (math.radians(v) for v in (31.76, -106.49, 32.6, -106.8))
    arc = math.acos(math.sin(lat0) * math.sin(lat1) + math.cos(lat0) * math.cos(lat1) * math.cos(lon1 - lon0))
    assert strip.strip.length_m == pytest.approx(6_371_000.0 * arc, rel=5e-3)
    assert (strip.latitude, strip.longitude) == (pytest.approx(lat0), pytest.approx(lon0))
    target = m.targets()["rio_grande"]
    assert target.moving and target.dwell == strip.dwell
    mode = target.track.mode_at(500.0)
    assert mode.kind == "strip" and mode.scan_start == 500.0 and mode.scan_speed == 7000.0
    assert (mode.end_latitude, mode.end_longitude) == (pytest.approx(lat1, abs=1e-9), pytest.approx(lon1, abs=1e-9))


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_a_hostile_target_list_is_refused_naming_the_field(tmp_path, name):
    import yaml
    changes, words = HOSTILE[name]
    path = tmp_path / "list.yaml"
    path.write_text(yaml.safe_dump({**GOOD, **changes}))
    with pytest.raises(ConfigError) as err:
        tl.load(str(path))
    assert err.value.code == ErrorCode.INVALID_CONFIG and words in err.value.message, err.value.message
    assert str(path) in err.value.message


def test_unknown_list_and_unreadable_file(tmp_path):
    with pytest.raises(KeyError, match="unknown target list 'nowhere'.*observatory"):
        tl.load("nowhere")
    path = tmp_path / "broken.yaml"
    path.write_text("kind: [inertial\n")
    with pytest.raises(ConfigError, match=r"broken.yaml:2: \(file\): expected valid YAML"):
        tl.load(str(path))
