"""The documentation builds with Sphinx and MyST with every warning an error, and its generated pages
hold what the code declares (error codes, planning methods, node topics and parameters)."""
from __future__ import annotations

import os
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def build(out: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q", "-E",
                           "-d", str(out / "doctrees"), str(DOCS), str(out / "html")],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=240)


def test_the_documentation_builds_without_a_warning(tmp_path):
    run = build(tmp_path)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    html = (tmp_path / "html" / "errors.html").read_text()
    from att_msgs_py.errors import ErrorCode
    for code in ErrorCode:                      # every code of the enum is on the generated page
        assert f"<td><p>{int(code)}</p></td>" in html and code.name in html, code
    from att_planner.methods import REGISTRY
    methods = (tmp_path / "html" / "planning-methods.html").read_text()
    for method in REGISTRY:                     # every registered method and each of its options
        assert f'id="{method.name.replace("_", "-")}"' in methods, method.name
        assert all(f"<code class=\"docutils literal notranslate\"><span class=\"pre\">{o}</span></code>" in methods
                   for o in method.options), method.name
    from att_msgs_py import topics
    nodes = "".join(page.read_text() for page in (tmp_path / "html" / "nodes").glob("*.html"))
    for name in topics.ABOUT:                   # every topic, service and action is on a node's page
        assert f"<span class=\"pre\">{name}</span>" in nodes, name


class _Tables(HTMLParser):
    """The text of every cell of every table of an HTML page: tables -> rows -> cells."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tables: list[list[list[str]]] = []
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.tables[-1][-1].append(" ".join("".join(self._cell).split()))
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def _parameter_rows(page: Path) -> dict[str, list[str]]:
    """Parameter name -> its row's cells, from the parameter table of a built node page."""
    from att_msgs_py.parameter_docs import COLUMNS
    parser = _Tables()
    parser.feed(page.read_text())
    tables = [t for t in parser.tables if t and tuple(t[0]) == COLUMNS]
    assert len(tables) == 1, f"{page.name}: {len(tables)} parameter tables"
    return {row[0]: row for row in tables[0][1:]}


def test_every_declared_parameter_is_on_its_node_s_page(tmp_path):
    run = build(tmp_path)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        import att_docs
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    from att_planner.tools.node_parameters import NODE_PARAMETERS, declared
    assert set(att_docs.NODES) == set(NODE_PARAMETERS)
    for node in att_docs.NODES:
        rows = _parameter_rows(tmp_path / "html" / "nodes" / f"{node}.html")
        table = declared(node)
        assert list(rows) == [spec.name for spec in table], node      # every one, in order, none other
        for spec in table:
            _, kind, default, constraints, unit, description = rows[spec.name]
            where = f"{node}.{spec.name}"
            assert default == spec.default_text(), where
            assert constraints == " ".join(spec.constraints().split()), where
            assert unit == spec.unit and description.startswith(" ".join(spec.description.split())), where
            if spec.bounded:                                            # its range, as the node checks it
                assert spec.interval() in constraints or spec.refusal, where


def test_every_error_code_has_a_meaning():
    from att_msgs_py.error_meanings import MEANINGS
    from att_msgs_py.errors import ErrorCode
    assert set(MEANINGS) == set(ErrorCode)
    assert all(text.strip() for text in MEANINGS.values())


def test_node_pages_read_each_node_s_endpoints_from_its_source():
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        import att_docs
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    from att_planner.tools.launch import NODE_MODULES
    rows = {node: {(r[0], r[1].strip("`"), r[2].strip("`")) for r in att_docs.node_interfaces(NODE_MODULES[node])}
            for node in att_docs.NODES}
    assert ("serves (action)", "/controller/execute", "att_msgs/action/ExecuteManeuver") in rows["controller"]
    assert ("serves (service)", "/simulator/reset", "att_msgs/srv/ResetSimulator") in rows["simulator"]
    assert ("serves (service)", "/simulator/hold", "std_srvs/srv/SetBool") in rows["simulator"]
    # the simulator publishes a sensor's topic only when the scenario has that sensor
    assert ("publishes (when configured)", "/sensors/imu", "sensor_msgs/msg/Imu") in rows["simulator"]
    assert ("publishes", "/estimator/attitude", "att_msgs/msg/AttitudeEstimate") in rows["estimator"]
    from att_msgs_py.topics import RECORDED
    assert {r[1] for r in rows["recorder"]} == set(RECORDED)


def _is_list(annotation) -> bool:
    """Whether a field's annotation is a list (under ``Annotated`` and ``| None``)."""
    import types
    import typing
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Annotated:
        return _is_list(args[0])
    if origin in (typing.Union, types.UnionType):
        return any(_is_list(a) for a in args if a is not type(None))
    return origin is list


def _config_keys(annotation, path: str, seen: set) -> list[tuple[str, object]]:
    """(key path, FieldInfo) of every key reachable from a model or a union of models, each model once."""
    import typing

    from pydantic import BaseModel
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        if annotation in seen:
            return []
        seen.add(annotation)
        out = []
        for name, info in annotation.model_fields.items():
            key = f"{path}{info.alias or name}"
            out.append((key, info))
            out += _config_keys(info.annotation, key + ("[]." if _is_list(info.annotation) else "."), seen)
        return out
    return [k for arg in typing.get_args(annotation) for k in _config_keys(arg, path, seen)]


def _config_row_problem(row: list[str], info) -> str | None:
    """Why a row of a configuration page does not show the field ``info`` (None when it does)."""
    import math
    import re

    import yaml
    from pydantic import BaseModel
    _, _, unit, default, bounds, meaning, old = row
    if info.is_required():
        if default != "required":
            return f"default {default!r}, not required"
    else:
        value = info.get_default(call_default_factory=True)
        if isinstance(value, BaseModel):
            if default != f"the defaults of {type(value).__name__}":
                return f"default {default!r}"
        elif yaml.safe_load(default) != value:
            return f"default {default!r}, not {value!r}"
    for m in info.metadata:                       # each bound of the field, with its operator
        for name, op in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
            if getattr(m, name, None) is not None:
                found = [float(v) for v in re.findall(rf"(?:^|, ){op} ([-+.\w]+)", bounds)]
                if not any(math.isclose(v, getattr(m, name)) for v in found):
                    return f"range {bounds!r} without {op} {getattr(m, name)}"
    low = next((m.min_length for m in info.metadata if getattr(m, "min_length", None) is not None), None)
    high = next((m.max_length for m in info.metadata if getattr(m, "max_length", None) is not None), None)
    lengths = [f"length {low}"] if low is not None and low == high else \
        [f"length >= {low}"] * bool(low) + [f"length <= {high}"] * (high is not None)
    if any(text not in bounds.split(", ") for text in lengths):       # its length bounds
        return f"range {bounds!r} without {lengths}"
    if info.description and meaning != " ".join(info.description.split()):
        return f"meaning {meaning!r}"
    return None


def test_every_configuration_key_is_on_its_kind_s_page_with_its_default_and_range(tmp_path):
    from att_planner.tools.config_cli import KINDS
    run = build(tmp_path)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    pages = tmp_path / "html" / "reference" / "configuration"
    assert {p.stem for p in pages.glob("*.html")} == set(KINDS)
    total = 0
    for kind, (_, root) in KINDS.items():
        rows: dict[str, list[list[str]]] = {}
        for t in _page_tables(pages / f"{kind}.html"):
            for row in t[1:]:
                rows.setdefault(row[0], []).append(row)
        for key, info in _config_keys(root, "", set()):
            total += 1
            assert key in rows, f"{kind}: {key} not on the page"
            problems = [_config_row_problem(row, info) for row in rows[key]]
            assert None in problems, f"{kind}: {key}: {problems}"   # one table of the key shows the field
    assert total > 150
    spacecraft = {row[0]: row for t in _page_tables(pages / "spacecraft.html") for row in t[1:]}
    # an old key name is answered with its new one, and a unit a key's name carries is shown
    assert spacecraft["inertia_kg_m2"][6] == "inertia" and spacecraft["inertia_kg_m2"][2] == "kg m^2"


def _page_tables(page: Path) -> list[list[list[str]]]:
    parser = _Tables()
    parser.feed(page.read_text())
    return parser.tables
