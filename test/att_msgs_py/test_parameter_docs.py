"""The Markdown table of a node's parameters: one row per declaration, cells that stay cells."""
from __future__ import annotations

from att_msgs_py.parameter_docs import COLUMNS, markdown, markdown_table
from att_msgs_py.parameters import Parameter, ParameterTable

TABLE = ParameterTable("demo", (
    Parameter("gain", float, 0.5, "a gain | with a pipe and a <tag>", "1/s", 0.0, 1.0, high_open=True),
    Parameter("path", str, None, "a file", default_rule="a_file_in\nthe state directory"),
), "a demo node")


def test_a_table_has_a_heading_its_summary_and_one_row_per_declaration():
    lines = markdown(TABLE, level=3).splitlines()
    assert lines[0] == "### demo" and lines[2] == "A demo node."
    assert lines[4] == "| " + " | ".join(COLUMNS) + " |"
    assert lines[6] == "| `gain` | double | `0.5` | in [0, 1) | 1/s | a gain \\| with a pipe and a &lt;tag> |"
    assert lines[7] == "| `path` | string | a_file_in the state directory |  |  | a file |"
    assert len(lines) == 8


def test_the_table_alone_is_the_sections_table():
    alone = markdown_table(TABLE)
    assert markdown(TABLE).endswith("\n\n" + alone) and alone.startswith("| parameter |")
    assert len(alone.splitlines()) == 2 + len(TABLE)
