"""Sphinx extension: the reference pages generated from the code, written at build time.

At ``config-inited`` it writes Markdown (MyST) files into ``docs/_generated/`` (git-ignored), which the
hand-written pages include:

- ``errors.md``: every :class:`att_msgs_py.errors.ErrorCode` with its meaning
  (:data:`att_msgs_py.error_meanings.MEANINGS`);
- ``methods.md``: every planning method of :data:`att_planner.methods.REGISTRY`: description, paper,
  how the planner runs it and its options with their ranges;
- ``nodes/<node>.md``: the topics, services and actions of each node of
  :data:`att_planner.tools.launch.NODE_MODULES`, read from the node's source (the ``create_*`` calls and
  the action servers), with their types (the node's imports), QoS (:mod:`att_msgs_py.qos`) and what they
  carry (:data:`att_msgs_py.topics.ABOUT`);
- ``parameters/<node>.md``: the table of every parameter the node declares
  (:func:`att_planner.tools.node_parameters.declared`, rendered by
  :func:`att_msgs_py.parameter_docs.markdown_table`): type, default, range, unit and description.

The node sources are parsed, not imported, so the build starts no ROS node.
"""
from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

NODES = ("simulator", "planner", "controller", "estimator", "recorder", "bridge")
_CALLS = {"create_publisher": "publishes", "create_subscription": "subscribes",
          "create_service": "serves (service)", "create_client": "calls (service)",
          "ActionServer": "serves (action)", "ActionClient": "calls (action)"}


def cell(text: str) -> str:
    """``text`` made safe for one cell of a Markdown table."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


# -- error codes -------------------------------------------------------------------------------------------
def errors_page() -> str:
    from att_msgs_py.error_meanings import MEANINGS
    from att_msgs_py.errors import ErrorCode
    missing = [code.name for code in ErrorCode if code not in MEANINGS]
    if missing:
        raise ValueError(f"att_msgs_py.error_meanings.MEANINGS has no meaning for {', '.join(missing)}")
    rows = [[str(int(code)), f"`{code.name}`", MEANINGS[code]] for code in ErrorCode]
    return table(["code", "name", "meaning"], rows)


# -- planning methods --------------------------------------------------------------------------------------
def _number(value: float, integer: bool) -> str:
    return str(int(value)) if integer else f"{value:g}"


def methods_page() -> str:
    from att_planner.methods import REGISTRY
    out = []
    for method in REGISTRY:
        out.append(f"### `{method.name}`\n")
        out.append(f"{method.description[0].upper()}{method.description[1:]}.\n")
        facts = [f"function: `{method.module}.{method.function}`"]
        if method.fixed:
            facts.append("fixed arguments: " + ", ".join(f"`{k}={v!r}`" for k, v in method.fixed.items()))
        facts.append("runs in the planner's own process (closed form)" if method.cheap
                     else "runs in a solver worker process, in the planner's stages")
        if method.seeded:
            facts.append("seeded with the first plan (`warm_starts`)")
        if method.paper:
            facts.append(f"paper: {method.paper}")
        if method.combined:
            facts.append("combinations of " + ", ".join(f"`{c}`" for c in method.combined)
                         + " are checked by the method's hook (refused with 131 INVALID_OPTION)")
        out.append("\n".join(f"- {f}" for f in facts) + "\n")
        if method.options:
            rows = [[f"`{name}`", f"[{_number(o.low, o.integer)}, {_number(o.high, o.integer)}]",
                     "integer" if o.integer else "number",
                     "bound of the maneuver (a `ManeuverProblem` field, verified)" if o.limit else "tuning",
                     o.doc] for name, o in method.options.items()]
            out.append(table(["option", "range", "type", "kind", "meaning"], rows))
        else:
            out.append("No options.\n")
    return "\n".join(out)


# -- nodes -------------------------------------------------------------------------------------------------
def _source(module: str) -> Path:
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        raise ValueError(f"node module {module} not found")
    return Path(spec.origin)


def _imports(tree: ast.Module) -> dict[str, str]:
    """Imported class name -> ROS type name (``pkg/msg/Type``) for ``from pkg.msg import Type``."""
    names = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.count(".") == 1:
            pkg, kind = node.module.split(".")
            if kind in ("msg", "srv", "action"):
                for alias in node.names:
                    names[alias.asname or alias.name] = f"{pkg}/{kind}/{alias.name}"
    return names


def _attribute(node: ast.AST, owner: str) -> str | None:
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == owner:
        return node.attr
    return None


def _call_name(call: ast.Call) -> str | None:
    func = call.func
    if isinstance(func, ast.Attribute):
        return func.attr
    return func.id if isinstance(func, ast.Name) else None


def _endpoints(function: ast.AST, call: ast.Call, kind: str) -> list[tuple[str, str, str | None]]:
    """(type class name, topics attribute, qos attribute) of one ``create_*`` call: its arguments, or,
    where the topic is a variable, every (Type, topics.X) pair of a tuple in the same function."""
    args = list(call.args)
    if kind in ("ActionServer", "ActionClient"):
        args = args[1:]                                    # (node, Type, name, ...)
    qos_name = next((_attribute(a, "qos") for a in [*args, *(k.value for k in call.keywords)]
                     if _attribute(a, "qos")), None)            # the argument that is a profile of qos.py
    if len(args) >= 2 and _attribute(args[1], "topics") and isinstance(args[0], ast.Name):
        return [(args[0].id, _attribute(args[1], "topics"), qos_name)]
    found = []
    for node in ast.walk(function):
        if isinstance(node, ast.Tuple):
            names = [e.id for e in node.elts if isinstance(e, ast.Name)]
            topic = [_attribute(e, "topics") for e in node.elts if _attribute(e, "topics")]
            if names and topic:
                found.append((names[-1], topic[0], qos_name))
    return found


def _qos_text(name: str | None, kind: str) -> str:
    from att_msgs_py import qos
    if name is None:
        return "rclpy's default" + (" for services" if "service" in kind else "")
    profile = getattr(qos, name)
    return (f"{profile.reliability.name.lower()}, {profile.durability.name.lower().replace('_', ' ')}, "
            f"keep last {profile.depth}")


def _conditional(call: ast.Call, parents: dict) -> bool:
    """Whether ``call`` runs only under a condition of its own: ``x if c else y``, a comprehension's
    ``if``, or an ``if`` block of the function (the node's configuration decides)."""
    node = call
    while node in parents and not isinstance(node, ast.FunctionDef):
        parent = parents[node]
        if isinstance(parent, (ast.IfExp, ast.If)) and node is not parent.test:
            return True
        if isinstance(parent, (ast.ListComp, ast.DictComp, ast.SetComp, ast.GeneratorExp)) and any(
                g.ifs for g in parent.generators):
            return True
        node = parent
    return False


def node_interfaces(module: str) -> list[list[str]]:
    """Rows (role, name, type, QoS, what) of one node, from its source."""
    from att_msgs_py import qos, topics
    tree = ast.parse(_source(module).read_text())
    types = _imports(tree)
    rows = []
    parents = {child: node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
    functions = [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)]
    for function in functions:
        for call in (n for n in ast.walk(function) if isinstance(n, ast.Call)):
            kind = _call_name(call)
            if kind not in _CALLS:
                continue
            role = _CALLS[kind] + (" (when configured)" if _conditional(call, parents) else "")
            for type_name, attr, qos_name in _endpoints(function, call, kind):
                name = getattr(topics, attr)
                rows.append([role, f"`{name}`", f"`{types.get(type_name, type_name)}`",
                             _qos_text(qos_name, _CALLS[kind]), topics.ABOUT.get(name, "")])
    if "recorded_topics()" in _source(module).read_text():
        for name, (type_name, profile) in qos.recorded_topics().items():
            rows.append(["subscribes (raw CDR)", f"`{name}`", f"`{type_name}`",
                         f"{profile.reliability.name.lower()}, "
                         f"{profile.durability.name.lower().replace('_', ' ')}, keep last {profile.depth}",
                         topics.ABOUT.get(name, "")])
    unique = []
    for row in rows:
        if row not in unique:
            unique.append(row)
    if not unique:
        raise ValueError(f"no topic, service or action found in {module}")
    return unique


def node_page(node: str) -> str:
    from att_planner.tools.launch import NODE_MODULES
    module = NODE_MODULES[node]
    return (f"Read from `{module}` (`{_source(module).name}`):\n\n"
            + table(["role", "name", "type", "QoS", "what"], node_interfaces(module)))


def parameters_page(node: str) -> str:
    """The table of every parameter ``node`` declares, from its declarations."""
    from att_msgs_py.parameter_docs import markdown_table
    from att_planner.tools.node_parameters import declared
    return markdown_table(declared(node))


def generate(out: Path) -> list[Path]:
    """Write every generated page under ``out``; the paths written."""
    pages = {"errors.md": errors_page(), "methods.md": methods_page()}
    pages |= {f"nodes/{node}.md": node_page(node) for node in NODES}
    pages |= {f"parameters/{node}.md": parameters_page(node) for node in NODES}
    written = []
    for name, text in pages.items():
        path = out / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists() or path.read_text() != text:    # unchanged files keep their time: no rebuild
            path.write_text(text)
        written.append(path)
    return written


def _on_config(app, config) -> None:
    generate(Path(app.srcdir) / "_generated")


def setup(app):
    app.connect("config-inited", _on_config)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
