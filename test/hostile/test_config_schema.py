"""Hostile configuration files: each refused by ``att-config check`` with its file, line and field.

Every case is a file written in ``tmp_path`` — a valid file of its kind with one thing made wrong
(a type, a unit, an unknown or old key, NaN, a non-physical inertia, a missing spacecraft, a YAML
alias bomb, a 10 MB file...) — and must come back as problems naming that file, the line of the
wrong value and its field path, with what was expected; nothing may crash or pass.
"""
from __future__ import annotations

import pytest

from att_planner.tools import config_cli

P = "/**.ros__parameters"
SCENARIO = """\
/**:
  ros__parameters:
    frame_id: eci
    spacecraft:
      inertia_kg_m2: [100.0, 100.0, 120.0]
      torque_max_Nm: 0.1
      wheel_axes: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
      wheel_inertia_kg_m2: 0.01
    orbit:
      altitude_m: 450000.0
    field_model: dipole
    environment:
      solar_pressure: false
      facets:
        - {area_m2: 1.0, normal: [1.0, 0.0, 0.0], center_m: [0.1, 0.0, 0.0], specular: 0.3, diffuse: 0.3}
    zones:
      - {name: keep, body: inertial, sensor_axis: [1.0, 0.0, 0.0], half_angle_deg: 20.0, direction: [0.0, 0.0, 1.0]}
      - {name: other, body: inertial, sensor_axis: [0.0, 1.0, 0.0], half_angle_deg: 10.0, direction: [1.0, 0.0, 0.0]}
    sensors:
      seed: 3
      gyro: {rate_Hz: 20.0, arw_deg_per_sqrt_h: 0.005}
      star_trackers:
        - {name: st1, mounting: [0.0, 0.0, 0.0, 1.0]}
        - {name: st2, mounting: [0.0, 0.0, 0.0, 1.0]}
      magnetometer: {noise_nT: 50.0}
    actuators:
      wheels: {coulomb_friction_Nm: 0.002}
    allow_fault_injection: true
    faults:
      - {t_s: 10.0, component: wheel, index: 2, kind: seized}
      - {t_s: 20.0, component: gyro, index: 1, kind: bias_step, bias_rad_s: 0.001}
simulator:
  ros__parameters:
    step: 0.05
"""
MISSION = """\
targets: observatory
sensor_axis: [0.0, 1.0, 0.0]
horizon_s: 3600
rate_Hz: 5.0
"""
TARGETS = """\
kind: inertial
scenario: leo_observatory
targets:
  - {name: crab, ra_deg: 83.6, dec_deg: 22.0, dwell_s: 600}
  - {name: vega, ra_deg: 279.2, dec_deg: 38.8, dwell_s: 300}
"""
CAMPAIGN = """\
campaign:
  scenario: swift_demo
  seed: 16
  runs: 10
  converge_timeout_s: 30.0
  dispersions:
    inertia_scale: {distribution: normal, three_sigma: 0.05, truncate: 3}
    com_offset_m: {distribution: uniform, low: -0.01, high: 0.01}
"""
BASES = {"scenario": SCENARIO, "mission": MISSION, "targets": TARGETS, "campaign": CAMPAIGN}
SC = f"{P}.spacecraft"

# name: (kind, text replaced, its replacement, field path of the problem, words of what was expected)
EDITS = {
    # the spacecraft: types, units, physics, old and unknown keys
    "inertia a word": ("scenario", "[100.0, 100.0, 120.0]", "heavy", f"{SC}.inertia_kg_m2", "valid list"),
    "inertia negative": ("scenario", "[100.0, 100.0, 120.0]", "[-100.0, 100.0, 120.0]", f"{SC}.inertia_kg_m2",
                         "positive definite"),
    "inertia non-physical": ("scenario", "[100.0, 100.0, 120.0]", "[10.0, 10.0, 30.0]", f"{SC}.inertia_kg_m2",
                             "triangle inequality"),
    "inertia not symmetric": ("scenario", "[100.0, 100.0, 120.0]", "[100, 5, 0, 0, 100, 0, 0, 0, 120]",
                              f"{SC}.inertia_kg_m2", "symmetric"),
    "inertia NaN": ("scenario", "[100.0, 100.0, 120.0]", "[.nan, 100.0, 120.0]", f"{SC}.inertia_kg_m2[0]", "finite"),
    "inertia infinite": ("scenario", "[100.0, 100.0, 120.0]", "[.inf, 100.0, 120.0]", f"{SC}.inertia_kg_m2[0]",
                         "finite"),
    "inertia four numbers": ("scenario", "[100.0, 100.0, 120.0]", "[1.0, 1.0, 1.0, 1.0]", f"{SC}.inertia_kg_m2",
                             "3 principal or 9"),
    "inertia old name": ("scenario", "inertia_kg_m2:", "inertia:", f"{SC}.inertia", "renamed to 'inertia_kg_m2'"),
    "torque old name": ("scenario", "torque_max_Nm:", "torque_max:", f"{SC}.torque_max", "renamed to 'torque_max_Nm'"),
    "torque unknown key": ("scenario", "torque_max_Nm:", "torque_maximum_Nm:", f"{SC}.torque_maximum_Nm",
                           "did you mean 'torque_max_Nm'"),
    "torque negative": ("scenario", "torque_max_Nm: 0.1", "torque_max_Nm: -0.1", f"{SC}.torque_max_Nm",
                        "greater than 0"),
    "torque NaN": ("scenario", "torque_max_Nm: 0.1", "torque_max_Nm: .nan", f"{SC}.torque_max_Nm", "greater than 0"),
    "torque a string": ("scenario", "torque_max_Nm: 0.1", "torque_max_Nm: '0.1'", f"{SC}.torque_max_Nm",
                        "valid number"),
    "torque a flag": ("scenario", "torque_max_Nm: 0.1", "torque_max_Nm: true", f"{SC}.torque_max_Nm", "valid number"),
    "torque with a unit": ("scenario", "torque_max_Nm: 0.1", "torque_max_Nm: 0.1 Nm", f"{SC}.torque_max_Nm",
                           "valid number"),
    "torque in mN m": ("scenario", "torque_max_Nm:", "torque_max_mNm:", f"{SC}.torque_max_mNm", "torque_max_Nm"),
    "wheel axis not unit": ("scenario", "0.0, 1.0, 0.0, 0.0, 0.0, 1.0]", "0.0, 2.0, 0.0, 0.0, 0.0, 1.0]",
                            f"{SC}.wheel_axes", "vector 1 has norm 2"),
    "wheel axes not triples": ("scenario", "0.0, 0.0, 1.0]\n", "0.0, 0.0]\n", f"{SC}.wheel_axes", "3 numbers"),
    "wheels without inertia": ("scenario", "wheel_inertia_kg_m2: 0.01", "wheel_inertia_kg_m2: 0.0", SC,
                               "wheel_inertia_kg_m2 > 0"),
    "missing spacecraft": ("scenario", "    spacecraft:\n      inertia_kg_m2: [100.0, 100.0, 120.0]\n      "
                           "torque_max_Nm: 0.1\n      wheel_axes: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
                           "      wheel_inertia_kg_m2: 0.01\n", "", f"{P}.spacecraft", "required"),
    "missing shared section": ("scenario", "/**:\n  ros__parameters:\n    frame_id: eci\n",
                               "craft:\n  ros__parameters:\n    frame_id: eci\n", "/**", "required"),
    "empty frame name": ("scenario", "frame_id: eci", "frame_id: ''", f"{P}.frame_id", "at least 1 character"),
    # the sky
    "altitude zero": ("scenario", "altitude_m: 450000.0", "altitude_m: 0", f"{P}.orbit.altitude_m", "greater than 0"),
    "altitude old name": ("scenario", "altitude_m:", "altitude:", f"{P}.orbit.altitude", "renamed to 'altitude_m'"),
    "altitude in km": ("scenario", "altitude_m:", "altitude_km:", f"{P}.orbit.altitude_km", "altitude_m"),
    "orbit type unknown": ("scenario", "altitude_m: 450000.0", "type: elliptic", f"{P}.orbit.type",
                           "'circular', 'kepler', 'tle'"),
    "kepler without epoch": ("scenario", "altitude_m: 450000.0", "type: kepler\n      semi_major_axis_m: 7.0e6\n"
                             "      eccentricity: 0.0\n      inclination_deg: 98.0\n      raan_deg: 0.0\n"
                             "      arg_perigee_deg: 0.0\n      mean_anomaly_deg: 0.0", P, "an epoch"),
    "kepler eccentricity": ("scenario", "altitude_m: 450000.0", "type: kepler\n      semi_major_axis_m: 7.0e6\n"
                            "      eccentricity: 1.2\n      inclination_deg: 98.0\n      raan_deg: 0.0\n"
                            "      arg_perigee_deg: 0.0\n      mean_anomaly_deg: 0.0", f"{P}.orbit.eccentricity",
                            "less than 1"),
    "epoch naive": ("scenario", "field_model: dipole", "epoch: '2026-12-21T00:00:00'", f"{P}.epoch", "'Z' or a UTC"),
    "epoch too early": ("scenario", "field_model: dipole", "epoch: '1800-01-01T00:00:00Z'", f"{P}.epoch", "ISO 8601"),
    "field model unknown": ("scenario", "field_model: dipole", "field_model: igrf99", f"{P}.field_model", "igrf14"),
    "zone body unknown": ("scenario", "name: keep, body: inertial", "name: keep, body: jupiter", f"{P}.zones[0].body",
                          "'inertial'"),
    "zone half-angle 200": ("scenario", "half_angle_deg: 20.0", "half_angle_deg: 200.0", f"{P}.zones[0]",
                            "(0, 180)"),
    "zone axis zero": ("scenario", "sensor_axis: [1.0, 0.0, 0.0], half_angle_deg: 20.0",
                       "sensor_axis: [0.0, 0.0, 0.0], half_angle_deg: 20.0", f"{P}.zones[0].sensor_axis",
                       "unit vector"),
    "zone names repeated": ("scenario", "name: other", "name: keep", f"{P}.zones", "distinct zone names"),
    "zone sun with a direction": ("scenario", "name: keep, body: inertial", "name: keep, body: sun",
                                  f"{P}.zones[0]", "direction"),
    "zone sun without epoch": ("scenario", "body: inertial, sensor_axis: [1.0, 0.0, 0.0], half_angle_deg: 20.0, "
                               "direction: [0.0, 0.0, 1.0]}", "body: sun, sensor_axis: [1.0, 0.0, 0.0], "
                               "half_angle_deg: 20.0}", P, "an epoch"),
    "facet reflects over 1": ("scenario", "specular: 0.3, diffuse: 0.3", "specular: 0.7, diffuse: 0.7",
                              f"{P}.environment.facets[0]", "at most 1"),
    "facet old key": ("scenario", "{area_m2:", "{area:", f"{P}.environment.facets[0].area", "renamed to 'area_m2'"),
    "pressure without epoch": ("scenario", "solar_pressure: false", "solar_pressure: true", P, "an epoch"),
    # faults: kind, index against the hardware, time, parameters
    "fault kind unknown": ("scenario", "kind: seized}", "kind: jammed}", f"{P}.faults[0]",
                           "kind one of seized, off, friction, tachometer_stuck for a wheel, got 'jammed'"),
    "fault component unknown": ("scenario", "component: wheel", "component: thruster", f"{P}.faults[0].component",
                                "'wheel'"),
    "fault wheel beyond the wheels": ("scenario", "index: 2, kind: seized", "index: 3, kind: seized", P,
                                      "faults[0].index below 3 (the spacecraft has 3 wheels), got 3"),
    "fault gyro axis 3": ("scenario", "index: 1, kind: bias_step", "index: 3, kind: bias_step", P,
                          "faults[1].index below 3 (the spacecraft has 3 gyro axes)"),
    "fault tracker beyond the trackers": ("scenario", "component: wheel, index: 2, kind: seized",
                                          "component: star_tracker, index: 2, kind: outage", P,
                                          "faults[0].index below 2 (the spacecraft has 2 star trackers), got 2"),
    "fault index negative": ("scenario", "index: 2, kind: seized", "index: -1, kind: seized",
                             f"{P}.faults[0].index", "greater than or equal to 0"),
    "fault time negative": ("scenario", "t_s: 10.0", "t_s: -1.0", f"{P}.faults[0].t_s",
                            "greater than or equal to 0"),
    "fault time NaN": ("scenario", "t_s: 10.0", "t_s: .nan", f"{P}.faults[0].t_s", "finite"),
    "fault parameter of another kind": ("scenario", "kind: seized}", "kind: seized, factor: 2.0}", f"{P}.faults[0]",
                                        "factor none for a seized fault (it takes no parameter), got 2.0"),
    "fault bias step missing": ("scenario", "kind: bias_step, bias_rad_s: 0.001", "kind: bias_step",
                                f"{P}.faults[1]", "bias_rad_s a value for a bias_step fault, got none"),
    "fault bias step NaN": ("scenario", "bias_rad_s: 0.001", "bias_rad_s: .nan", f"{P}.faults[1].bias_rad_s",
                            "finite"),
    "fault friction factor zero": ("scenario", "kind: seized}", "kind: friction, factor: 0.0}", f"{P}.faults[0]",
                                   "factor a friction multiplier in (0, 1000], got 0.0"),
    "fault tachometer missing": ("scenario", "kind: seized}", "kind: tachometer_stuck}", P,
                                 "tachometer_stuck fault, got no wheels with a tachometer"),
    "fault injection a word": ("scenario", "allow_fault_injection: true", "allow_fault_injection: maybe",
                               f"{P}.allow_fault_injection", "valid boolean"),
    # sensors and actuators
    "gyro rate zero": ("scenario", "rate_Hz: 20.0, arw", "rate_Hz: 0.0, arw", f"{P}.sensors.gyro.rate_Hz",
                       "greater than 0"),
    "gyro rate old name": ("scenario", "rate_Hz: 20.0, arw", "rate_hz: 20.0, arw", f"{P}.sensors.gyro.rate_hz",
                           "renamed to 'rate_Hz'"),
    "gyro unit missing": ("scenario", "arw_deg_per_sqrt_h:", "arw:", f"{P}.sensors.gyro.arw", "arw_deg_per_sqrt_h"),
    "tracker quaternion": ("scenario", "{name: st1, mounting: [0.0, 0.0, 0.0, 1.0]}",
                           "{name: st1, mounting: [0.0, 0.0, 0.0, 2.0]}", f"{P}.sensors.star_trackers[0].mounting",
                           "unit vector"),
    "tracker names repeated": ("scenario", "name: st2", "name: st1", f"{P}.sensors.star_trackers",
                               "distinct star tracker names"),
    "magnetometer noise negative": ("scenario", "noise_nT: 50.0", "noise_nT: -50.0",
                                    f"{P}.sensors.magnetometer.noise_nT", "greater than or equal to 0"),
    "seed negative": ("scenario", "seed: 3", "seed: -3", f"{P}.sensors.seed", "greater than or equal to 0"),
    "friction too large": ("scenario", "coulomb_friction_Nm: 0.002", "coulomb_friction_Nm: 11",
                           f"{P}.actuators.wheels.coulomb_friction_Nm", "less than or equal to 10"),
    "node section a number": ("scenario", "simulator:\n  ros__parameters:\n    step: 0.05\n", "simulator: 3\n",
                              "simulator", "valid dictionary"),
    # missions
    "mission axis not unit": ("mission", "[0.0, 1.0, 0.0]", "[0.0, 1.5, 0.0]", "sensor_axis", "unit 3-vector"),
    "mission horizon missing": ("mission", "horizon_s: 3600\n", "", "horizon_s", "required"),
    "mission horizon in hours": ("mission", "horizon_s: 3600", "horizon_h: 1", "horizon_h", "horizon_s"),
    "mission rate a word": ("mission", "rate_Hz: 5.0", "rate_Hz: fast", "rate_Hz", "valid number"),
    "mission rate old name": ("mission", "rate_Hz: 5.0", "rate_hz: 5.0", "rate_hz", "renamed to 'rate_Hz'"),
    "mission unknown targets": ("mission", "targets: observatory", "targets: nowhere", "targets",
                                "the name of a target list"),
    # target lists
    "targets kind unknown": ("targets", "kind: inertial", "kind: sky", "kind", "'inertial' or 'ground'"),
    "target ra 400": ("targets", "ra_deg: 83.6", "ra_deg: 400", "targets[0].ra_deg", "less than or equal to 360"),
    "target names repeated": ("targets", "name: vega", "name: crab", "targets", "distinct names"),
    "target dwell in minutes": ("targets", "dwell_s: 600", "dwell_min: 10", "targets[0].dwell_min", "dwell_s"),
    "targets unknown scenario": ("targets", "scenario: leo_observatory", "scenario: nowhere", "scenario",
                                 "the name of a scenario"),
    # campaigns
    "campaign old key": ("campaign", "converge_timeout_s:", "converge_timeout:", "campaign.converge_timeout",
                         "renamed to 'converge_timeout_s'"),
    "campaign unknown dispersion": ("campaign", "com_offset_m:", "com_offset_mm:", "campaign.dispersions.com_offset_mm",
                                    "com_offset_m"),
    "campaign two sigmas": ("campaign", "three_sigma: 0.05,", "three_sigma: 0.05, sigma: 0.1,",
                            "campaign.dispersions.inertia_scale", "exactly one of sigma"),
    "campaign uniform reversed": ("campaign", "low: -0.01, high: 0.01", "low: 0.01, high: -0.01",
                                  "campaign.dispersions.com_offset_m", "low below high"),
    "campaign distribution unknown": ("campaign", "distribution: uniform", "distribution: cauchy",
                                      "campaign.dispersions.com_offset_m.distribution", "'normal', 'uniform'"),
    "campaign seed fractional": ("campaign", "seed: 16", "seed: 1.5", "campaign.seed", "valid integer"),
    "campaign runs zero": ("campaign", "runs: 10", "runs: 0", "campaign.runs", "greater than or equal to 1"),
    "campaign unknown scenario": ("campaign", "scenario: swift_demo", "scenario: nowhere", "campaign.scenario",
                                  "the name of a scenario"),
}


@pytest.mark.parametrize("name", sorted(EDITS))
def test_hostile_edit_refused_with_file_line_and_field(name, tmp_path):
    kind, old, new, field, words = EDITS[name]
    base = BASES[kind]
    assert old in base, f"case {name}: {old!r} is not in the {kind} base"
    path = tmp_path / f"{name.replace(' ', '_')}.yaml"
    path.write_text(base.replace(old, new, 1))
    got_kind, problems = config_cli.check_file(path, kind)
    assert got_kind == kind and problems, f"{name}: accepted"
    mine = [p for p in problems if p.field == field]
    assert mine, f"{name}: no problem at {field}: " + "\n".join(map(str, problems))
    p = mine[0]
    assert p.file == str(path) and words in p.expected + " " + p.found, str(p)
    lines = base.replace(old, new, 1).splitlines()
    assert p.line is not None and 1 <= p.line <= len(lines), str(p)
    key = field.split(".")[-1].split("[")[0]
    at_key = [i + 1 for i, text in enumerate(lines) if f"{key}:" in text]
    if field.endswith("]") and p.line in at_key:   # an item of a list of numbers: the list's line
        pass
    elif field.endswith("]"):      # a list item's own check: the item's line
        assert lines[p.line - 1].lstrip().startswith("- "), f"{name}: {p}"
    elif p.found == "nothing":     # a missing key: the line of the mapping that lacks it
        assert p.line == 1 or lines[p.line - 1].rstrip().endswith(":"), f"{name}: {p}"
    elif at_key and field != P:    # the line that writes the key; else (a mapping's check) the mapping's line
        assert p.line in at_key, f"{name}: line {p.line}, the key {key} is on line(s) {at_key}: {p}"
    else:
        assert lines[p.line - 1].strip().endswith(":") or "{" in lines[p.line - 1], f"{name}: {p}"


def test_every_valid_base_passes(tmp_path):
    for kind, text in BASES.items():
        path = tmp_path / f"{kind}.yaml"
        path.write_text(text)
        assert config_cli.check_file(path, kind) == (kind, []), kind


# whole-file cases: (text or bytes, line, words)
FILES = {
    "alias bomb": ("a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
                   "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: [*c, *c, *c, *c, *c, *c, *c, *c, *c]\n", 1,
                   "anchor"),
    "alias without anchor line": ("/**:\n  ros__parameters:\n    spacecraft: *craft\n", 3, "alias"),
    "duplicate key": (SCENARIO.replace("      torque_max_Nm: 0.1\n", "      torque_max_Nm: 0.1\n      "
                                       "torque_max_Nm: 0.2\n"), 7, "duplicate of the key on line 6"),
    "non-UTF-8": (SCENARIO.encode().replace(b"frame_id: eci", b"frame_id: \xe9ci"), 3, "UTF-8"),
    "empty file": ("", 1, "an empty file"),
    "only comments": ("# a scenario\n# nothing else\n", 1, "an empty file"),
    "root a list": ("- spacecraft\n- orbit\n", 1, "a list"),
    "root a number": ("42\n", 1, "the value '42'"),
    "python tag": ("/**: !!python/object/apply:os.system ['true']\n", 1, "tag"),
    "broken YAML": ("/**:\n  ros__parameters: {spacecraft: [1, 2\n", 3, "valid YAML"),
    "deep nesting": ("a: " + "[" * 100 + "]" * 100 + "\n", 1, "levels of nesting"),
    "list as key": ("? [a, b]\n: 1\n", 1, "used as a key"),
}


@pytest.mark.parametrize("name", sorted(FILES))
def test_hostile_file_refused_with_file_and_line(name, tmp_path):
    text, line, words = FILES[name]
    path = tmp_path / "hostile.yaml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    _, problems = config_cli.check_file(path, "scenario")
    assert len(problems) == 1, problems
    assert problems[0].file == str(path) and problems[0].line == line and words in str(problems[0]), str(problems[0])


def test_ten_megabyte_file_refused_before_parsing(tmp_path):
    path = tmp_path / "big.yaml"
    with open(path, "w") as fh:
        fh.write(SCENARIO)
        fh.write(("# " + "x" * 1022 + "\n") * 10 * 1024)
    _, problems = config_cli.check_file(path, "scenario")
    assert len(problems) == 1 and "bytes" in problems[0].expected and str(path) == problems[0].file


def test_all_problems_of_a_file_at_once(tmp_path):
    text = (SCENARIO.replace("torque_max_Nm: 0.1", "torque_max: 0.1").replace("altitude_m: 450000.0", "altitude_m: -1")
            .replace("seed: 3", "seed: x").replace("noise_nT: 50.0", "noise_nT: .nan"))
    path = tmp_path / "many.yaml"
    path.write_text(text)
    _, problems = config_cli.check_file(path, "scenario")
    assert [(p.line, p.field) for p in problems] == [
        (6, f"{SC}.torque_max"), (10, f"{P}.orbit.altitude_m"), (20, f"{P}.sensors.seed"),
        (25, f"{P}.sensors.magnetometer.noise_nT")]


def test_the_scenario_reader_refuses_duplicate_keys_and_alias_bombs(tmp_path):
    """scenario.load reads through the same guards: a duplicate key or an alias bomb is a ConfigError
    naming the file and the line, never a silent last value or gigabytes of memory."""
    from att_msgs_py.errors import ConfigError
    from att_sim.models import scenario
    twice = tmp_path / "twice.yaml"
    twice.write_text("/**:\n  ros__parameters:\n    frame_id: eci\n    frame_id: gcrs\n")
    with pytest.raises(ConfigError, match=r"twice.yaml:4: /\*\*.ros__parameters.frame_id: expected each key "
                                          r"once in a mapping"):
        scenario.load(str(twice))
    bomb = tmp_path / "bomb.yaml"
    levels = "a: &a [" + ", ".join(["lol"] * 10) + "]\n"
    for name, below in zip("bcdefgh", "abcdefg"):          # 10^8 values once expanded, 600 bytes written
        levels += f"{name}: &{name} [" + ", ".join([f"*{below}"] * 10) + "]\n"
    bomb.write_text(levels)
    with pytest.raises(ConfigError, match="alias bomb"):
        scenario.load(str(bomb))
