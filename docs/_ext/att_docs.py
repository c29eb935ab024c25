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

and, as pages of their own, into ``docs/reference/configuration/`` (git-ignored):

- ``<kind>.md``: the reference of each kind of configuration file ``att-config`` knows
  (:data:`att_planner.tools.config_cli.KINDS`): one table per pydantic model of the kind's schema, one
  row per key with its path, type, unit (the one its name carries), default, range (the field's
  ``ge``/``gt``/``le``/``lt`` and length bounds), meaning (the field's description) and the old key
  names answered with it (the model's ``renamed`` table).

The node sources are parsed, not imported, so the build starts no ROS node.
"""
from __future__ import annotations

import ast
import importlib.util
import inspect
import json
import math
import types
import typing
from datetime import datetime
from pathlib import Path

CONFIG_PAGES = "reference/configuration"      # generated pages, under the docs' source folder
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


# -- configuration files -----------------------------------------------------------------------------------
# the unit a key's name carries, longest suffix first (the unit of a key without one is in its meaning)
UNIT_SUFFIXES = (("_deg_per_h_per_sqrt_h", "deg/h/sqrt(h)"), ("_deg_per_sqrt_h", "deg/sqrt(h)"),
                 ("_nT_per_Am2", "nT/(A m^2)"), ("_deg_per_s", "deg/s"), ("_deg_per_h", "deg/h"),
                 ("_rad_per_s", "rad/s"), ("_rad_s", "rad/s"), ("_Nm_s", "N m s/rad"), ("_kg_m2", "kg m^2"),
                 ("_arcsec", "arcsec"), ("_Nms", "N m s"), ("_Am2", "A m^2"), ("_ppm", "ppm"), ("_deg", "deg"),
                 ("_rad", "rad"), ("_Nm", "N m"), ("_nT", "nT"), ("_Hz", "Hz"), ("_hz", "Hz"), ("_m2", "m^2"),
                 ("_W", "W"), ("_m", "m"), ("_s", "s"))
CONFIG_COLUMNS = ["key", "type", "unit", "default", "range", "meaning", "old name"]


def unit_of(key: str) -> str:
    """The unit the name ``key`` carries (empty when it carries none)."""
    return next((unit for suffix, unit in UNIT_SUFFIXES if key.endswith(suffix)), "")


def _models_in(annotation) -> list:
    """The pydantic models an annotation holds (inside unions, lists, mappings, ``Annotated``)."""
    from pydantic import BaseModel
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for arg in typing.get_args(annotation) for m in _models_in(arg)]


def type_text(annotation) -> str:
    """A field's type as a reader of the YAML file sees it."""
    from pydantic import BaseModel
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Annotated:
        return type_text(args[0])
    if origin in (typing.Union, types.UnionType):
        return " or ".join(type_text(a) for a in args)
    if origin is typing.Literal:
        return "one of " + ", ".join(f"{a}" for a in args)
    if origin is list:
        return f"list of {type_text(args[0])}" if args else "list"
    if origin is dict:
        return f"mapping of {type_text(args[1])}" if args else "mapping"
    if annotation is type(None):
        return "null"
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return f"mapping ({annotation.__name__})"
    names = {float: "number", int: "integer", bool: "boolean", str: "string", datetime: "date-time",
             typing.Any: "any"}
    return names.get(annotation, getattr(annotation, "__name__", str(annotation)))


def yaml_text(value) -> str:
    """``value`` written as in a YAML file."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, float):
        return ".nan" if math.isnan(value) else (".inf" if value > 0 else "-.inf") if math.isinf(value) else repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(yaml_text(v) for v in value) + "]"
    if isinstance(value, str):
        return json.dumps(value)
    return str(value)


def default_text(info) -> str:
    """The default of a field as its table shows it: ``required`` when it has none, the value in YAML
    (as code) or, for a mapping, a pointer to its own table."""
    from pydantic import BaseModel
    if info.is_required():
        return "required"
    value = info.default_factory() if info.default_factory is not None else info.default
    return f"the defaults of `{type(value).__name__}`" if isinstance(value, BaseModel) else f"`{yaml_text(value)}`"


def _bounds(metadata) -> list[str]:
    words = {"ge": ">=", "gt": ">", "le": "<=", "lt": "<"}
    out = [f"{words[name]} {yaml_text(getattr(m, name))}" for m in metadata for name in words
           if getattr(m, name, None) is not None]
    low = next((m.min_length for m in metadata if getattr(m, "min_length", None) is not None), None)
    high = next((m.max_length for m in metadata if getattr(m, "max_length", None) is not None), None)
    if low is not None and low == high:
        out.append(f"length {low}")
    else:
        out += [f"length >= {low}"] if low else []
        out += [f"length <= {high}"] if high is not None else []
    return out


def range_text(info) -> str:
    """The range of a field: its bounds (``ge``, ``gt``, ``le``, ``lt``), its length bounds, and those of
    each item of a list."""
    out = _bounds(info.metadata)
    annotation = info.annotation
    if typing.get_origin(annotation) is list:
        item = typing.get_args(annotation)[0]
        if typing.get_origin(item) is typing.Annotated:
            inner = _bounds(typing.get_args(item)[1:])
            out += [f"each {', '.join(inner)}"] if inner else []
    return ", ".join(out)


def _extra_sections(model) -> object | None:
    """The type of the extra sections of a model that allows them (a parameter file's node sections)."""
    if model.model_config.get("extra") != "allow":
        return None
    return typing.get_type_hints(model).get("__pydantic_extra__")


def config_models(root) -> list[tuple[type, str]]:
    """Every model of a configuration kind with the key path it is found at, depth first, each once:
    ``root`` is a model or a union of models (a kind chosen by a key)."""
    found: list[tuple[type, str]] = []

    def visit(model, path: str) -> None:
        if any(model is m for m, _ in found):
            return
        found.append((model, path))
        for name, info in model.model_fields.items():
            key = info.alias or name
            suffix = "[]" if typing.get_origin(_plain(info.annotation)) is list else ""
            for sub in _models_in(info.annotation):
                visit(sub, f"{path}{key}{suffix}.")
        extra = _extra_sections(model)
        for sub in _models_in(extra) if extra is not None else []:
            visit(sub, f"{path}<section>.")

    for model in _models_in(root):
        visit(model, "")
    return found


def _plain(annotation):
    """``annotation`` without ``Annotated`` and ``| None``."""
    while True:
        origin, args = typing.get_origin(annotation), typing.get_args(annotation)
        if origin is typing.Annotated:
            annotation = args[0]
        elif origin in (typing.Union, types.UnionType) and type(None) in args and len(args) == 2:
            annotation = next(a for a in args if a is not type(None))
        else:
            return annotation


def _keys_of(annotation) -> str:
    models = _models_in(annotation)
    return ("its keys: " + ", ".join(f"`{m.__name__}`" for m in models) + " below") if models else ""


def config_rows(model, path: str) -> list[list[str]]:
    """One row (:data:`CONFIG_COLUMNS`) per key of ``model`` found at ``path``."""
    old = {}
    for before, after in getattr(model, "renamed", {}).items():
        old.setdefault(after, []).append(before)
    rows = []
    for name, info in model.model_fields.items():
        key = info.alias or name
        rows.append([f"`{path}{key}`", type_text(info.annotation), unit_of(key), default_text(info),
                     range_text(info), info.description or _keys_of(info.annotation),
                     ", ".join(f"`{o}`" for o in old.get(key, []))])
    extra = _extra_sections(model)
    if extra is not None:
        value = typing.get_args(extra)[1]
        rows.append([f"`{path}<section>`", type_text(value), "", "", "", "any other key: one section, "
                     + _keys_of(value), ""])
    return rows


def _about(model) -> str:
    doc = inspect.getdoc(model) or ""
    if model.__doc__ is None or doc == inspect.getdoc(model.__mro__[1]):
        return ""                                                   # no docstring of its own
    return " ".join(doc.split("\n\n")[0].split())


def configuration_page(kind: str) -> str:
    """The reference page of one kind of configuration file: a table per model of its schema."""
    from att_planner.tools.config_cli import KINDS
    _, root = KINDS[kind]
    out = [f"# `{kind}` files\n",
           f"Every key of a `{kind}` file, generated from the models `att-config check` validates it with "
           f"(`att-config schema {kind}` prints them as JSON Schema); {{doc}}`/configuration` says where the files "
           "are. Each value is checked against its type and range when the file is read; a key of an old name is "
           "refused with its new name (column *old name*).\n"]
    for model, path in config_models(root):
        where = f"at `{path.rstrip('.')}`" if path else "of the file's root mapping"
        out.append(f"## `{model.__name__}`\n")
        about = _about(model)
        out.append((f"{about} " if about else "") + f"Keys {where}.\n")
        out.append(table(CONFIG_COLUMNS, config_rows(model, path)))
    return "\n".join(out)


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


def generate_pages(out: Path) -> list[Path]:
    """Write the configuration reference pages under ``out`` (one per kind, stale ones removed); the
    paths written."""
    from att_planner.tools.config_cli import KINDS
    pages = {f"{kind}.md": configuration_page(kind) for kind in KINDS}
    out.mkdir(parents=True, exist_ok=True)
    for stale in out.glob("*.md"):
        if stale.name not in pages:
            stale.unlink()
    written = []
    for name, text in pages.items():
        path = out / name
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
        written.append(path)
    return written


def _on_config(app, config) -> None:
    generate(Path(app.srcdir) / "_generated")
    generate_pages(Path(app.srcdir) / CONFIG_PAGES)


def setup(app):
    app.connect("config-inited", _on_config)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
