"""Node parameters declared once and checked without ROS: type, range, length and choices, one line
naming the bad one.

Each node's parameters are a :class:`ParameterTable` of :class:`Parameter` declarations (name, type,
default, range, length, choices, unit, description). :class:`att_msgs_py.node_runner.ParameterReader`
declares them as ROS parameters with full descriptors and checks every value with
:meth:`Parameter.check`; :class:`SectionReader` reads the same table over a scenario's node section
for the in-process cores (the closed loop of :mod:`att_planner.tools.closed_loop`), so a value a
node would refuse is refused there too, in the same words. Both are called ``read(name)`` (the table's default) or
``read(name, default)`` for a default the node finds at start-up (``default_rule`` says how), and
``high=`` for an upper bound found at start-up (``high_rule``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.validation import number, text

KINDS = (float, int, bool, str, list)
PROTOTYPES = {float: 0.0, int: 0, bool: False, str: "", list: []}     # a value of each kind
_EXPECTED = {float: "a number", int: "an integer", bool: "true or false", str: "a string"}


@dataclass(frozen=True)
class Parameter:
    """One node parameter.

    ``kind``: ``float``, ``int``, ``bool``, ``str`` or ``list`` (a list of numbers). ``default``: the
    value when none is given; ``None`` when the node finds it at start-up (from the scenario or from
    another parameter), which ``default_rule`` then says in words. ``low``/``high``: the closed range
    (``low_open``/``high_open`` exclude a bound; a bounded number is finite, NaN and Inf never pass),
    applied to each number of a list; ``high_rule``: an upper bound found at start-up, in words.
    ``length``: the list's length. ``choices``: the allowed values. ``unit``: SI or the unit in the
    name. ``hint``: words added to every refusal. ``refusal``: the sentence of a range or choice
    refusal instead of the interval or the list of choices (``allow_inf`` then lets +Inf through: a
    bound that can be "none").
    ``read_only``: the node takes the value at start only."""

    name: str
    kind: type
    default: object
    description: str
    unit: str = ""
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    length: int | None = None
    choices: tuple | None = None
    default_rule: str = ""
    high_rule: str = ""
    hint: str = ""
    refusal: str = ""
    allow_inf: bool = False
    read_only: bool = True

    def __post_init__(self):
        if self.kind not in KINDS:
            raise TypeError(f"parameter '{self.name}': kind {self.kind!r} is not one of {KINDS}")
        if not self.description:
            raise ValueError(f"parameter '{self.name}' has no description")
        if self.kind is list and self.default is not None and not isinstance(self.default, tuple):
            raise TypeError(f"parameter '{self.name}': a list's default is a tuple (a declaration is immutable)")
        if self.default is None and not self.default_rule:
            raise ValueError(f"parameter '{self.name}': a default found at start-up needs its default_rule")
        if self.default is not None:
            self.check(list(self.default) if isinstance(self.default, tuple) else self.default,
                       " (its declared default)")

    @property
    def bounded(self) -> bool:
        """Whether the parameter is a number (or numbers) with a range."""
        return self.kind in (float, int, list) and (self.low is not None or self.high is not None)

    def interval(self) -> str:
        """The range in interval notation (``(0, 1]``; ``finite`` for a number bounded by +-Inf only),
        ``""`` without one."""
        if not self.bounded:
            return ""
        if self.low in (None, -math.inf) and self.high in (None, math.inf) and not self.high_rule:
            return "finite"
        low = "-inf" if self.low is None else _bound(self.low)
        high = self.high_rule or ("inf" if self.high is None else _bound(self.high))
        return f"{'(' if self.low_open else '['}{low}, {high}{')' if self.high_open else ']'}"

    def summary(self) -> str:
        """The description with the unit: what a ROS user's parameter introspection shows."""
        return f"{self.description} [{self.unit}]" if self.unit else self.description

    def default_text(self) -> str:
        """The default as written in a parameter file (``default_rule`` for one found at start-up)."""
        if self.default is None:
            return self.default_rule
        if isinstance(self.default, bool):
            return str(self.default).lower()
        if isinstance(self.default, str):
            return repr(self.default)
        if isinstance(self.default, tuple):
            return f"[{', '.join(map(_number, self.default))}]"
        return ".inf" if self.default == math.inf else _number(self.default)

    def constraints(self) -> str:
        """Every constraint in words: the range (or the ``refusal`` sentence that replaces it), the
        list's length, the choices, the hint."""
        parts = []
        if self.refusal:
            parts.append(self.refusal.removeprefix("expected "))
        elif self.interval() == "finite":
            parts.append("finite numbers" if self.kind is list else "finite")
        elif self.bounded:
            parts.append(f"each number in {self.interval()}" if self.kind is list else f"in {self.interval()}")
        if self.length is not None:
            parts.append(f"{self.length} numbers")
        if self.choices is not None and not self.refusal:
            parts.append(f"one of {', '.join(repr(c) if isinstance(c, str) else str(c) for c in self.choices)}")
        if self.hint and not self.high_rule:
            parts.append(self.hint.strip(" ()"))
        return "; ".join(parts)

    def json_schema(self) -> dict:
        """This declaration as a JSON Schema property (see :meth:`ParameterTable.json_schema`)."""
        number = {float: "number", int: "integer"}.get(self.kind, "number")
        bounds = {}
        for key, bound, is_open in (("Minimum", self.low, self.low_open), ("Maximum", self.high, self.high_open)):
            if bound is not None and not math.isinf(bound) and not (key == "Maximum" and self.high_rule):
                bounds[f"exclusive{key}" if is_open else key.lower()] = bound
        if self.kind is list:
            out = {"type": "array", "items": {"type": "number", **bounds}}
            if self.length is not None:
                out["minItems"] = out["maxItems"] = self.length
        else:
            out = {"type": {bool: "boolean", str: "string"}.get(self.kind, number)}
            if self.kind in (float, int):
                out.update(bounds)
        out["description"] = self.summary() + (f" ({self.constraints()})" if self.constraints() else "")
        if self.choices is not None:
            out["enum"] = list(self.choices)
        if self.default is not None and not (isinstance(self.default, float) and math.isinf(self.default)):
            out["default"] = list(self.default) if isinstance(self.default, tuple) else self.default
        return out

    def check(self, value, where: str = "", high: float | None = None):
        """``value`` checked against this declaration (``high``: a tighter upper bound found at
        start-up); ConfigError naming the parameter, ``where`` the value came from and what is expected."""
        top = self.high if high is None else high
        label = f"parameter '{self.name}'{where}"
        try:
            if self.refusal:
                value = coerce(self.name, value, PROTOTYPES[self.kind], where)
                if (self.bounded and not _within(value, self.low, top, self.low_open, self.high_open, self.allow_inf)
                        or self.choices is not None and value not in self.choices):
                    raise ConfigError(ErrorCode.INVALID_PARAMETER, f"{label}: {self.refusal}, got "
                                                                   f"{clip(repr(value), 80)}")
                return checked(self.name, value, value, where, length=self.length)
            return checked(self.name, value, PROTOTYPES[self.kind], where, self.low, top, low_open=self.low_open,
                           high_open=self.high_open, length=self.length, choices=self.choices)
        except ConfigError as err:
            raise ConfigError(err.code, err.message + self.hint) from None


def _number(x) -> str:
    """A number as a parameter file writes it, to 15 significant digits."""
    if isinstance(x, int) or math.isinf(x):
        return str(x)
    text = f"{x:.15g}"
    return text if any(c in text for c in ".en") else text + ".0"


def _bound(x) -> str:
    """A bound of a range: an integer in full (``2**63 - 1``, not ``9.2e+18``), a float to 15 digits."""
    return str(x) if isinstance(x, int) else f"{x:.15g}"


def _within(value, low, high, low_open: bool, high_open: bool, allow_inf: bool) -> bool:
    for v in (value if isinstance(value, list) else [value]):
        if math.isnan(v) or (math.isinf(v) and not (allow_inf and v > 0)):
            return False
        if low is not None and (v < low or (low_open and v == low)):
            return False
        if high is not None and (v > high or (high_open and v == high)):
            return False
    return True


class ParameterTable:
    """A node's parameters by name, in the order the node documents them; ``renamed``: each old
    parameter name and its new name (the unit in the name), an old name answered with its new one."""

    def __init__(self, node: str, parameters: tuple[Parameter, ...], summary: str = "",
                 renamed: dict[str, str] | None = None):
        self.node, self.summary = node, summary
        self.parameters = {p.name: p for p in parameters}
        self.renamed = dict(renamed or {})
        if len(self.parameters) != len(parameters):
            raise ValueError(f"node '{node}': a parameter is declared twice")
        if set(self.renamed) & set(self.parameters) or not set(self.renamed.values()) <= set(self.parameters):
            raise ValueError(f"node '{node}': a renamed parameter is declared, or its new name is not")

    def renamed_error(self, name: str, where: str = "") -> ConfigError:
        """The refusal of the old parameter name ``name``, with its new name."""
        return ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter '{name}'{where} is renamed "
                                                        f"'{self.renamed[name]}' (its unit in its name)")

    def __getitem__(self, name: str) -> Parameter:
        return self.parameters[name]

    def __contains__(self, name: str) -> bool:
        return name in self.parameters

    def __iter__(self):
        return iter(self.parameters.values())

    def __len__(self) -> int:
        return len(self.parameters)

    def __add__(self, other: ParameterTable) -> ParameterTable:
        return ParameterTable(self.node, (*self, *other), self.summary, {**self.renamed, **other.renamed})

    def problems(self, values: dict, where: str = "", allowed=()) -> list[ConfigError]:
        """Every problem of a node section ``values`` (a scenario's or a ``--params-file``'s) at once,
        each a ConfigError naming its parameter: an undeclared name (a typo; ``allowed``: names a node
        shares, such as ``use_sim_time``), a value its declaration refuses. A bound found at start-up
        (``high_rule``) is not checked here: the node checks it."""
        out = [self.renamed_error(name, where) for name in values if name in self.renamed]
        unknown = sorted(set(values) - set(self.parameters) - set(allowed) - set(self.renamed))
        if unknown:
            out.append(ConfigError(ErrorCode.INVALID_PARAMETER,
                                   f"unknown {self.node} parameter(s) {clip(', '.join(unknown), 120)}{where}; "
                                   f"known: {clip(', '.join(self.parameters), 160)}"))
        for name, value in values.items():
            if name in self.parameters:
                try:
                    self.parameters[name].check(value, where)
                except ConfigError as err:
                    out.append(err)
        return out

    def json_schema(self) -> dict:
        """The JSON Schema (draft 2020-12) of this node's ``ros__parameters`` mapping: each declaration's
        type, description with its unit, default, range, length and choices; no other key. An open
        bound is ``exclusiveMinimum``/``exclusiveMaximum``; a bound found at start-up is left to the
        node; NaN and Inf, which JSON cannot write, are refused by the node."""
        return {"type": "object", "additionalProperties": False, "title": f"{self.node} parameters",
                "description": self.summary, "properties": {p.name: p.json_schema() for p in self}}


def coerce(name: str, value, default, where: str):
    """``value`` as the type of ``default`` (an integer is a valid float), or ConfigError."""
    kind = type(default)
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    if kind is list:
        if not isinstance(value, (list, tuple)) or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            raise ConfigError(ErrorCode.INVALID_PARAMETER,
                              f"parameter '{name}'{where}: expected a list of numbers, got {clip(repr(value), 80)}")
        return [float(v) for v in value]
    if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
        raise ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter '{name}'{where}: expected {_EXPECTED[kind]}, got "
                                                       f"{type(value).__name__} {clip(repr(value), 80)}")
    return value


def checked(name: str, value, default, where: str = "", low: float | None = None, high: float | None = None, *,
            low_open: bool = False, high_open: bool = False, length: int | None = None, choices=None):
    """``value`` of parameter ``name`` as the type of ``default`` (an integer is accepted for a
    float), within [``low``, ``high``] (``(low, ...`` with ``low_open``, ``..., high)`` with
    ``high_open``; NaN and Inf never pass for a bounded number), of list ``length`` and among
    ``choices``; ConfigError otherwise (``where`` says where the value came from)."""
    value = coerce(name, value, default, where)
    label = f"parameter '{name}'{where}"
    try:
        if low is not None or high is not None:
            top = math.inf if high is None else high
            for v in (value if isinstance(value, list) else [value]):
                number(v, label, ErrorCode.INVALID_PARAMETER, -math.inf if low is None else low, top,
                       low_open=low_open)
                if high_open and v == top:
                    raise RequestError(ErrorCode.INVALID_PARAMETER, f"{label} = {float(v)!r} is outside "
                                                                    f"{'(' if low_open else '['}{low:g}, {top:g})")
        if isinstance(value, str):
            text(value, label, ErrorCode.INVALID_PARAMETER, max_length=4096)
    except RequestError as err:
        raise ConfigError(ErrorCode.INVALID_PARAMETER, err.message) from None
    if length is not None and len(value) != length:
        raise ConfigError(ErrorCode.INVALID_PARAMETER, f"{label}: expected {length} numbers, got {len(value)}")
    if choices is not None and value not in choices:
        raise ConfigError(ErrorCode.INVALID_PARAMETER,
                          f"{label}: expected one of {', '.join(map(str, choices))}, got {clip(repr(value), 80)}")
    return value


class Reader:
    """``read(name, default=None, *, high=None)``: the value of parameter ``name`` of ``table``
    checked against its declaration; ``default`` is required for (and only for) a declaration whose
    default is found at start-up. Subclasses say where a value comes from (:meth:`_source`)."""

    def __init__(self, table: ParameterTable):
        self.table = table
        self.used: set[str] = set()

    def __call__(self, name: str, default=None, *, high: float | None = None):
        spec = self.table[name]                  # KeyError: the node reads a parameter it does not declare
        if (default is None) != (spec.default is not None):
            raise TypeError(f"parameter '{name}': a default is given {'twice' if default is not None else 'nowhere'}")
        self.used.add(name)
        if default is None:
            default = list(spec.default) if isinstance(spec.default, tuple) else spec.default
        return self._source(spec, default, high)

    def _source(self, spec: Parameter, default, high):
        raise NotImplementedError


class SectionReader(Reader):
    """The reader of :class:`att_msgs_py.node_runner.ParameterReader` (same call, same checks) over
    a plain mapping: a node's section of a scenario's ``NAME.params.yaml``, with ``overrides`` on top."""

    def __init__(self, table: ParameterTable, values: dict, source: str = "", overrides: dict | None = None):
        super().__init__(table)
        self.values, self.source, self.overrides = dict(values), source, dict(overrides or {})

    def _source(self, spec: Parameter, default, high):
        if spec.name in self.overrides:
            value, where = self.overrides[spec.name], " (override)"
        elif spec.name in self.values:
            value, where = self.values[spec.name], f" (from {self.source})" if self.source else ""
        else:
            value, where = default, ""
        return spec.check(value, where, high)

    def refuse_unknown(self) -> None:
        for names, where in ((self.overrides, " (override)"), (self.values, f" (from {self.source})")):
            old = sorted(n for n in names if n in self.table.renamed)
            if old:
                raise self.table.renamed_error(old[0], where)
        unknown = sorted(set(self.overrides) - set(self.table.parameters))
        if unknown:
            raise ConfigError(ErrorCode.INVALID_PARAMETER, f"unknown parameter(s) {clip(', '.join(unknown), 120)}; "
                                                           f"known: {', '.join(self.table.parameters)}")


SCENARIO = Parameter("scenario", str, "swift_demo", "the scenario: a name (config/scenarios/NAME.yaml, its "
                                                    "spacecraft and NAME.params.yaml, also looked up in "
                                                    "$ATT_CONFIG_PATH) or a path to a scenario file")
SCENARIO_TABLE = ParameterTable("any", (SCENARIO,))
