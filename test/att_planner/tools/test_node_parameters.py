"""Every node's parameter declarations (ROS-free): complete, with units that match their names,
defaults that are the cores' own, the in-process cores refusing what a node refuses in the same
words, and a Markdown reference that lists every declared parameter."""
from __future__ import annotations

import dataclasses
import json
import math
import re

import pytest
import yaml

from att_msgs_py.errors import ConfigError, ErrorCode
from att_msgs_py.parameter_docs import COLUMNS, TYPE_NAMES, markdown
from att_msgs_py.parameters import SectionReader
from att_planner.control.controller_config import ControllerConfig
from att_planner.control.controller_from_scenario import controller_config, gate_config
from att_planner.control.controller_parameters import CONTROLLER
from att_planner.control.state_gate import GateConfig
from att_planner.estimation.estimator import EstimatorConfig
from att_planner.estimation.estimator_from_scenario import estimator_config
from att_planner.estimation.estimator_parameters import ESTIMATOR
from att_planner.tools.closed_loop import ClosedLoop
from att_planner.tools.launch import NODE_MODULES
from att_planner.tools.node_parameters import NODE_PARAMETERS, declared, reference
from att_sim.models import scenario as scen

SWIFT = scen.load("swift_demo")
UNIT_OF_SUFFIX = {"_deg": "deg", "_nT": "nT", "_ppm": "ppm", "_arcsec": "arcsec", "_mb": "MiB",
                  "_deg_per_sqrt_h": "deg/sqrt(h)", "_deg_per_h": "deg/h", "_deg_per_h_per_sqrt_h": "deg/h/sqrt(h)"}


def test_every_node_has_its_declarations():
    assert set(NODE_PARAMETERS) == set(NODE_MODULES)
    for node in ("simulator", "controller", "estimator", "planner"):
        assert "scenario" in declared(node)
    assert "scenario" not in declared("recorder")


@pytest.mark.parametrize("node", NODE_PARAMETERS)
def test_a_unit_in_a_name_is_the_declared_unit(node):
    for spec in NODE_PARAMETERS[node]:
        suffix = max((s for s in UNIT_OF_SUFFIX if spec.name.endswith(s)), key=len, default=None)
        if suffix:
            assert spec.unit == UNIT_OF_SUFFIX[suffix], spec.name
        assert spec.description and spec.description == spec.description.strip(), spec.name
        if spec.kind is str or spec.kind is bool:
            assert not spec.bounded and not spec.unit, spec.name


def test_without_parameters_the_controller_and_its_gate_have_the_cores_defaults():
    cfg = controller_config(SectionReader(CONTROLLER, {}), SWIFT)
    d = ControllerConfig()
    expected = dataclasses.replace(d, m_max=SWIFT.spacecraft.dipole_max, safe_kd=d.tracking_kd)
    for field in dataclasses.fields(ControllerConfig):
        assert getattr(cfg, field.name) == pytest.approx(getattr(expected, field.name)), field.name
    assert gate_config(SectionReader(CONTROLLER, {})) == GateConfig()


def test_without_parameters_the_estimators_fixed_tuning_is_the_cores():
    cfg, d = estimator_config(SectionReader(ESTIMATOR, {}), SWIFT), EstimatorConfig()
    for name in ("gate_probability", "propagate_timeout", "history", "lost_after", "vector_fallback_after",
                 "magnetometer_sigma", "sun_sigma", "sun_threshold", "pair_window", "max_gyro_gap", "resync_timeout"):
        assert getattr(cfg, name) == pytest.approx(getattr(d, name)), name


@pytest.mark.parametrize("overrides, words", [
    ({"controller": {"control_rate_Hz": 0.0}}, "parameter 'control_rate_Hz' (override) = 0.0 is outside (0, 1000]"),
    ({"controller": {"control_rate": 20.0}}, "parameter 'control_rate' (override) is renamed 'control_rate_Hz'"),
    ({"controller": {"state_source": "oracle"}}, "parameter 'state_source' (override): expected one of truth, "
                                                 "estimate, got 'oracle'"),
    ({"controller": {"m_max_Am2": -1.0}}, "parameter 'm_max_Am2' (override): expected a dipole > 0 A m², got -1.0"),
    ({"estimator": {"gate_probability": 1.5}}, "parameter 'gate_probability' (override) = 1.5 is outside"),
    ({"simulator": {"step_s": 2}}, "parameter 'step_s' (override) = 2.0 is outside (0, 1]"),
    ({"simulator": {"step": 0.1}}, "parameter 'step' (override) is renamed 'step_s'"),
    ({"simulator": {"publish_rate_Hz": 1000.0}}, "(at most 1/step_s: one per integration step)"),
    ({"controller": {"settle_tme": 1.0}}, "unknown parameter(s) settle_tme"),
    ({"controler": {"settle_time_s": 1.0}}, "overrides of unknown node(s) controler"),
])
def test_the_in_process_loop_refuses_what_a_node_refuses_in_the_same_words(overrides, words):
    with pytest.raises(ConfigError) as err:
        ClosedLoop(SWIFT, overrides=overrides)
    assert err.value.code == ErrorCode.INVALID_PARAMETER and words in err.value.message, err.value.message


def test_an_integer_for_a_double_runs_in_process():
    loop = ClosedLoop(SWIFT, overrides={"controller": {"control_rate_Hz": 20, "state_source": "truth"}})
    assert loop.controller.config.control_period == pytest.approx(0.05)


def rows(text: str) -> list[list[str]]:
    return [[c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]] for line in text.splitlines()
            if line.startswith("| ")]


@pytest.mark.parametrize("node", NODE_PARAMETERS)
def test_the_markdown_reference_lists_every_declared_parameter(node):
    table = declared(node)
    text = markdown(table)
    header, *body = rows(text)
    assert header == list(COLUMNS) and text.startswith(f"## {node}\n")
    assert [r[0] for r in body] == [f"`{spec.name}`" for spec in table]
    for r, spec in zip(body, table):
        assert len(r) == len(COLUMNS)
        assert r[1] == TYPE_NAMES[spec.kind] and r[4] == spec.unit and r[5].startswith(spec.description[:20])
        assert (r[2] == f"`{spec.default_text()}`") if spec.default is not None else r[2] == spec.default_rule
        if spec.bounded and not spec.refusal:
            assert spec.interval() in r[3]


def test_the_reference_has_every_node_and_writes_numbers_as_a_parameter_file_does():
    text = reference()
    assert all(f"## {node}\n" in text for node in NODE_PARAMETERS)
    assert "| `step_s` | double | `0.05` | in (0, 1] | s |" in text
    assert "| `schedule_rate_max_rad_s` | double | `.inf` |" in text
    assert "| `initial_attitude` | double[] | `[0.0, 0.0, 0.0, 1.0]` |" in text
    assert math.isclose(CONTROLLER["control_rate_Hz"].default, 1.0 / ControllerConfig().control_period)


def node_sections(name: str) -> tuple[str, dict]:
    """The node sections of shipped file ``name``: a scenario's, or a plain ROS parameter file's."""
    try:
        s = scen.load(name)
    except ConfigError:                                   # a --params-file (controller_gains)
        path = scen.find(name)
        return str(path), {k: v["ros__parameters"] for k, v in yaml.safe_load(path.read_text()).items()}
    return str(s.path), s.node_params


@pytest.mark.parametrize("name", scen.available())
def test_every_shipped_file_sets_only_declared_node_parameters_to_accepted_values(name):
    """A shipped file's node sections pass the checks a node makes of them."""
    path, sections = node_sections(name)
    assert sections
    for node, section in sections.items():
        if node not in NODE_PARAMETERS:                   # the demo maneuver, the shared /** keys
            continue
        assert NODE_PARAMETERS[node].problems(section, f" (from {path})") == []


@pytest.mark.parametrize("node", NODE_PARAMETERS)
def test_each_nodes_json_schema_is_json_and_has_every_declaration(node):
    schema = json.loads(json.dumps(NODE_PARAMETERS[node].json_schema(), allow_nan=False))
    assert list(schema["properties"]) == list(NODE_PARAMETERS[node].parameters)
    for spec in NODE_PARAMETERS[node]:
        prop = schema["properties"][spec.name]
        assert prop["description"].startswith(spec.summary())
        if spec.bounded and spec.kind is not list and spec.low is not None and not math.isinf(spec.low):
            assert prop["exclusiveMinimum" if spec.low_open else "minimum"] == spec.low


def test_a_renamed_parameter_is_answered_with_its_new_name_and_its_new_name_is_declared():
    assert {old: CONTROLLER.renamed[old] for old in ("control_rate", "settle_time", "wall_timeout")} == {
        "control_rate": "control_rate_Hz", "settle_time": "settle_time_s", "wall_timeout": "wall_timeout_s"}
    assert all(new in CONTROLLER and old not in CONTROLLER for old, new in CONTROLLER.renamed.items())
    [err] = CONTROLLER.problems({"wall_timeout": 2.0})
    assert err.code == ErrorCode.INVALID_PARAMETER
    assert err.message == "parameter 'wall_timeout' is renamed 'wall_timeout_s' (its unit in its name)"
    assert CONTROLLER.problems({"wall_timeout_s": 2.0}) == []


# Each node's old parameter names and the new name (with its unit) each is answered with.
OLD_NAMES = {
    "controller": {"control_rate": "control_rate_Hz", "settle_time": "settle_time_s", "wall_timeout": "wall_timeout_s",
                   "safe_rate_threshold": "safe_rate_threshold_rad_s", "null_space_speed": "null_space_speed_rad_s",
                   "handover_blend": "handover_blend_s", "max_start_rate_error": "max_start_rate_error_rad_s",
                   "max_start_epoch_error": "max_start_epoch_error_s", "max_state_gap": "max_state_gap_s",
                   "max_clock_skew": "max_clock_skew_s", "resync_timeout": "resync_timeout_s",
                   "start_timeout": "start_timeout_s", "mode_sequence_ahead": "mode_sequence_ahead_s",
                   "m_max": "m_max_Am2", "max_cache_mb": "max_cache_MiB"},
    "estimator": {"publish_rate": "publish_rate_Hz", "resync_timeout": "resync_timeout_s",
                  "start_timeout": "start_timeout_s", "propagate_timeout": "propagate_timeout_s",
                  "history": "history_s", "vector_fallback_after": "vector_fallback_after_s",
                  "pair_window": "pair_window_s", "max_gyro_gap": "max_gyro_gap_s"},
    "simulator": {"step": "step_s", "publish_rate": "publish_rate_Hz", "start_timeout": "start_timeout_s",
                  "initial_rate": "initial_rate_rad_s"},
    "planner": {"time_budget": "time_budget_s", "accept_final_rate": "accept_final_rate_rad_s",
                "schedule_rate_max": "schedule_rate_max_rad_s"},
    "recorder": {"flush_period": "flush_period_s"},
}


@pytest.mark.parametrize("node, old, new", [(n, o, w) for n, names in OLD_NAMES.items() for o, w in names.items()])
def test_each_old_parameter_name_is_answered_with_its_new_name(node, old, new):
    table = NODE_PARAMETERS[node]
    assert table.renamed[old] == new and new in table and old not in table
    [err] = table.problems({old: 1.0}, " (override)")
    assert err.code == ErrorCode.INVALID_PARAMETER
    assert err.message == f"parameter '{old}' (override) is renamed '{new}' (its unit in its name)"
    if node in ("simulator", "controller", "estimator"):          # the nodes of the in-process closed loop
        with pytest.raises(ConfigError, match=f"parameter '{old}' \\(override\\) is renamed '{new}'"):
            ClosedLoop(SWIFT, overrides={node: {old: 1.0}})
