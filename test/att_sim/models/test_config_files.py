"""The configuration loader: lines, field paths, every problem at once, renames, the YAML guards."""
from __future__ import annotations

import math
from typing import ClassVar

import pytest
from pydantic import Field

from att_msgs_py.errors import ConfigError, ErrorCode
from att_sim.models import config_files as cf
from att_sim.models.config_base import Schema


class Wheel(Schema):
    renamed: ClassVar = {"torque_max": "torque_max_Nm"}
    torque_max_Nm: float = Field(gt=0.0)
    axis: list[float] = Field(min_length=3, max_length=3)


class Craft(Schema):
    name: str
    mass_kg: float = Field(10.0, gt=0.0)
    wheels: list[Wheel] = []


def refused(tmp_path, text, model=Craft, name="f.yaml") -> cf.ConfigFileError:
    path = tmp_path / name
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(cf.ConfigFileError) as err:
        cf.load_file(path, model)
    assert isinstance(err.value, ConfigError) and err.value.code == ErrorCode.INVALID_CONFIG
    return err.value


def test_valid_file_keeps_lines_and_defaults(tmp_path):
    path = tmp_path / "ok.yaml"
    path.write_text("# a craft\nname: sat\nwheels:\n  - {torque_max_Nm: 0.1, axis: [1, 0, 0]}\n")
    loaded = cf.load_file(path, Craft)
    assert loaded.model.mass_kg == 10.0 and loaded.model.wheels[0].torque_max_Nm == 0.1
    assert loaded.lines[("name",)] == 2 and loaded.lines[("wheels", 0, "torque_max_Nm")] == 4
    assert ("mass_kg",) not in loaded.lines


def test_every_problem_at_once_with_line_and_path(tmp_path):
    text = ("name: sat\nmass_kg: -1\nwheels:\n  - {torque_max_Nm: 0.1, axis: [1, 0, 0]}\n"
            "  - {torque_max_Nm: fast, axis: [1, 0]}\n  - {torque_max: 0.2, axis: [0, 0, 1]}\ncolour: red\n")
    err = refused(tmp_path, text)
    got = {(p.line, p.field) for p in err.problems}
    assert got == {(2, "mass_kg"), (5, "wheels[1].torque_max_Nm"), (5, "wheels[1].axis"),
                   (6, "wheels[2].torque_max"), (7, "colour")}, err.message
    by_field = {p.field: p for p in err.problems}
    assert "greater than 0" in by_field["mass_kg"].expected and by_field["mass_kg"].found == "-1"
    assert by_field["wheels[1].torque_max_Nm"].found == "'fast'"
    assert "renamed to 'torque_max_Nm'" in by_field["wheels[2].torque_max"].expected
    assert "colour" in by_field["colour"].found and "mass_kg" in by_field["colour"].expected
    lines = err.message.splitlines()
    assert len(lines) == 5 and all(line.startswith(str(tmp_path)) for line in lines)


def test_missing_key_names_the_key(tmp_path):
    err = refused(tmp_path, "mass_kg: 3\n")
    assert [(p.line, p.field, p.found) for p in err.problems] == [(1, "name", "nothing")]


@pytest.mark.parametrize("text, line, words", [
    ("a: &x [1]\nb: *x\n", 1, "anchor"),
    ("name: sat\nname: sat2\n", 2, "duplicate of the key on line 1"),
    ("- 1\n- 2\n", 1, "a list"),
    ("just text\n", 1, "the value"),
    ("", 1, "an empty file"),
    ("# only a comment\n", 1, "an empty file"),
    ("name: [unclosed\n", 2, "valid YAML"),
    ("name: !!python/object:os.system x\n", 1, "tag"),
    ("? [1, 2]\n: 3\n", 1, "used as a key"),
    (b"name: caf\xe9\n", 1, "0xe9"),
])
def test_yaml_guards(tmp_path, text, line, words):
    err = refused(tmp_path, text)
    assert len(err.problems) == 1 and err.problems[0].line == line, err.message
    assert words in str(err.problems[0]), err.message


def test_size_cap_before_parsing(tmp_path):
    err = refused(tmp_path, "name: x\n" + "#" * (cf.MAX_FILE_BYTES + 1))
    assert "bytes" in err.message and err.problems[0].line is None


def test_missing_file(tmp_path):
    with pytest.raises(cf.ConfigFileError, match="readable file"):
        cf.load_file(tmp_path / "none.yaml", Craft)


def test_message_bounded(tmp_path):
    text = "name: x\n" + "".join(f"k{i}: 1\n" for i in range(3 * cf.MAX_PROBLEMS))
    err = refused(tmp_path, text)
    assert len(err.problems) == 3 * cf.MAX_PROBLEMS
    assert len(err.message.splitlines()) == cf.MAX_PROBLEMS + 1 and "more problem" in err.message


def test_nan_reported_as_nan(tmp_path):
    err = refused(tmp_path, "name: x\nmass_kg: .nan\n")
    assert err.problems[0].found == "nan" and err.problems[0].field == "mass_kg"
    assert math.isnan(float(err.problems[0].found))


def test_renamed_text_rewrites_old_keys_only(tmp_path):
    text = "name: sat  # torque_max: in a comment stays\nwheels:\n  - {torque_max: 0.2, axis: [0, 0, 1]}\n"
    err = refused(tmp_path, text)
    fixed = cf.renamed_text(text, err.problems)
    assert fixed == text.replace("{torque_max:", "{torque_max_Nm:")
    one = cf.Problem("f", 1, "torque_max", "", "", ("torque_max", "torque_max_Nm"))
    assert cf.renamed_text("torque_max: 1      # N m\n", [one]) == "torque_max_Nm: 1   # N m\n"
    path = tmp_path / "fixed.yaml"
    path.write_text(fixed)
    assert cf.load_file(path, Craft).model.wheels[0].torque_max_Nm == 0.2


def test_field_path():
    assert cf.field_path(("a", "b", 2, "c")) == "a.b[2].c" and cf.field_path(()) == ""


def test_yaml_12_exponents_are_numbers(tmp_path):
    path = tmp_path / "e.yaml"
    path.write_text("name: x\nmass_kg: 7.0e6\n")
    assert cf.load_file(path, Craft).model.mass_kg == 7.0e6
    path.write_text("name: 1e3\n")
    with pytest.raises(cf.ConfigFileError, match="name: expected a valid string; found 1000.0"):
        cf.load_file(path, Craft)


def test_aliases_when_asked_are_bounded(tmp_path):
    """A reader of files written by yaml.safe_dump accepts its anchors; an alias bomb stays refused."""
    path = tmp_path / "a.yaml"
    path.write_text("a: &x [1, 2]\nb: *x\n")
    assert cf.read_yaml(path, aliases=True)[0] == {"a": [1, 2], "b": [1, 2]}
    bomb = "a: &a [" + ", ".join(["x"] * 10) + "]\n"
    for name, below in zip("bcdefg", "abcdef"):
        bomb += f"{name}: &{name} [" + ", ".join([f"*{below}"] * 10) + "]\n"
    path.write_text(bomb)
    with pytest.raises(cf.ConfigFileError, match="alias bomb"):
        cf.read_yaml(path, aliases=True)
