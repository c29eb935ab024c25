"""Hostile configuration: scenario files that are not scenarios, and node parameters of the wrong
type or out of range.

A bad scenario file is a :class:`ConfigError` (INVALID_CONFIG, a ValueError) naming the file and
the field; an unknown scenario name stays a KeyError (the planner maps it to UNKNOWN_SPACECRAFT).
A node started with a bad parameter, an unknown or broken scenario or a missing or broken
``--params-file`` prints one line ``<prog>: [code NAME] message`` naming it and exits 2, without a
traceback. Good values (an integer for a float, relative paths from the current directory) start.
"""
from __future__ import annotations

import copy
import re
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
import rclpy
import yaml

from att_msgs.msg import ActuatorCommand, SpacecraftState
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError
from att_planner.service.requests import load_spacecraft
from att_planner.tools.launch import NODE_MODULES, isolated_env
from att_sim.models import scenario
from helpers import forked_nodes

BASE = {
    "/**": {"ros__parameters": {
        "frame_id": "eci", "body_frame_id": "body",
        "spacecraft": {"inertia_kg_m2": [10.0, 12.0, 14.0], "torque_max_Nm": 0.1,
                       "wheel_axes": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], "wheel_inertia_kg_m2": 0.01,
                       "wheel_torque_max_Nm": 0.1, "wheel_speed_max_rad_s": 600.0, "dipole_max_Am2": 5.0},
        "orbit": {"altitude_m": 500000.0, "inclination_deg": 97.0}}},
    "simulator": {"ros__parameters": {"step_s": 0.1, "publish_rate_Hz": 10.0}},
}


def edited(**changes):
    """BASE as YAML with ``changes``: key paths ``a__b`` (under the shared parameters, or a node
    section named ``simulator``) set to a value, or deleted with ``...``."""
    doc = copy.deepcopy(BASE)
    for path, value in changes.items():
        keys = path.split("__")
        node = doc if keys[0] == "simulator" else doc["/**"]["ros__parameters"]
        for key in keys[:-1]:
            node = node[key]
        if value is ...:
            del node[keys[-1]]
        else:
            node[keys[-1]] = value
    return yaml.safe_dump(doc)


GAINS = (Path(scenario.__file__).resolve().parents[2] / "config" / "controller_gains.yaml").read_text()
BAD_SCENARIOS = {
    "a list": ("- 1\n- 2\n", "a mapping"),
    "a scalar": ("just some text\n", "a mapping"),
    "empty": ("", "an empty file"),
    "broken YAML": ("/**: {ros__parameters: [\n", "expected valid YAML"),
    "tab indentation": ("/**:\n\tros__parameters: {}\n", "expected valid YAML"),
    "a gains file (no /**)": (GAINS, "/**: expected this key (required)"),
    "/** without ros__parameters": ("/**:\n  spacecraft: {inertia: [1, 1, 1]}\n", "ros__parameters"),
    "no spacecraft": (edited(spacecraft=...), "spacecraft"),
    "spacecraft a list": (edited(spacecraft=[1, 2]), "spacecraft: expected a valid dictionary"),
    "inertia missing": (edited(spacecraft__inertia_kg_m2=...),
        "spacecraft.inertia_kg_m2: expected this key (required)"),
    "inertia of 4 numbers": (edited(spacecraft__inertia_kg_m2=[1.0, 2.0, 3.0, 4.0]), "spacecraft.inertia"),
    "inertia text": (edited(spacecraft__inertia_kg_m2="heavy"), "spacecraft.inertia"),
    "inertia with a text entry": (edited(spacecraft__inertia_kg_m2=[1.0, "x", 1.0]), "spacecraft.inertia"),
    "inertia NaN": (edited(spacecraft__inertia_kg_m2=[float("nan"), 1.0, 1.0]), "finite"),
    "inertia a scalar": (edited(spacecraft__inertia_kg_m2=5.0), "spacecraft.inertia"),
    "inertia nested lists": (edited(spacecraft__inertia_kg_m2=[[1, 0, 0], [0, 1, 0], [0, 0, 1]]), "spacecraft.inertia"),
    "torque_max text": (edited(spacecraft__torque_max_Nm="fast"), "spacecraft.torque_max"),
    "torque_max zero": (edited(spacecraft__torque_max_Nm=0.0), "spacecraft.torque_max"),
    "torque_max negative": (edited(spacecraft__torque_max_Nm=-0.1),
        "spacecraft.torque_max_Nm: expected greater than 0"),
    "dipole_max NaN": (edited(spacecraft__dipole_max_Am2=float("nan")), "spacecraft.dipole_max"),
    "wheel_speed_max a bool": (edited(spacecraft__wheel_speed_max_rad_s=True), "spacecraft.wheel_speed_max"),
    "wheel_torque_max a list": (edited(spacecraft__wheel_torque_max_Nm=[0.1]), "spacecraft.wheel_torque_max"),
    "unknown spacecraft key (typo)": (edited(spacecraft__intertia=[1.0, 1.0, 1.0]), "unknown key(s) intertia"),
    "wheel_axes of 4 numbers": (edited(spacecraft__wheel_axes=[1.0, 0.0, 0.0, 1.0]),
        "spacecraft.wheel_axes: expected 3 numbers per vector"),
    "wheel axis not unit": (edited(spacecraft__wheel_axes=[2.0, 0.0, 0.0]),
        "wheel_axes: expected 3 numbers per unit vector; vector 0"),
    "wheels without inertia": (edited(spacecraft__wheel_inertia_kg_m2=0.0), "wheel_inertia"),
    "wheel_inertia negative": (edited(spacecraft__wheel_inertia_kg_m2=-1.0), "wheel_inertia"),
    "unknown orbit key": (edited(orbit__eccentricity=0.1), "orbit"),
    "orbit altitude text": (edited(orbit__altitude_m="high"), "orbit.altitude"),
    "orbit altitude negative": (edited(orbit__altitude_m=-1.0), "orbit.altitude"),
    "orbit a list": (edited(orbit=[1, 2]), "orbit"),
    "frame_id empty": (edited(frame_id=""), "frame_id"),
    "body_frame_id with a newline": (edited(body_frame_id="body\nx"), "body_frame_id"),
    "node section not a mapping": (edited(simulator=5), "simulator: expected a valid dictionary"),
    "node section without ros__parameters": (edited(simulator={"step": 0.1}),
        "simulator.ros__parameters: expected this key (required)"),
    "a file over 1 MB": ("# " + "x" * 1_100_000 + "\n" + yaml.safe_dump(BASE), "bytes"),
    "not UTF-8": (b"\xff\xfe/**: \x00\x81", "expected UTF-8 text"),
    # sensors and actuators
    "sensors a list": (edited(sensors=[1, 2]), "sensors: expected a valid dictionary"),
    "sensors unknown kind": (edited(sensors={"lidar": {}}), "sensors.lidar: expected one of the keys"),
    "gyro ARW negative": (edited(sensors={"gyro": {"arw_deg_per_sqrt_h": -0.1}}), "sensors.gyro.arw_deg_per_sqrt_h"),
    "gyro rate text": (edited(sensors={"gyro": {"rate_Hz": "fast"}}), "sensors.gyro.rate_Hz"),
    "gyro key typo": (edited(sensors={"gyro": {"arw_deg_per_sqrt_hr": 0.1}}), "unknown key(s) arw_deg_per_sqrt_hr"),
    "tracker without a name": (edited(sensors={"star_trackers": [{"rate_Hz": 5.0}]}),
                               "sensors.star_trackers[0].name"),
    "tracker mounting not unit": (edited(sensors={"star_trackers": [{"name": "a", "mounting": [0, 0, 0, 3]}]}),
                                  "sensors.star_trackers[0].mounting"),
    "tracker Sun exclusion without an epoch": (
        edited(sensors={"star_trackers": [{"name": "a", "exclusions": [{"body": "sun", "half_angle_deg": 30}]}]}),
        "expected an epoch (the Sun, Moon and Earth depend on the date) for star tracker a's sun exclusion"),
    "sun sensors without an epoch": (edited(sensors={"sun_sensors": {}}),
        "expected an epoch (the Sun, Moon and Earth depend on the date) for sun_sensors"),
    "seed text": (edited(sensors={"seed": "lucky"}), "sensors.seed"),
    "magnetometer noise NaN": (edited(sensors={"magnetometer": {"noise_nT": float("nan")}}),
                               "sensors.magnetometer.noise_nT"),
    "actuators unknown kind": (edited(actuators={"thrusters": {}}), "actuators.thrusters: expected one of the keys"),
    "wheel friction negative": (edited(actuators={"wheels": {"coulomb_friction_Nm": -1.0}}),
                                "actuators.wheels.coulomb_friction_Nm"),
}


@pytest.mark.parametrize("content, words", BAD_SCENARIOS.values(), ids=BAD_SCENARIOS.keys())
def test_a_file_that_is_not_a_valid_scenario_is_a_config_error_naming_file_and_field(tmp_path, content, words):
    path = tmp_path / "hostile_scenario.yaml"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(ConfigError) as err:
        scenario.load(str(path))
    assert isinstance(err.value, ValueError) and err.value.code == ErrorCode.INVALID_CONFIG
    assert "hostile_scenario.yaml" in err.value.message and words in err.value.message, err.value.message
    lines = err.value.message.splitlines()      # every problem, one bounded line each (the path aside)
    assert 1 <= len(lines) <= 10 and all(len(line.replace(str(path), "")) <= 400 for line in lines), lines


def test_the_base_scenario_of_these_cases_is_valid(tmp_path):
    path = tmp_path / "good.yaml"
    path.write_text(yaml.safe_dump(BASE))
    s = scenario.load(str(path))
    assert s.spacecraft.n_wheels == 3 and s.node_params["simulator"]["step_s"] == 0.1
    assert s.spacecraft.body_torque_max == 0.1 and s.orbit.altitude == 500000.0


def test_unknown_names_stay_key_errors_and_the_planner_maps_both(tmp_path, monkeypatch):
    with pytest.raises(KeyError):
        scenario.load("no_such_scenario")
    with pytest.raises(ConfigError) as err:
        scenario.load_checked("no_such_scenario")
    assert err.value.code == ErrorCode.INVALID_CONFIG and "no_such_scenario" in err.value.message
    monkeypatch.setenv("ATT_CONFIG_PATH", str(tmp_path))
    (tmp_path / "typo_craft.yaml").write_text(edited(spacecraft__intertia=[1.0, 1.0, 1.0]))
    for name, code in (("typo_craft", ErrorCode.INVALID_SPACECRAFT), ("missing_craft", ErrorCode.UNKNOWN_SPACECRAFT)):
        with pytest.raises(RequestError) as err:
            load_spacecraft(name)
        assert err.value.code == code and name in err.value.message


# -- nodes started with hostile parameters -------------------------------------------------------

SIM = "simulator"
P, C = "INVALID_PARAMETER", "INVALID_CONFIG"
NODE_CASES = {
    # type
    "real_time_factor text": (SIM, ["-p", "real_time_factor:=fast"], P, ["'real_time_factor'", "a number"]),
    "step text": (SIM, ["-p", "step_s:=abc"], P, ["'step_s'", "a number"]),
    "wait_for_subscribers float": (SIM, ["-p", "wait_for_subscribers:=1.5"], P, ["'wait_for_subscribers'", "integer"]),
    "wait_for_subscribers text": (SIM, ["-p", "wait_for_subscribers:=many"], P, ["'wait_for_subscribers'"]),
    "lockstep integer": (SIM, ["-p", "lockstep:=1"], P, ["'lockstep'", "true or false"]),
    "lockstep text": (SIM, ["-p", "lockstep:=maybe"], P, ["'lockstep'", "true or false"]),
    "gravity_gradient integer": (SIM, ["-p", "gravity_gradient:=2"], P, ["'gravity_gradient'"]),
    "initial_attitude text list": (SIM, ["-p", "initial_attitude:=[a,b,c,d]"], P, ["'initial_attitude'", "list"]),
    "initial_attitude a number": (SIM, ["-p", "initial_attitude:=1.0"], P, ["'initial_attitude'", "list"]),
    "scenario integer": (SIM, ["-p", "scenario:=5"], P, ["'scenario'", "a string"]),
    # range
    "real_time_factor negative": (SIM, ["-p", "real_time_factor:=-1.0"], P, ["'real_time_factor'", "[0, inf]"]),
    "real_time_factor inf": (SIM, ["-p", "real_time_factor:=.inf"], P, ["'real_time_factor'"]),
    "real_time_factor NaN": (SIM, ["-p", "real_time_factor:=.nan"], P, ["'real_time_factor'"]),
    "step zero": (SIM, ["-p", "step_s:=0.0"], P, ["'step_s'", "(0, 1]"]),
    "step 2 s": (SIM, ["-p", "step_s:=2.0"], P, ["'step_s'", "(0, 1]"]),
    "simulator: an old parameter name": (SIM, ["-p", "step:=0.1"], P, ["parameter 'step'", "is renamed 'step_s'"]),
    "publish_rate zero": (SIM, ["-p", "publish_rate_Hz:=0.0"], P, ["'publish_rate_Hz'"]),
    "publish_rate above 1/step": (SIM, ["-p", "publish_rate_Hz:=1000.0"], P, ["'publish_rate_Hz'", "1/step_s"]),
    "clock_rate negative": (SIM, ["-p", "clock_rate_Hz:=-5.0"], P, ["'clock_rate_Hz'"]),
    "tf_rate negative": (SIM, ["-p", "tf_rate_Hz:=-1.0"], P, ["'tf_rate_Hz'", "0: off"]),
    "tf_rate above 1/step": (SIM, ["-p", "tf_rate_Hz:=1000.0"], P, ["'tf_rate_Hz'", "1/step_s"]),
    "tf_rate NaN": (SIM, ["-p", "tf_rate_Hz:=.nan"], P, ["'tf_rate_Hz'"]),
    "marker_rate inf": (SIM, ["-p", "marker_rate_Hz:=.inf"], P, ["'marker_rate_Hz'"]),
    "marker_rate text": (SIM, ["-p", "marker_rate_Hz:=often"], P, ["'marker_rate_Hz'", "a number"]),
    "command_timeout zero": (SIM, ["-p", "command_timeout_s:=0.0"], P, ["'command_timeout_s'"]),
    "end_time negative": (SIM, ["-p", "end_time_s:=-1.0"], P, ["'end_time_s'"]),
    "wait_for_subscribers negative": (SIM, ["-p", "wait_for_subscribers:=-1"], P, ["'wait_for_subscribers'"]),
    "start_timeout zero": (SIM, ["-p", "start_timeout_s:=0.0"], P, ["'start_timeout_s'"]),
    "lockstep_timeout zero": (SIM, ["-p", "lockstep_timeout_s:=0.0"], P, ["'lockstep_timeout_s'"]),
    "initial_attitude norm 2": (SIM, ["-p", "initial_attitude:=[0.0,0.0,0.0,2.0]"], P, ["'initial_attitude'", "norm"]),
    "initial_attitude 3 numbers": (SIM, ["-p", "initial_attitude:=[0.0,0.0,1.0]"], P, ["'initial_attitude'", "4"]),
    "initial_rate 2 numbers": (SIM, ["-p", "initial_rate_rad_s:=[0.0,0.0]"], P, ["'initial_rate_rad_s'", "3"]),
    "initial_rate NaN": (SIM, ["-p", "initial_rate_rad_s:=[.nan,0.0,0.0]"], P, ["'initial_rate_rad_s'"]),
    "initial_rate above max_reset_rate": (SIM, ["-p", "initial_rate_rad_s:=[5.0,0.0,0.0]"], P,
                                          ["'initial_rate_rad_s'", "max_reset_rate_rad_s"]),
    "command_limit_factor below 1": (SIM, ["-p", "command_limit_factor:=0.5"], P, ["'command_limit_factor'"]),
    "max_reset_rate zero": (SIM, ["-p", "max_reset_rate_rad_s:=0.0"], P, ["'max_reset_rate_rad_s'"]),
    "unknown parameter (typo)": (SIM, ["-p", "real_time_facter:=3.0"], P, ["real_time_facter"]),
    # scenario and files
    "unknown scenario": (SIM, ["-p", "scenario:=no_such_scenario"], C, ["'scenario'", "no_such_scenario", "known:"]),
    "scenario that is a gains file": (SIM, ["-p", "scenario:=controller_gains"], C, ["controller_gains.yaml",
                                                                                    "/**: expected this key"]),
    "scenario file a list": (SIM, ["-p", "scenario:={tmp}/list.yaml"], C, ["list.yaml", "a mapping"]),
    "scenario file broken": (SIM, ["-p", "scenario:={tmp}/broken.yaml"], C, ["broken.yaml", "expected valid YAML"]),
    "scenario with a bad simulator value": (SIM, ["-p", "scenario:={tmp}/bad_step.yaml"], P,
                                            ["'step_s'", "bad_step.params.yaml", "(0, 1]"]),
    "scenario with an unknown simulator key": (SIM, ["-p", "scenario:={tmp}/sim_typo.yaml"], P,
                                               ["lockstep_timout", "sim_typo.params.yaml"]),
    "missing --params-file": (SIM, ["--params-file", "no_such_params.yaml"], C,
                              ["no_such_params.yaml", "no such file", "current directory"]),
    "--params-file a directory": (SIM, ["--params-file", "{tmp}"], C, ["no such file"]),
    "--params-file not YAML": (SIM, ["--params-file", "{tmp}/broken.yaml"], C, ["broken.yaml"]),
    "--params-file a list": (SIM, ["--params-file", "{tmp}/list.yaml"], C, ["list.yaml"]),
    "--params-file with a wrong type": (SIM, ["--params-file", "{tmp}/rtf_text.yaml"], P,
                                        ["'real_time_factor'", "a number"]),
    "--params-file with a typo": (SIM, ["--params-file", "{tmp}/typo.yaml"], P, ["real_time_facter"]),
    # the other nodes take the same scenario parameter
    "controller: unknown scenario": ("controller", ["-p", "scenario:=no_such_scenario"], C, ["no_such_scenario"]),
    "controller: not a scenario": ("controller", ["-p", "scenario:=controller_gains"], C,
                                   ["controller_gains.yaml", "/**: expected this key"]),
    "planner: unknown scenario": ("planner", ["-p", "scenario:=no_such_scenario"], C, ["no_such_scenario"]),
    "planner: not a scenario": ("planner", ["-p", "scenario:=controller_gains"], C,
                                ["controller_gains.yaml", "/**: expected this key"]),
    "planner: unknown parameter (typo)": ("planner", ["-p", "time_budgett_s:=5.0"], P, ["time_budgett_s"]),
    "planner: an old parameter name": ("planner", ["-p", "time_budget:=5.0"], P,
                                       ["parameter 'time_budget'", "is renamed 'time_budget_s'"]),
    "controller: an old parameter name": ("controller", ["-p", "settle_time:=5.0"], P,
                                          ["parameter 'settle_time'", "is renamed 'settle_time_s'"]),
    "planner: unknown warm-up scenario": ("planner", ["-p", "warm_up_scenarios:=swift_demo,no_such_scenario"], C,
                                          ["no_such_scenario"]),
    "planner: plan_markers integer": ("planner", ["-p", "plan_markers:=2"], P, ["'plan_markers'", "true or false"]),
    # the simulator's seed, the controller's state source, the estimator's tuning
    "simulator seed negative": (SIM, ["-p", "seed:=-1"], P, ["'seed'"]),
    "simulator seed text": (SIM, ["-p", "seed:=lucky"], P, ["'seed'", "integer"]),
    "controller state_source unknown": ("controller", ["-p", "state_source:=oracle"], P,
                                        ["'state_source'", "truth, estimate"]),
    "controller estimate without tachometers": ("controller", ["-p", "scenario:=olivares_staffetti", "-p",
                                                               "state_source:=estimate"], P,
                                                ["'state_source'", "wheel_tachometer"]),
    "controller plan_wait beyond the client's stall timeout": ("controller", ["-p", "plan_wait_s:=30.0"], P,
                                                              ["'plan_wait_s'", "[0, 10]"]),
    "controller plan_wait NaN": ("controller", ["-p", "plan_wait_s:=.nan"], P, ["'plan_wait_s'"]),
    # a campaign's dispersed truth
    "simulator campaign without run_seed": (SIM, ["-p", "campaign:={tmp}/campaign.yaml"], P,
                                            ["'campaign'", "'run_seed'"]),
    "simulator run_seed without campaign": (SIM, ["-p", "run_seed:=5"], P, ["'campaign'", "'run_seed'"]),
    "simulator run_seed text": (SIM, ["-p", "run_seed:=lucky"], P, ["'run_seed'"]),
    "simulator campaign missing": (SIM, ["-p", "campaign:={tmp}/no_campaign.yaml", "-p", "run_seed:=1"], P,
                                   ["'campaign'", "no_campaign.yaml: (file): expected a readable file"]),
    "simulator campaign of another scenario": (SIM, ["-p", "scenario:=leo_observatory", "-p",
                                                     "campaign:={tmp}/campaign.yaml", "-p", "run_seed:=1"], P,
                                               ["'campaign'", "swift_demo", "leo_observatory"]),
    "simulator campaign with a typo": (SIM, ["-p", "campaign:={tmp}/campaign_typo.yaml", "-p", "run_seed:=1"], P,
                                       ["'campaign'", "inertia_scal"]),
    "simulator campaign run not physical": (SIM, ["-p", "campaign:={tmp}/campaign_wide.yaml", "-p", "run_seed:=0"],
                                            P, ["'campaign'", "run seed 0", "triangle inequality"]),
    "estimator: a scenario without a gyro": ("estimator", ["-p", "scenario:=bruni_celani"], C, ["no gyro"]),
    "estimator: gate probability 1.5": ("estimator", ["-p", "gate_probability:=1.5"], P, ["'gate_probability'"]),
    "estimator: publish_rate above the gyro's": ("estimator", ["-p", "publish_rate_Hz:=100.0"], P,
                                                  ["'publish_rate_Hz'"]),
    "estimator: history zero": ("estimator", ["-p", "history_s:=0.0"], P, ["'history_s'"]),
    "estimator: wait_for_subscribers negative": ("estimator", ["-p", "wait_for_subscribers:=-1"], P,
                                                 ["'wait_for_subscribers'"]),
    "controller: start_timeout zero": ("controller", ["-p", "start_timeout_s:=0.0"], P, ["'start_timeout_s'"]),
    "controller: mode_sequence_ahead zero": ("controller", ["-p", "require_signed_modes:=true", "-p",
                                                            "mode_sequence_ahead_s:=0.0"], P,
                                             ["'mode_sequence_ahead_s'"]),
    "controller: mode_sequence_ahead text": ("controller", ["-p", "require_signed_modes:=true", "-p",
                                                            "mode_sequence_ahead_s:=forever"], P,
                                             ["'mode_sequence_ahead_s'", "a number"]),
    "controller: mode_sequence_file integer": ("controller", ["-p", "require_signed_modes:=true", "-p",
                                                              "mode_sequence_file:=5"], P,
                                               ["'mode_sequence_file'", "a string"]),
    "estimator: unknown parameter (typo)": ("estimator", ["-p", "gate_probabilty:=0.99"], P, ["gate_probabilty"]),
    "estimator: unknown scenario": ("estimator", ["-p", "scenario:=no_such_scenario"], C, ["no_such_scenario"]),
    # the live bridge
    "bridge: port text": ("bridge", ["-p", "port:=http"], P, ["'port'", "integer"]),
    "bridge: port a float": ("bridge", ["-p", "port:=8765.0"], P, ["'port'", "integer"]),
    "bridge: port negative": ("bridge", ["-p", "port:=-1"], P, ["'port'", "[0, 65535]"]),
    "bridge: port above 65535": ("bridge", ["-p", "port:=70000"], P, ["'port'", "[0, 65535]"]),
    "bridge: host a number": ("bridge", ["-p", "host:=5"], P, ["'host'", "a string"]),
    "bridge: host not this machine's": ("bridge", ["-p", "host:=192.0.2.1", "-p", "port:=0"], P,
                                        ["'host'", "192.0.2.1", "cannot serve", "Cannot assign"]),
    "bridge: unknown parameter (typo)": ("bridge", ["-p", "prot:=8765"], P, ["prot"]),
    # every declared parameter is checked, the recorder's too
    "recorder: flush_period zero": ("recorder", ["-p", "flush_period_s:=0.0"], P,
                                    ["'flush_period_s'", "(0, 3600]"]),
    "recorder: flush_period text": ("recorder", ["-p", "flush_period_s:=often"], P,
                                    ["'flush_period_s'", "a number"]),
    "recorder: an old parameter name": ("recorder", ["-p", "flush_period:=0.5"], P,
                                        ["parameter 'flush_period'", "is renamed 'flush_period_s'"]),
    "recorder: unknown parameter (typo)": ("recorder", ["-p", "outptu:=run.mcap"], P, ["outptu"]),
    "recorder: output a directory": ("recorder", ["-p", "output:={tmp}"], C, ["output:", "cannot be written"]),
    "recorder: output under a file": ("recorder", ["-p", "output:={tmp}/list.yaml/run.mcap"], C,
                                      ["output:", "cannot be written"]),
    "recorder: output a file that is not a log": ("recorder", ["-p", "output:={tmp}/list.yaml"], C,
                                                  ["output:", "not an MCAP log", "left as it is"]),
    "controller: m_max zero": ("controller", ["-p", "m_max_Am2:=0.0"], P, ["'m_max_Am2'", "dipole > 0"]),
    "controller: fault_table not there": ("controller", ["-p", "fault_table:=no_such_table"], C,
                                          ["parameter 'fault_table': expected empty", "'no_such_table'",
                                           "which is neither"]),
    "controller: fault_table not a fault table": ("controller", ["-p", "fault_table:={tmp}/list.yaml"], C,
                                                  ["parameter 'fault_table'", "list.yaml"]),
    "controller: fault_table on the truth": ("controller", ["-p", "fault_table:=default", "-p",
                                                            "state_source:=truth"], P,
                                             ["parameter 'fault_table'", "state_source estimate"]),
    "controller: fault_table integer": ("controller", ["-p", "fault_table:=5"], P, ["'fault_table'", "a string"]),
    "estimator: fault_table not there": ("estimator", ["-p", "fault_table:=/no/such/faults.yaml"], C,
                                         ["parameter 'fault_table': expected empty", "/no/such/faults.yaml"]),
    "planner: default_method unknown": ("planner", ["-p", "default_method:=magic"], P,
                                        ["'default_method'", "(the best)", "magic"]),
    "simulator: step an integer out of range": (SIM, ["-p", "step_s:=2"], P, ["'step_s'", "(0, 1]"]),
}
RCL_PARSE_ERROR = re.compile(r"^\[ERROR\] \[[\d.]+\] \[rcl\]: Failed to parse global arguments$")
REFUSAL = re.compile(r"^(\w+)\.py: \[(\d+) (\w+)\] (.+)$")


def write_files(tmp: Path) -> None:
    shipped = Path(scenario.__file__).resolve().parents[2] / "config" / "scenarios"
    sky, params = (shipped / "swift_demo.yaml").read_text(), (shipped / "swift_demo.params.yaml").read_text()

    def swift_with(name: str, tuning: str) -> None:
        """swift_demo's scenario (naming the shipped spacecraft) with its node tuning ``tuning`` beside it."""
        (tmp / f"{name}.yaml").write_text(sky)
        (tmp / f"{name}.params.yaml").write_text(tuning)
    (tmp / "list.yaml").write_text("- 1\n- 2\n")
    (tmp / "broken.yaml").write_text("{{{ not yaml\n")
    swift_with("bad_step", params.replace("step_s: 0.05 ", "step_s: 5.0 "))
    swift_with("sim_typo", params.replace("lockstep_timeout_s:", "lockstep_timout_s:"))
    (tmp / "rtf_text.yaml").write_text("simulator:\n  ros__parameters:\n    real_time_factor: fast\n")
    (tmp / "typo.yaml").write_text("simulator:\n  ros__parameters:\n    real_time_facter: 2.0\n")
    (tmp / "rtf3.yaml").write_text("simulator:\n  ros__parameters:\n    real_time_factor: 3\n")
    swift_with("mine", params.replace("real_time_factor: 8.0", "real_time_factor: 5.0"))
    scale = "{distribution: uniform, low: -0.9, high: 2.0}"
    for name, dispersions in (("campaign", "{}"), ("campaign_typo", f"{{inertia_scal: {scale}}}"),
                              ("campaign_wide", f"{{inertia_scale: {scale}}}")):
        (tmp / f"{name}.yaml").write_text(f"campaign: {{scenario: swift_demo, seed: 1, dispersions: {dispersions}}}\n")


def start(node: str, args: list, cwd: Path | None = None, output=subprocess.PIPE) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", NODE_MODULES[node], "--ros-args", *args], env=isolated_env(),
                            cwd=cwd, stdout=output, stderr=subprocess.STDOUT if output is not subprocess.PIPE
                            else subprocess.PIPE, text=True)


def run_case(node: str, args: list) -> tuple[int | None, str]:
    """Exit code (None: still running after 30 s, then killed) and stderr + stdout."""
    proc = start(node, args)
    try:
        out, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        return None, err + out
    return proc.returncode, err + out


@pytest.fixture(scope="module")
def node_results(tmp_path_factory):
    """Every case of NODE_CASES, three at a time: the first in its own interpreter (``python -m``,
    as a user starts it), the others forked from one that imported the nodes once
    (:mod:`forked_nodes`: the same ``main()``, argv, environment and file descriptors)."""
    tmp = tmp_path_factory.mktemp("hostile_config")
    write_files(tmp)
    cases = {name: (node, [a.replace("{tmp}", str(tmp)) for a in args])
             for name, (node, args, _, _) in NODE_CASES.items()}
    first = next(iter(cases))
    ctx = forked_nodes.context()
    with ThreadPoolExecutor(max_workers=3) as pool:
        futures = {name: pool.submit(run_case, node, args) if name == first else
                   pool.submit(forked_nodes.run_case, ctx, NODE_MODULES[node], args, isolated_env(),
                               str(tmp / f"case_{i}.log"))
                   for i, (name, (node, args)) in enumerate(cases.items())}
        return {name: f.result() for name, f in futures.items()}


@pytest.mark.ros
@pytest.mark.parametrize("name", NODE_CASES)
def test_a_node_with_a_hostile_parameter_prints_one_line_and_exits_2(node_results, name):
    node, _, code_name, words = NODE_CASES[name]
    exit_code, output = node_results[name]
    assert exit_code == 2, f"exit {exit_code}:\n{output}"
    assert "Traceback" not in output, output
    lines = [ln for ln in output.splitlines() if ln.strip() and not RCL_PARSE_ERROR.match(ln)]
    assert len(lines) == 1, output
    match = REFUSAL.match(lines[0])
    assert match and match.group(1) == NODE_MODULES[node].rsplit(".", 1)[1], lines[0]
    assert match.group(3) == code_name and int(match.group(2)) == ErrorCode[code_name], lines[0]
    assert all(w in match.group(4) for w in words), lines[0]
    assert len(lines[0]) <= 450


@pytest.mark.ros
def test_a_status_the_forkserver_lost_is_taken_from_a_real_run_never_from_the_child(tmp_path):
    """Where the forkserver reports 255 ("status lost"), the harness runs the case as ``python -m``
    and takes that process's exit status and output."""
    class Lost:                                    # a forked child whose status pipe gave EOF
        exitcode = 255

        def start(self):
            pass

        def join(self, timeout=None):
            pass

    ctx = type("LostContext", (), {"Process": staticmethod(lambda **_: Lost())})()
    node, args, code_name, words = NODE_CASES["real_time_factor text"]
    exit_code, output = forked_nodes.run_case(ctx, NODE_MODULES[node], args, isolated_env(), str(tmp_path / "case.log"))
    assert exit_code == 2, f"exit {exit_code}:\n{output}"
    assert code_name in output and all(w in output for w in words), output


def test_there_are_enough_distinct_hostile_configurations():
    assert len(BAD_SCENARIOS) + len(NODE_CASES) >= 70


@pytest.mark.ros
def test_good_values_start_the_simulator(tmp_path):
    """An integer for a float, and --params-file and scenario paths relative to the current
    directory, start the node (which then stops cleanly on SIGINT)."""
    write_files(tmp_path)
    cases = [(["-p", "real_time_factor:=0"], "RTF max"),
             (["--params-file", "rtf3.yaml"], "RTF 3.0"),
             (["-p", "scenario:=./mine.yaml"], "scenario 'mine', step 0.05 s, RTF 5.0"),
             (["-p", "initial_attitude:=[0,0,0,1]", "-p", "command_limit_factor:=1"], "scenario 'swift_demo'")]
    logs = [tmp_path / f"good_{i}.log" for i in range(len(cases))]
    procs = [start(SIM, args, cwd=tmp_path, output=open(log, "w")) for (args, _), log in zip(cases, logs)]
    try:
        for proc, log, (_, words) in zip(procs, logs, cases):
            end = time.monotonic() + 40
            while words not in log.read_text() and time.monotonic() < end and proc.poll() is None:
                time.sleep(0.2)     # wait-ok: poll period of a wait on the log's words or the node's exit (40 s)
            assert words in log.read_text(), f"exit {proc.poll()}: {log.read_text()}"
    finally:
        for proc in procs:
            proc.send_signal(signal.SIGINT)
        codes = [proc.wait(20) for proc in procs]
    assert codes == [0] * len(cases)


@pytest.mark.ros
def test_a_simulator_started_by_hand_waits_for_its_subscribers(ros_suite):
    """``-p wait_for_subscribers:=2``: sim time stays at 0 while one subscriber listens; with the
    second the run starts, and the first state either sees is the one at t = 0."""
    with ros_suite("swift_demo", nodes=("simulator",), params={"simulator": {"wait_for_subscribers": 2}},
                   name="wait_subs") as s:
        first, second = [], []
        s.client.create_subscription(SpacecraftState, topics.STATE, first.append, qos.STREAM_QOS)
        end = time.monotonic() + 3.0
        while time.monotonic() < end:
            rclpy.spin_once(s.client, timeout_sec=0.05)
        assert not first, "the simulator started with one of two subscribers"
        s.client.create_subscription(SpacecraftState, topics.STATE, second.append, qos.STREAM_QOS)
        end = time.monotonic() + 10.0
        while time.monotonic() < end and not (first and second):
            rclpy.spin_once(s.client, timeout_sec=0.05)
        assert first and second, "no state after the second subscriber came"
        assert convert.from_time(first[0].header.stamp) == 0.0 and convert.from_time(second[0].header.stamp) == 0.0


@pytest.mark.ros
def test_a_controller_takes_its_inputs_once_its_commands_are_heard(ros_suite):
    """``-p wait_for_subscribers:=2`` on the controller: no subscription to the state while fewer
    than two subscriptions hear its commands; with the second it subscribes."""
    with ros_suite("swift_demo", nodes=("controller",), name="wait_heard",
                   params={"controller": {"wait_for_subscribers": 2, "state_source": "truth"}}) as s:
        def state_subscribers(seconds):
            end = time.monotonic() + seconds
            while time.monotonic() < end and not s.client.count_subscribers(topics.STATE):
                rclpy.spin_once(s.client, timeout_sec=0.05)
            return s.client.count_subscribers(topics.STATE)

        s.client.create_subscription(ActuatorCommand, topics.COMMAND, lambda _: None, qos.STREAM_QOS)
        assert state_subscribers(4.0) == 0, "the controller took its inputs with one of two listeners"
        s.client.create_subscription(ActuatorCommand, topics.COMMAND, lambda _: None, qos.STREAM_QOS)
        assert state_subscribers(10.0) == 1, "the controller did not take its inputs after the second listener"
