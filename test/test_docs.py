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
    # the simulator publishes a sensor's topic only when the scenario has that sensor
    assert ("publishes (when configured)", "/sensors/imu", "sensor_msgs/msg/Imu") in rows["simulator"]
    assert ("publishes", "/estimator/attitude", "att_msgs/msg/AttitudeEstimate") in rows["estimator"]
    from att_msgs_py.topics import RECORDED
    assert {r[1] for r in rows["recorder"]} == set(RECORDED)
