"""Reading a configuration file a user writes: YAML in, a validated pydantic model out.

:func:`load_file` reads one file and validates it against a pydantic v2 model
(:mod:`att_sim.models.config_schema` and the schemas of missions, target lists and campaigns). It
refuses, and reports **every** problem at once (one :class:`ConfigFileError`, code
``INVALID_CONFIG``), each naming the file, the line, the field path
(``/**.ros__parameters.spacecraft.torque_max_Nm``, ``targets[2].dwell_s``), what was expected and
what was found:

- a file over :data:`MAX_FILE_BYTES` (before anything is parsed), a file that is not UTF-8, an
  empty file, a root that is not a mapping;
- YAML anchors and aliases (an alias "bomb" expands a few hundred bytes into gigabytes), tags other
  than the standard ones, duplicate keys (YAML keeps the last one silently), non-scalar keys;
- a key the model does not know (``extra="forbid"``: a typo never silently means a default), and an
  old key name, answered with its new one (a model's ``renamed`` table);
- a value of the wrong type, out of its range, or failing a physical check of the model.

The YAML is composed with PyYAML's safe loader (nothing in a file is ever evaluated) and walked
node by node, so that each value keeps the line it was written on: :class:`Loaded` holds the
model, the plain data and that map of lines (``att-config show`` prints where each value came from).
"""
from __future__ import annotations

import difflib
import math
import re
import types
import typing
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import yaml
from pydantic import BaseModel, ValidationError

from att_msgs_py.errors import ConfigError, ErrorCode

MAX_FILE_BYTES = 1_000_000     # a configuration file is a few kB
MAX_DEPTH = 32                 # nesting of mappings and lists
MAX_NODES = 100_000            # values of a file, aliases expanded
MAX_PROBLEMS = 100             # problems reported for one file (then: "and N more")
MAX_FOUND = 80                 # characters of a found value quoted in a problem

Path_ = tuple                  # a field path: keys (str) and list indices (int)


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a file: where (file, line, field path), what was expected, what was found."""

    file: str
    line: int | None           # 1-based; None when the file has no line to point at
    field: str                 # dotted path with [i] for list items; "" for the whole file
    expected: str
    found: str
    rename: tuple | None = None  # (old key, new key) when the problem is an old key name

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}" if self.line else self.file
        what = self.field or "(file)"
        return f"{where}: {what}: expected {self.expected}; found {self.found}"


class ConfigFileError(ConfigError):
    """A configuration file refused: every :class:`Problem` of it, one per line of the message."""

    def __init__(self, problems: Iterable[Problem]):
        self.problems = list(problems)
        shown = self.problems[:MAX_PROBLEMS]
        lines = [str(p) for p in shown]
        if len(self.problems) > len(shown):
            lines.append(f"... and {len(self.problems) - len(shown)} more problem(s)")
        super().__init__(ErrorCode.INVALID_CONFIG, lines[0] if lines else "invalid configuration")
        self.message = "\n".join(lines)        # bounded: at most MAX_PROBLEMS lines of bounded length
        self.args = (self.message,)


@dataclass(frozen=True)
class Loaded:
    """A valid file: its model, the plain data read and the 1-based line of each field path."""

    path: Path
    model: BaseModel
    data: dict
    lines: dict = field(default_factory=dict)


def field_path(path: Iterable) -> str:
    """``('a', 'b', 2, 'c')`` as ``a.b[2].c``."""
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def shown(value) -> str:
    """A found value quoted in a problem, clipped to :data:`MAX_FOUND` characters."""
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return f"a list of {len(value)} item(s)"
    text = repr(value)
    return text if len(text) <= MAX_FOUND else text[: MAX_FOUND - 3] + "..."


class _Refused(Exception):
    """A node the walk refuses (an alias, an anchor, a tag, a duplicate key)."""

    def __init__(self, line: int, field: str, expected: str, found: str):
        super().__init__(found)
        self.line, self.field, self.expected, self.found = line, field, expected, found


class _NoAliasLoader(yaml.SafeLoader):
    """PyYAML's safe loader that refuses anchors and aliases while it composes (before any expansion)."""

    aliases = False            # True: anchors and aliases composed (shared nodes), their expansion bounded

    def compose_node(self, parent, index):
        event = self.peek_event()
        if self.aliases:
            return super().compose_node(parent, index)
        if isinstance(event, yaml.AliasEvent):
            raise _Refused(event.start_mark.line + 1, "", "no YAML aliases (write the value out)",
                           f"the alias *{event.anchor}")
        if getattr(event, "anchor", None) is not None:
            raise _Refused(event.start_mark.line + 1, "", "no YAML anchors (write the value out)",
                           f"the anchor &{event.anchor}")
        return super().compose_node(parent, index)


# YAML 1.2's floats with an unsigned exponent (7.0e6, 1e-3 already resolves): PyYAML's YAML 1.1 reads them as text
_NoAliasLoader.add_implicit_resolver("tag:yaml.org,2002:float",
                                     re.compile(r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
                                     list("-+0123456789"))

_STANDARD_TAGS = {f"tag:yaml.org,2002:{t}" for t in ("str", "int", "float", "bool", "null", "map", "seq",
                                                     "timestamp")}


class _Walk:
    """The plain data of a composed YAML tree, with the line of every field path."""

    def __init__(self, loader: yaml.SafeLoader):
        self.loader = loader
        self.lines: dict[tuple, int] = {}
        self.visits = 0

    def value(self, node, path: tuple):
        line = node.start_mark.line + 1
        self.visits += 1
        if self.visits > MAX_NODES:            # aliases expanding into more values than a file holds: a bomb
            raise _Refused(line, field_path(path), f"at most {MAX_NODES} values once aliases are expanded",
                           "more (an alias bomb?)")
        self.lines.setdefault(path, line)
        if node.tag not in _STANDARD_TAGS:
            raise _Refused(line, field_path(path), "a plain YAML value (no tags)", f"the tag {node.tag}")
        if len(path) > MAX_DEPTH:
            raise _Refused(line, field_path(path), f"at most {MAX_DEPTH} levels of nesting", "deeper nesting")
        if isinstance(node, yaml.MappingNode):
            out = {}
            for key_node, value_node in node.value:
                if not isinstance(key_node, yaml.ScalarNode) or key_node.tag not in _STANDARD_TAGS:
                    raise _Refused(key_node.start_mark.line + 1, field_path(path), "a plain key",
                                   "a mapping or list used as a key" if not isinstance(key_node, yaml.ScalarNode)
                                   else f"the tag {key_node.tag}")
                key = self.loader.construct_object(key_node)
                key = key if isinstance(key, str) else str(key)
                key_line = key_node.start_mark.line + 1
                if key in out:
                    raise _Refused(key_line, field_path((*path, key)), "each key once in a mapping",
                                   f"a duplicate of the key on line {self.lines[(*path, key)]}")
                self.lines[(*path, key)] = key_line
                out[key] = self.value(value_node, (*path, key))
            return out
        if isinstance(node, yaml.SequenceNode):
            return [self.value(item, (*path, i)) for i, item in enumerate(node.value)]
        return self.loader.construct_object(node)


def read_yaml(path: Path, max_bytes: int = MAX_FILE_BYTES, aliases: bool = False) -> tuple[dict, dict]:
    """The root mapping of the YAML file ``path`` and the line of each field path in it;
    :class:`ConfigFileError` for a file that cannot be read, is too large, is not UTF-8, is not
    YAML, uses anchors and aliases (unless ``aliases``: then accepted up to :data:`MAX_NODES` values
    expanded, as ``yaml.safe_dump`` writes an object it meets twice), tags or duplicate keys, or whose
    root is not a mapping."""
    name = str(path)

    def refuse(line, fld, expected, found):
        return ConfigFileError([Problem(name, line, fld, expected, found)])

    try:
        size = path.stat().st_size
        if size > max_bytes:
            raise refuse(None, "", f"a file of at most {max_bytes} bytes", f"{size} bytes")
        with open(path, "rb") as fh:
            raw = fh.read(max_bytes + 1)
    except OSError as exc:
        raise refuse(None, "", "a readable file", exc.strerror or type(exc).__name__) from None
    if len(raw) > max_bytes:
        raise refuse(None, "", f"a file of at most {max_bytes} bytes", "more")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise refuse(raw[: exc.start].count(b"\n") + 1, "", "UTF-8 text",
                     f"the byte 0x{raw[exc.start]:02x} at offset {exc.start}") from None
    return parse_yaml(text, name, aliases)


def parse_yaml(text: str, name: str, aliases: bool = False) -> tuple[dict, dict]:
    """The root mapping of the YAML ``text`` (of the file ``name``) and the line of each field path
    in it; :class:`ConfigFileError` as :func:`read_yaml`."""

    def refuse(line, fld, expected, found):
        return ConfigFileError([Problem(name, line, fld, expected, found)])

    if not text.strip() or all(not ln.strip() or ln.lstrip().startswith("#") for ln in text.splitlines()):
        raise refuse(1, "", "a mapping of keys", "an empty file")
    loader = _NoAliasLoader(text)
    loader.aliases = aliases
    try:
        node = loader.get_single_node()
        if node is None:
            raise refuse(1, "", "a mapping of keys", "an empty document")
        if not isinstance(node, yaml.MappingNode):
            raise refuse(node.start_mark.line + 1, "", "a mapping of keys at the top of the file",
                         "a list" if isinstance(node, yaml.SequenceNode) else f"the value {shown(node.value)}")
        walk = _Walk(loader)
        data = walk.value(node, ())
    except _Refused as r:
        raise refuse(r.line, r.field, r.expected, r.found) from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        raise refuse(mark.line + 1 if mark else None, "", "valid YAML",
                     " ".join(str(exc.problem or exc).split())[:200]) from None
    except yaml.YAMLError as exc:
        raise refuse(None, "", "valid YAML", " ".join(str(exc).split())[:200]) from None
    except RecursionError:
        raise refuse(None, "", f"at most {MAX_DEPTH} levels of nesting", "deeper nesting") from None
    finally:
        loader.dispose()
    return data, walk.lines


# ---------------------------------------------------------------------------------------------
# pydantic's errors as problems


def _models_in(annotation) -> list[type[BaseModel]]:
    """The pydantic models an annotation can hold directly (through Optional, Union, Annotated)."""
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _models_in(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return [m for a in typing.get_args(annotation) for m in _models_in(a)]
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return []


def _items_of(annotation):
    """The item annotation of a list or dict annotation (through Optional and Annotated), else None."""
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _items_of(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        for a in typing.get_args(annotation):
            item = _items_of(a)
            if item is not None:
                return item
        return None
    if origin in (list, tuple):
        return typing.get_args(annotation)[0]
    if origin is dict:
        return typing.get_args(annotation)[1]
    return None


def keys_of(model: type[BaseModel]) -> dict:
    """The keys a model reads in a file (a field's alias where it has one) and their fields."""
    return {(info.alias or name): info for name, info in model.model_fields.items()}


def _one(annotation, value) -> type[BaseModel] | None:
    models = _models_in(annotation)
    return (_pick(models, value) if len(models) > 1 else models[0]) if models else None


def model_at(root: type[BaseModel], path: tuple, data) -> type[BaseModel] | None:
    """The model class validating the mapping at data path ``path`` (None when it is not a model)."""
    current: typing.Any = root
    value = data
    for part in path:
        model = _one(current, value)
        keys = keys_of(model) if model is not None else {}
        current = keys[part].annotation if isinstance(part, str) and part in keys else _items_of(current)
        value = value[part] if isinstance(value, (dict, list)) and _has(value, part) else None
        if current is None:
            return None
    return _one(current, value)


def _has(container, part) -> bool:
    if isinstance(container, dict):
        return part in container
    return isinstance(part, int) and 0 <= part < len(container)


def _pick(models: list, value) -> type[BaseModel] | None:
    """Of a union's models, the one a mapping's discriminating literal names (its ``type`` or ``kind``)."""
    if isinstance(value, dict):
        for m in models:
            for name, info in keys_of(m).items():
                if typing.get_origin(info.annotation) is typing.Literal and value.get(name) in typing.get_args(
                        info.annotation):
                    return m
        return max(models, key=lambda m: len(set(value) & set(keys_of(m))))
    return models[0]


def _data_path(loc: tuple, data, missing: bool = False) -> tuple:
    """pydantic's error location as a path into the data: union tags and validator names dropped;
    for a ``missing`` error the last element, the absent key, kept."""
    out, value = [], data
    for i, part in enumerate(loc):
        if isinstance(value, dict) and part in value:
            out.append(part)
            value = value[part]
        elif isinstance(value, list) and isinstance(part, int) and 0 <= part < len(value):
            out.append(part)
            value = value[part]
        elif missing and i == len(loc) - 1:
            out.append(part)
    return tuple(out)


def _line(lines: dict, path: tuple) -> int | None:
    while path not in lines and path:
        path = path[:-1]
    return lines.get(path)


def _expected(err: dict) -> str:
    msg = err["msg"]
    for prefix in ("Input should be ", "Value error, ", "Assertion failed, "):
        if msg.startswith(prefix):
            msg = msg[len(prefix):]
    return msg


def problems_of(exc: ValidationError, root: type[BaseModel], data: dict, lines: dict, name: str) -> list[Problem]:
    """Every error of a pydantic validation as a :class:`Problem` with its line and field path."""
    out, renamed_to = [], set()
    errors = exc.errors(include_url=False)
    for err in errors:
        if err["type"] != "extra_forbidden":
            continue
        path = _data_path(err["loc"], data)
        model = model_at(root, path[:-1], data)
        renames = getattr(model, "renamed", {}) if model else {}
        key = path[-1] if path else ""
        known = sorted(keys_of(model)) if model else []
        if key in renames:
            renamed_to.add((*path[:-1], renames[key]))
            out.append(Problem(name, _line(lines, path), field_path(path), f"the key renamed to '{renames[key]}'",
                               f"the old key '{key}'", (key, renames[key])))
            continue
        close = difflib.get_close_matches(str(key), known, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        out.append(Problem(name, _line(lines, path), field_path(path),
                           f"one of the keys {', '.join(known)}{hint}" if known else "no such key",
                           f"unknown key(s) {key}"))
    for err in errors:
        if err["type"] == "extra_forbidden":
            continue
        path = _data_path(err["loc"], data, err["type"] == "missing")
        if err["type"] == "missing":
            if path in renamed_to:
                continue                      # reported once, as the old name's rename
            out.append(Problem(name, _line(lines, path), field_path(path), "this key (required)", "nothing"))
            continue
        found = err.get("input")
        if err["type"] == "union_tag_invalid" and isinstance(found, dict):
            tag = err["ctx"]["tag"]
            key = next((k for k, v in found.items() if str(v) == tag), None)
            path = (*path, key) if key is not None else path
            out.append(Problem(name, _line(lines, path), field_path(path), f"one of {err['ctx']['expected_tags']}",
                               shown(tag)))
            continue
        out.append(Problem(name, _line(lines, path), field_path(path), _expected(err),
                           shown(found) if not (isinstance(found, float) and math.isnan(found)) else "nan"))
    return sorted(set(out), key=lambda p: (p.line or 0, p.field, p.expected))


def validate(path: Path, model, data: dict, lines: dict, context: dict | None = None) -> BaseModel:
    """``data`` (read from ``path``) validated by ``model`` (a model class, or a function of the data
    choosing one); :class:`ConfigFileError` with every problem."""
    if not (isinstance(model, type) and issubclass(model, BaseModel)):
        model = model(data)
    try:
        return model.model_validate(data, context=context)
    except ValidationError as exc:
        raise ConfigFileError(problems_of(exc, model, data, lines, str(path))) from None


def load_file(path, model, context: dict | None = None,
              max_bytes: int = MAX_FILE_BYTES) -> Loaded:
    """The file ``path`` read (:func:`read_yaml`) and validated by ``model`` (:func:`validate`)."""
    path = Path(path)
    data, lines = read_yaml(path, max_bytes)
    return Loaded(path, validate(path, model, data, lines, context), data, lines)


def renamed_text(text: str, problems: Iterable[Problem]) -> str:
    """``text`` (a file's YAML) with each old key of ``problems`` written under its new name, on its
    line; comments, order and layout kept."""
    lines = text.splitlines(keepends=True)
    for p in problems:
        if p.rename and p.line and 0 < p.line <= len(lines):
            old, new = p.rename
            line = re.sub(rf"(?<![\w.]){re.escape(old)}(?=\s*:)", new, lines[p.line - 1], count=1)
            if line != lines[p.line - 1]:            # keep a trailing comment in its column where room allows
                gap = re.search(r"\S( {3,})#", line)
                if gap:
                    spaces = " " * max(2, len(gap[1]) - len(new) + len(old))
                    line = line[:gap.start(1)] + spaces + line[gap.end(1):]
            lines[p.line - 1] = line
    return "".join(lines)
