"""Markdown reference of a node's parameters, from their declarations (no ROS): one table per node
with each parameter's name, type, default, range or other constraints, unit and description."""
from __future__ import annotations

from att_msgs_py.parameters import Parameter, ParameterTable

TYPE_NAMES = {float: "double", int: "integer", bool: "bool", str: "string", list: "double[]"}   # as ROS names them
COLUMNS = ("parameter", "type", "default", "range / constraints", "unit", "description")


def _cell(text: str) -> str:
    """``text`` safe in a Markdown table cell: one line, ``|`` escaped, ``<`` not read as HTML."""
    return " ".join(str(text).split()).replace("|", "\\|").replace("<", "&lt;")


def row(spec: Parameter) -> tuple[str, ...]:
    """The table row of ``spec``, in the order of :data:`COLUMNS`."""
    default = spec.default_text()
    return (f"`{spec.name}`", TYPE_NAMES[spec.kind], f"`{default}`" if spec.default is not None else default,
            spec.constraints(), spec.unit, spec.description + ("" if spec.read_only else " (settable at run time)"))


def markdown_table(table: ParameterTable) -> str:
    """``table`` as a Markdown table alone: a header, then one row per parameter, in declaration
    order (for a page that has its own heading)."""
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(_cell(c) for c in row(spec)) + " |" for spec in table]
    return "\n".join(lines) + "\n"


def markdown(table: ParameterTable, heading: str | None = None, level: int = 2) -> str:
    """``table`` as a Markdown section: a heading (default: the node's name), its summary, then
    :func:`markdown_table`."""
    lines = [f"{'#' * level} {heading or table.node}", ""]
    if table.summary:
        lines += [table.summary[0].upper() + table.summary[1:] + ".", ""]
    return "\n".join(lines) + "\n" + markdown_table(table)


def markdown_all(tables: dict[str, ParameterTable], level: int = 2) -> str:
    """Every node's section (``tables``: node name -> table), in the given order."""
    return "\n".join(markdown(t, name, level) for name, t in tables.items())
