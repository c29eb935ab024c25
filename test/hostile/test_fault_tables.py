"""Hostile fault table files: each refused by the loader and ``att-config check`` with its file, line
and field path, with what was expected (an unknown detector or response, a threshold ≤ 0, a negative
persistence, a response that does not fit its detector's component, an id written twice...)."""
from __future__ import annotations

import pytest

from att_msgs_py.errors import ErrorCode
from att_planner.fdir import table
from att_planner.tools import config_cli
from att_sim.models.config_files import ConfigFileError

BASE = """\
faults:
  wheel_torque:
    detector: wheel_torque
    threshold_Nm: 0.01
    persistence_s: 0.5
    response: exclude_wheel
  tracker_inconsistent:
    detector: tracker_innovation
    threshold: 21.1
    persistence_s: 1.0
    readmit_s: 30.0
    response: exclude_sensor
  attitude_error:
    detector: attitude_error
    threshold_deg: 10.0
    persistence_s: 10.0
    response: safe_mode
"""

THRESHOLD = "    threshold_Nm: 0.01\n"

# name: (text replaced, its replacement, line, field path, words of what was expected or found)
EDITS = {
    "unknown detector": ("detector: wheel_torque", "detector: wheel_temperature", 3, "faults.wheel_torque.detector",
                         "'wheel_torque'"),
    "unknown response": ("response: exclude_wheel", "response: reboot", 6, "faults.wheel_torque.response",
                         "'exclude_wheel'"),
    "response of another component": ("response: exclude_wheel", "response: exclude_sensor", 2,
                                      "faults.wheel_torque", "fits detector wheel_torque's component wheel"),
    "safe mode excluding a wheel": ("response: safe_mode", "response: exclude_wheel", 13, "faults.attitude_error",
                                    "(one of report, safe_mode)"),
    "threshold zero": ("threshold_Nm: 0.01", "threshold_Nm: 0.0", 4, "faults.wheel_torque.threshold_Nm",
                       "greater than 0"),
    "threshold negative": ("threshold: 21.1", "threshold: -21.1", 9, "faults.tracker_inconsistent.threshold",
                           "greater than 0"),
    "threshold NaN": ("threshold_deg: 10.0", "threshold_deg: .nan", 15, "faults.attitude_error.threshold_deg",
                      "nan"),
    "threshold a word": ("threshold_Nm: 0.01", "threshold_Nm: small", 4, "faults.wheel_torque.threshold_Nm",
                         "valid number"),
    "threshold of another unit": ("threshold_Nm: 0.01", "threshold_deg: 0.01", 4, "faults.wheel_torque.threshold_deg",
                                  "threshold_Nm"),
    "threshold missing": ("    threshold_Nm: 0.01\n", "", 2, "faults.wheel_torque.threshold_Nm", "required"),
    "persistence negative": ("persistence_s: 0.5", "persistence_s: -0.5", 5, "faults.wheel_torque.persistence_s",
                             "greater than or equal to 0"),
    "persistence in ms": ("persistence_s: 0.5", "persistence_ms: 500", 5, "faults.wheel_torque.persistence_ms",
                          "persistence_s"),
    "readmit negative": ("readmit_s: 30.0", "readmit_s: -1.0", 11, "faults.tracker_inconsistent.readmit_s",
                         "greater than or equal to 0"),
    "readmit on a wheel": ("    persistence_s: 0.5\n", "    persistence_s: 0.5\n    readmit_s: 3.0\n", 6,
                           "faults.wheel_torque.readmit_s", "one of the keys"),
    "id with a space": ("  attitude_error:\n", "  attitude error:\n", 13, "faults.attitude error",
                        "match pattern"),
    "faults a list": ("faults:\n  wheel_torque:\n", "faults:\n- wheel_torque:\n", 1, "faults", "valid dictionary"),
    "gain tolerance negative": (THRESHOLD, THRESHOLD + "    drive_gain_tolerance: -0.1\n", 5,
                                "faults.wheel_torque.drive_gain_tolerance", "greater than or equal to 0"),
    "gain tolerance of one": (THRESHOLD, THRESHOLD + "    drive_gain_tolerance: 1.0\n", 5,
                              "faults.wheel_torque.drive_gain_tolerance", "less than 1"),
    "gain tolerance NaN": (THRESHOLD, THRESHOLD + "    drive_gain_tolerance: .nan\n", 5,
                           "faults.wheel_torque.drive_gain_tolerance", "nan"),
    "gain tolerance in percent": (THRESHOLD, THRESHOLD + "    drive_gain_tolerance_pct: 10\n", 5,
                                  "faults.wheel_torque.drive_gain_tolerance_pct", "drive_gain_tolerance"),
    "inertia tolerance a word": (THRESHOLD, THRESHOLD + "    wheel_inertia_tolerance: five percent\n", 5,
                                 "faults.wheel_torque.wheel_inertia_tolerance", "valid number"),
    "inertia tolerance on a tracker": ("    readmit_s: 30.0\n",
                                       "    readmit_s: 30.0\n    wheel_inertia_tolerance: 0.05\n", 12,
                                       "faults.tracker_inconsistent.wheel_inertia_tolerance", "one of the keys"),
    "tolerances that hide a dead wheel": (THRESHOLD, THRESHOLD + "    drive_gain_tolerance: 0.6\n"
                                          "    wheel_inertia_tolerance: 0.5\n", 2, "faults.wheel_torque",
                                          "a wheel that delivers no torque would pass as healthy"),
}


def refused_with_file_line_and_field(base, name, edit, tmp_path):
    """``base`` with ``edit`` = (old, new, line, field, words) applied: the configuration checker
    refuses it at that line and field with those words, and the runtime reader refuses it too."""
    old, new, line, field, words = edit
    assert old in base, f"case {name}: {old!r} is not in the base"
    path = tmp_path / "faults" / "hostile.yaml"
    path.parent.mkdir()
    path.write_text(base.replace(old, new, 1))
    kind, problems = config_cli.check_file(path)
    assert kind == "faults" and problems, f"{name}: accepted"
    mine = [p for p in problems if p.field == field]
    assert mine, f"{name}: no problem at {field}: " + "\n".join(map(str, problems))
    p = mine[0]
    assert p.file == str(path) and p.line == line and words in p.expected + " " + p.found, str(p)
    with pytest.raises(ConfigFileError) as err:      # the runtime reader refuses it the same way
        table.read(path)
    assert err.value.code == ErrorCode.INVALID_CONFIG and str(path) in str(err.value)


@pytest.mark.parametrize("name", sorted(EDITS))
def test_hostile_fault_table_refused_with_file_line_and_field(name, tmp_path):
    refused_with_file_line_and_field(BASE, name, EDITS[name], tmp_path)


def test_an_id_written_twice_is_refused_on_its_second_line(tmp_path):
    path = tmp_path / "twice.yaml"
    path.write_text(BASE + "  wheel_torque:\n    detector: wheel_torque\n    threshold_Nm: 0.02\n"
                           "    persistence_s: 0.5\n    response: report\n")
    with pytest.raises(ConfigFileError) as err:
        table.read(path)
    (p,) = err.value.problems
    assert (p.file, p.line, p.field) == (str(path), 18, "faults.wheel_torque")
    assert "duplicate of the key on line 2" in p.found


def test_every_problem_of_a_table_at_once(tmp_path):
    path = tmp_path / "many.yaml"
    path.write_text(BASE.replace("threshold_Nm: 0.01", "threshold_Nm: -1").replace("persistence_s: 10.0",
                                                                                    "persistence_s: -2")
                    .replace("detector: tracker_innovation", "detector: star_counter"))
    with pytest.raises(ConfigFileError) as err:
        table.read(path)
    assert [(p.line, p.field) for p in err.value.problems] == [
        (4, "faults.wheel_torque.threshold_Nm"), (8, "faults.tracker_inconsistent.detector"),
        (16, "faults.attitude_error.persistence_s")]


def test_the_base_and_the_shipped_table_pass(tmp_path):
    path = tmp_path / "base.yaml"
    path.write_text(BASE)
    assert config_cli.check_file(path, "faults") == ("faults", [])
    shipped = table.read()
    assert set(shipped.faults) >= {"wheel_torque", "tracker_inconsistent", "tracker_outage", "gyro_axis_frozen",
                                   "gyro_bias_step", "magnetometer_frozen", "attitude_error", "rate_error"}
    assert {e.detector for e in shipped.faults.values()} == set(table.DETECTORS)


GLR_BASE = """\
faults:
  tracker_step:
    detector: tracker_step
    threshold: 40.0
    window_s: 12.0
    onset_s: 4.0
    persistence_s: 1.0
    response: exclude_sensor
  gyro_rate_step:
    detector: gyro_ramp
    threshold: 40.0
    persistence_s: 0.4
    response: safe_mode
  coil_open:
    detector: coil_torque
    threshold: 30.0
    persistence_s: 2.0
    window_s: 60.0
    response: report
"""

# the detectors comparing each tracker with the gyro's propagation: (text replaced, its replacement, line,
# field path, words of what was expected or found)
GLR_EDITS = {
    "onset beyond the window": ("onset_s: 4.0", "onset_s: 12.0", 2, "faults.tracker_step",
                                "onset_s below window_s"),
    "window zero": ("window_s: 12.0", "window_s: 0", 5, "faults.tracker_step.window_s", "greater than 0"),
    "window of hours": ("window_s: 12.0", "window_s: 7200", 5, "faults.tracker_step.window_s",
                        "less than or equal to 600"),
    "threshold zero": ("threshold: 40.0\n    window_s", "threshold: 0\n    window_s", 4,
                       "faults.tracker_step.threshold", "greater than 0"),
    "threshold in a unit": ("threshold: 40.0\n    persistence_s", "threshold_deg: 40.0\n    persistence_s", 11,
                            "faults.gyro_rate_step.threshold_deg", "threshold"),
    "gyro excluded as a sensor": ("response: safe_mode", "response: exclude_sensor", 9, "faults.gyro_rate_step",
                                  "(one of report, safe_mode)"),
    "tracker excluding a wheel": ("response: exclude_sensor", "response: exclude_wheel", 2, "faults.tracker_step",
                                  "fits detector tracker_step's component star_tracker"),
    "onset a word": ("onset_s: 4.0", "onset_s: soon", 6, "faults.tracker_step.onset_s", "valid number"),
    "coil excluded as a sensor": ("response: report", "response: exclude_sensor", 14, "faults.coil_open",
                                  "(one of report, safe_mode)"),
    "coil window negative": ("window_s: 60.0", "window_s: -60.0", 18, "faults.coil_open.window_s",
                             "greater than 0"),
    "coil threshold missing": ("    threshold: 30.0\n", "", 14, "faults.coil_open.threshold", "required"),
    "coil with an onset": ("window_s: 60.0", "window_s: 60.0\n    onset_s: 4.0", 19, "faults.coil_open.onset_s",
                           "one of the keys"),
}


@pytest.mark.parametrize("name", sorted(GLR_EDITS))
def test_hostile_tracker_gyro_entry_refused_with_file_line_and_field(name, tmp_path):
    refused_with_file_line_and_field(GLR_BASE, name, GLR_EDITS[name], tmp_path)


def test_the_tracker_gyro_base_passes_with_its_defaults(tmp_path):
    path = tmp_path / "glr.yaml"
    path.write_text(GLR_BASE)
    assert config_cli.check_file(path, "faults") == ("faults", [])
    ramp = table.read(path).faults["gyro_rate_step"]
    assert (ramp.window_s, ramp.onset_s) == (12.0, 4.0)
