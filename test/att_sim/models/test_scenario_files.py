"""A scenario split by job: the scenario names its spacecraft; the nodes' tuning and the demo beside it.

Each file is validated by its model and a problem names the file it is in, its line and field; what
the scenario and the spacecraft say together is checked once they are resolved."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from att_msgs_py.errors import ConfigError, ErrorCode
from att_sim.models import scenario

CONFIG = Path(scenario.__file__).resolve().parents[2] / "config"


@pytest.fixture
def tree(tmp_path, monkeypatch):
    """A configuration directory holding a copy of swift_demo's four files, first on $ATT_CONFIG_PATH."""
    for folder, names in (("scenarios", ("swift_demo.yaml", "swift_demo.params.yaml", "swift_demo.demo.yaml")),
                          ("spacecraft", ("swift_demo.yaml",))):
        (tmp_path / folder).mkdir()
        for name in names:
            shutil.copy(CONFIG / folder / name, tmp_path / folder / name)
    monkeypatch.setenv(scenario.CONFIG_ENV, str(tmp_path))
    return tmp_path


def refused(name: str) -> str:
    with pytest.raises(ConfigError) as err:
        scenario.load(name)
    assert err.value.code == ErrorCode.INVALID_CONFIG
    return err.value.message


def test_a_name_finds_the_scenario_its_spacecraft_its_tuning_and_its_demo(tree):
    s = scenario.load("swift_demo")
    assert s.path == tree / "scenarios" / "swift_demo.yaml"
    assert s.spacecraft_path == tree / "spacecraft" / "swift_demo.yaml"
    assert s.params_path == s.node_params_path == tree / "scenarios" / "swift_demo.params.yaml"
    assert s.node_params["simulator"]["step_s"] == 0.05 and s.node_params["demo"]["method"] == "slepian_minimum_time"
    assert s.spacecraft.body_torque_max == 0.1 and s.sensors.gyro is not None and s.orbit.altitude == 450e3
    assert "swift_demo" in scenario.available()


def test_a_scenario_without_tuning_has_no_node_sections(tree):
    (tree / "scenarios" / "swift_demo.params.yaml").unlink()
    (tree / "scenarios" / "swift_demo.demo.yaml").unlink()
    s = scenario.load("swift_demo")
    assert s.node_params == {} and s.params_path is None and s.node_params_path == s.path


def test_an_unknown_spacecraft_is_refused_on_the_scenarios_line(tree):
    path = tree / "scenarios" / "swift_demo.yaml"
    path.write_text(path.read_text().replace("spacecraft: swift_demo", "spacecraft: no_such_craft"))
    message = refused("swift_demo")
    line = next(i + 1 for i, text in enumerate(path.read_text().splitlines()) if text.startswith("spacecraft:"))
    assert message.startswith(f"{path}:{line}: spacecraft: expected the name of a spacecraft file; found "
                              f"'no_such_craft'"), message


def test_a_problem_of_the_spacecraft_names_the_spacecraft_file(tree):
    path = tree / "spacecraft" / "swift_demo.yaml"
    path.write_text(path.read_text().replace("torque_max_Nm: 0.1 ", "torque_max_Nm: -0.1"))
    line = next(i + 1 for i, text in enumerate(path.read_text().splitlines()) if text.startswith("torque_max_Nm"))
    assert refused("swift_demo") == f"{path}:{line}: torque_max_Nm: expected greater than 0; found -0.1"


def test_what_the_two_files_say_together_is_checked(tree):
    path = tree / "scenarios" / "swift_demo.yaml"
    path.write_text(path.read_text() + "environment:\n  drag: true\n")
    message = refused("swift_demo")
    assert message.startswith(f"{path}:") and "environment: expected facets (the surfaces drag acts on)" in message


def test_a_broken_tuning_file_is_refused_naming_it(tree):
    path = tree / "scenarios" / "swift_demo.params.yaml"
    path.write_text("simulator:\n  step: 0.05\n")
    message = refused("swift_demo")
    assert message.startswith(f"{path}:1: simulator.ros__parameters: expected this key (required)"), message


def test_a_bad_demo_is_refused_naming_it(tree):
    path = tree / "scenarios" / "swift_demo.demo.yaml"
    path.write_text(path.read_text().replace("sensor_axis: [1.0, 0.0, 0.0]", "sensor_axis: [2.0, 0.0, 0.0]"))
    assert "demo.sensor_axis: expected a unit vector" in refused("swift_demo")


def test_refusal_is_the_one_sentence_of_what_load_raises(tmp_path):
    """A shipped scenario loads (no refusal); an unknown name and a file that is not valid YAML are
    each refused with the sentence :func:`scenario.load` raises, naming the name or the file's line."""
    assert scenario.refusal("swift_demo") is None
    with pytest.raises(KeyError) as unknown:
        scenario.load("no_such_scenario")
    assert scenario.refusal("no_such_scenario") == unknown.value.args[0] and "no_such_scenario" in unknown.value.args[0]
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: x\n  spacecraft: [\n")
    why = scenario.refusal(str(broken))
    assert why is not None and why.startswith(f"{broken}:2: ") and "expected valid YAML" in why, why
