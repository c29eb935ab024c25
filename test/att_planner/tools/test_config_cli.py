"""att-config: check (exit codes, every problem), schema (valid JSON Schema), show (origins), migrate."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from att_planner.tools import config_cli

ROOT = Path(config_cli.__file__).resolve().parents[2]
SHIPPED = sorted([*ROOT.glob("config/*.yaml"), *ROOT.glob("config/*/*.yaml"), *ROOT.glob("campaigns/*.yaml")])


def expected_kind(path: Path) -> str:
    if path.name.endswith(".params.yaml") or path.stem == "controller_gains":
        return "parameters"
    if path.name.endswith(".demo.yaml"):
        return "demo"
    return {"missions": "mission", "targets": "targets", "campaigns": "campaign", "spacecraft": "spacecraft",
            "scenarios": "scenario", "faults": "faults"}[path.parent.name]


def test_shipped_files_are_found():
    """The split layout: a spacecraft file, a scenario file and its node tuning for each scenario."""
    assert len(SHIPPED) >= 22
    names = {p.stem for p in ROOT.glob("config/scenarios/*.yaml") if "." not in p.stem}
    assert names == {p.stem for p in ROOT.glob("config/spacecraft/*.yaml")} >= {"swift_demo", "leo_observatory"}
    assert all((ROOT / "config" / "scenarios" / f"{n}.params.yaml").is_file() for n in names)
    assert not [p for p in ROOT.glob("config/*.yaml") if p.stem != "controller_gains"]


@pytest.mark.parametrize("path", sorted(ROOT.glob("config/scenarios/*.params.yaml")), ids=lambda p: p.name)
def test_the_node_tuning_is_a_plain_ros_parameter_file(path):
    """rclpy's own parser (as --params-file reads it) takes every node section of the file, and every
    parameter is one the node declares, of its type and in its range."""
    from rclpy.parameter import parameter_dict_from_yaml_file

    from att_planner.tools.node_parameters import declared
    data = yaml.safe_load(path.read_text())
    for node, section in data.items():
        parsed = parameter_dict_from_yaml_file(str(path), target_nodes=[node])
        assert set(parsed) == set(section["ros__parameters"])
        assert declared(node).problems(section["ros__parameters"]) == []


def test_an_old_parameter_name_is_answered_with_its_new_name(tmp_path, capsys):
    path = tmp_path / "old.params.yaml"
    path.write_text("controller:\n  ros__parameters:\n    control_rate_Hz: 10.0\n    settle_time: 5.0\n")
    assert config_cli.main(["check", str(path)]) == 2
    assert (f"{path}:4: controller.ros__parameters.settle_time: expected a valid controller parameter "
            f"[INVALID_PARAMETER]; found parameter 'settle_time' is renamed 'settle_time_s' (its unit in its name)"
            in capsys.readouterr().out.splitlines())


def test_a_bad_parameter_file_is_refused_naming_the_node_and_parameter(tmp_path, capsys):
    path = tmp_path / "my.params.yaml"
    path.write_text("simulator:\n  ros__parameters:\n    step_s: 5.0\n    lockstep_timout: 1.0\n"
                    "navigator:\n  ros__parameters:\n    x: 1\n")
    assert config_cli.main(["check", str(path)]) == 2
    out = capsys.readouterr().out.splitlines()
    assert any(line.startswith(f"{path}:3: simulator.ros__parameters.step_s: expected a valid simulator parameter "
                               f"[INVALID_PARAMETER]") for line in out), out
    assert any(line.startswith(f"{path}:4: simulator.ros__parameters.lockstep_timout:") for line in out), out
    assert any(line.startswith(f"{path}:5: navigator: expected a section of one of the nodes") for line in out), out


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_shipped_file_passes_check(path, capsys):
    """Each file under config/ and campaigns/ is valid under its kind's schema as shipped: no old key
    name, every reference resolved, the file untouched."""
    before = path.read_text()
    kind, problems = config_cli.check_file(path)
    assert problems == [], "\n".join(map(str, problems))
    assert kind == expected_kind(path)
    assert config_cli.main(["check", str(path)]) == 0
    assert path.read_text() == before


def test_the_test_inputs_pass_check(monkeypatch, capsys):
    """The fixture scenario and campaign of test/data pass check (its campaign names the fixture scenario)."""
    data = ROOT / "test" / "data"
    monkeypatch.setenv("ATT_CONFIG_PATH", str(data / "config"))
    files = sorted([*data.glob("config/*/*.yaml"), *data.glob("campaigns/*.yaml")])
    assert len(files) >= 2 and config_cli.main(["check", *map(str, files)]) == 0


def test_a_migrated_copy_of_an_old_file_passes_check(tmp_path, capsys):
    """A spacecraft, a scenario and a demo written under the old key names are refused with each new
    name, and pass once migrated, their values unchanged."""
    renames = {"spacecraft/swift_demo.yaml": (("inertia_kg_m2:", "inertia:"), ("torque_max_Nm:", "torque_max:")),
               "scenarios/swift_demo.yaml": (("altitude_m:", "altitude:"), ("arg0_rad:", "arg0:")),
               "scenarios/leo_observatory.demo.yaml": (("time_budget_s:", "time_budget:"),
                                                       ("start_lead_s:", "start_lead:"),
                                                       ("start_time_s:", "start_time:"))}
    expected = {"spacecraft/swift_demo.yaml": [("inertia", "inertia_kg_m2"), ("torque_max", "torque_max_Nm"),
                                               ("wheel_inertia", "wheel_inertia_kg_m2"),
                                               ("wheel_torque_max", "wheel_torque_max_Nm")],
                "scenarios/swift_demo.yaml": [("altitude", "altitude_m"), ("arg0", "arg0_rad")],
                "scenarios/leo_observatory.demo.yaml": [("start_lead", "start_lead_s"),
                                                        ("start_time", "start_time_s"),
                                                        ("time_budget", "time_budget_s")]}
    for name, pairs in renames.items():
        shipped = ROOT / "config" / name
        old = shipped.read_text()
        for new, previous in pairs:
            old = old.replace(new, previous)
        path = tmp_path / name
        path.parent.mkdir(exist_ok=True)
        path.write_text(old)
        _, problems = config_cli.check_file(path)
        assert sorted(p.rename for p in problems) == expected[name]
        assert config_cli.main(["migrate", str(path)]) == 0
        assert config_cli.check_file(path)[1] == []
        assert yaml.safe_load(path.read_text()) == yaml.safe_load(shipped.read_text())


def test_check_exit_2_with_every_problem_of_every_file(tmp_path, capsys):
    a, b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    a.write_text("campaign:\n  scenario: swift_demo\n  seed: -1\n  runs: 0\n")
    b.write_text("kind: inertial\nscenario: no_such_scenario\ntargets:\n  - {name: x, ra_deg: 400, dec_deg: 0, "
                 "dwell_s: 1}\n")
    assert config_cli.main(["check", str(a), str(b)]) == 2
    out = capsys.readouterr().out.splitlines()
    assert any(line.startswith(f"{a}:3: campaign.seed: expected greater than or equal to 0") for line in out), out
    assert any(line.startswith(f"{a}:4: campaign.runs:") for line in out), out
    assert any(line.startswith(f"{b}:4: targets[0].ra_deg:") for line in out), out
    assert len(out) == 3


def test_check_resolves_references(tmp_path, capsys):
    mission = tmp_path / "missions" / "m.yaml"
    mission.parent.mkdir()
    mission.write_text("targets: nowhere\nsensor_axis: [0, 1, 0]\nhorizon_s: 600\n")
    assert config_cli.main(["check", str(mission)]) == 2
    out = capsys.readouterr().out
    assert f"{mission}:1: targets: expected the name of a target list; found 'nowhere'" in out
    assert "observatory" in out


def test_schema_is_json_for_every_kind(capsys):
    assert config_cli.main(["schema"]) == 0
    every = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}"))
    assert set(every) == set(config_cli.KINDS)
    assert config_cli.main(["schema", "spacecraft"]) == 0
    craft = json.loads(capsys.readouterr().out)
    assert craft["required"] == ["inertia_kg_m2"] and craft["additionalProperties"] is False
    assert craft["properties"]["torque_max_Nm"]["exclusiveMinimum"] == 0.0
    assert {"inertial", "ground"} <= {s.get("title", "").replace("Targets", "").lower()
                                      for s in every["targets"]["$defs"].values()}


def test_show_names_file_line_or_default(tmp_path, capsys):
    path = tmp_path / "mini.yaml"
    path.write_text("/**:\n  ros__parameters:\n    spacecraft:\n      inertia_kg_m2: [2, 3, 4]\n"
                    "      wheel_inertia_kg_m2: 0.01\nplanner:\n  ros__parameters:\n    time_budget: 5.0\n")
    assert config_cli.main(["show", str(path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert f"/**.ros__parameters.spacecraft.inertia_kg_m2 = [2.0, 3.0, 4.0]  ({path}:4)" in out
    assert "/**.ros__parameters.spacecraft.torque_max_Nm = .inf  (default)" in out
    assert "/**.ros__parameters.orbit.altitude_m = 450000.0  (default)" in out
    assert f"planner.ros__parameters.time_budget = 5.0  ({path}:8)" in out


def test_show_unknown_scenario(capsys):
    assert config_cli.main(["show", "no_such_scenario"]) == 2
    assert "unknown spacecraft/scenario 'no_such_scenario'" in capsys.readouterr().err


def test_migrate_renames_in_place_and_keeps_comments(tmp_path, capsys):
    path = tmp_path / "c.yaml"
    path.write_text("# campaign\ncampaign:\n  scenario: swift_demo\n  seed: 1\n  converge_timeout: 3.0   # s\n")
    assert config_cli.main(["migrate", str(path)]) == 0
    assert path.read_text().splitlines()[-1] == "  converge_timeout_s: 3.0  # s"


@pytest.mark.parametrize("kind", sorted(config_cli.KINDS))
def test_shipped_schemas_are_current(kind):
    """config/schemas/KIND.schema.json is what `att-config schema KIND --out config/schemas` writes."""
    assert (ROOT / "config" / "schemas" / f"{kind}.schema.json").read_text() == config_cli.schema_text(kind)


def test_schema_header_names_the_schema_of_the_files_kind():
    headed = [p for p in SHIPPED if p.read_text().startswith("# yaml-language-server: $schema=")]
    assert headed == SHIPPED, sorted(set(map(str, SHIPPED)) - set(map(str, headed)))
    for path in headed:
        target = path.read_text().splitlines()[0].split("$schema=", 1)[1].strip()
        kind, _ = config_cli.check_file(path)
        assert (path.parent / target).resolve() == (ROOT / "config" / "schemas" / f"{kind}.schema.json").resolve()


def test_schema_out_writes_one_file_per_kind(tmp_path, capsys):
    assert config_cli.main(["schema", "--out", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f"{k}.schema.json" for k in config_cli.KINDS)


OLD_SELF_CONTAINED = """/**:
  ros__parameters:
    spacecraft:
      inertia: [10.0, 12.0, 14.0]
      torque_max: 0.1            # N m
      wheel_inertia_kg_m2: 0.01
demo:
  ros__parameters:
    method: slepian_minimum_time
"""


def test_show_a_scenario_with_old_key_names(tmp_path, capsys):
    """A self-contained file whose only problems are old names is shown under the new names, the file untouched."""
    path = tmp_path / "old_names.yaml"
    path.write_text(OLD_SELF_CONTAINED)
    assert config_cli.main(["show", str(path)]) == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert path.read_text() == OLD_SELF_CONTAINED
    assert f"/**.ros__parameters.spacecraft.torque_max_Nm = 0.1  ({path}:5)" in lines
    assert "old key name" in captured.err and "att-config migrate" in captured.err
    assert any(line.startswith("demo.ros__parameters.method = ") for line in lines)


def test_show_a_shipped_scenario_with_where_each_value_came_from(capsys):
    """att-config show NAME: each value with its file and line across the scenario, its spacecraft,
    its node tuning and its demo, or 'default'."""
    assert config_cli.main(["show", "swift_demo"]) == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert "old key name" not in captured.err

    def origin(prefix: str) -> str:
        return next(line for line in lines if line.startswith(prefix)).rsplit("  (", 1)[1].rstrip(")")

    config = ROOT / "config"
    for prefix, path, key in (("spacecraft.torque_max_Nm = 0.1", config / "spacecraft" / "swift_demo.yaml",
                               "torque_max_Nm:"),
                              ("orbit.altitude_m = 450000.0", config / "scenarios" / "swift_demo.yaml", "altitude_m:"),
                              ("sensors.gyro.rate_Hz = 20.0", config / "spacecraft" / "swift_demo.yaml", "gyro:"),
                              ("simulator.ros__parameters.step_s = 0.05",
                               config / "scenarios" / "swift_demo.params.yaml", "step_s:"),
                              ("demo.method = ", config / "scenarios" / "swift_demo.demo.yaml", "method:")):
        text = path.read_text().splitlines()
        number = next(i + 1 for i, line in enumerate(text) if line.strip().startswith(key))
        where = origin(prefix)
        if key == "gyro:":                   # a leaf below the key: a line after it
            assert where.startswith(f"{path}:") and int(where.rsplit(":", 1)[1]) > number, where
        else:
            assert where == f"{path}:{number}", (prefix, where)
    assert origin("environment.drag_coefficient = 2.2") == "default"


def test_show_refuses_a_scenario_with_real_problems(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text("/**:\n  ros__parameters:\n    spacecraft:\n      inertia_kg_m2: [1, 1, 5]\n")
    assert config_cli.main(["show", str(path)]) == 2
    assert "triangle inequality" in capsys.readouterr().out


def test_the_parameter_schema_types_each_node_section_by_its_table():
    """Editors complete a parameter file from each node's table: every declared parameter with its
    unit in the description, and nothing else."""
    from att_planner.tools.node_parameters import NODE_PARAMETERS, declared
    nodes = config_cli.schema("parameters")["properties"]
    assert set(nodes) == set(NODE_PARAMETERS)
    for node, section in nodes.items():
        params = section["properties"]["ros__parameters"]
        assert set(params["properties"]) == set(declared(node).parameters) and params["additionalProperties"] is False
    step = nodes["simulator"]["properties"]["ros__parameters"]["properties"]["step_s"]
    assert "[s]" in step["description"] and (step["exclusiveMinimum"], step["maximum"]) == (0.0, 1.0)
