"""Node parameters checked without ROS: type, range, length and choices, one line naming the bad one.

:func:`checked` is what :class:`att_msgs_py.node_runner.ParameterReader` applies to every ROS
parameter; :class:`SectionReader` applies the same checks to a scenario file's section for the
in-process cores (the closed loop of :mod:`att_planner.tools.closed_loop`), so a value a node
would refuse is refused there too, in the same words.
"""
from __future__ import annotations

import math

from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.validation import number, text


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
        expected = {float: "a number", int: "an integer", bool: "true or false", str: "a string"}[kind]
        raise ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter '{name}'{where}: expected {expected}, got "
                                                       f"{type(value).__name__} {clip(repr(value), 80)}")
    return value


def checked(name: str, value, default, where: str = "", low: float | None = None, high: float | None = None, *,
            low_open: bool = False, length: int | None = None, choices=None):
    """``value`` of parameter ``name`` as the type of ``default`` (an integer is accepted for a
    float), within [``low``, ``high``] (``(low, high]`` with ``low_open``; NaN and Inf never pass
    for a bounded number), of list ``length`` and among ``choices``; ConfigError otherwise (``where``
    says where the value came from)."""
    value = coerce(name, value, default, where)
    label = f"parameter '{name}'{where}"
    try:
        if low is not None or high is not None:
            for v in (value if isinstance(value, list) else [value]):
                number(v, label, ErrorCode.INVALID_PARAMETER, -math.inf if low is None else low,
                       math.inf if high is None else high, low_open=low_open)
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


class SectionReader:
    """The reader of :class:`att_msgs_py.node_runner.ParameterReader` (same call, same checks) over
    a plain mapping: a scenario file's node section, with ``overrides`` on top."""

    def __init__(self, values: dict, source: str = "", overrides: dict | None = None):
        self.values, self.source, self.overrides = dict(values), source, dict(overrides or {})
        self.used: set[str] = set()

    def __call__(self, name: str, default, low: float | None = None, high: float | None = None, *,
                 low_open: bool = False, length: int | None = None, choices=None):
        self.used.add(name)
        if name in self.overrides:
            value, where = self.overrides[name], " (override)"
        elif name in self.values:
            value, where = self.values[name], f" (from {self.source})" if self.source else ""
        else:
            value, where = default, ""
        return checked(name, value, default, where, low, high, low_open=low_open, length=length, choices=choices)

    def refuse_unknown(self) -> None:
        unknown = sorted(set(self.overrides) - self.used)
        if unknown:
            raise ConfigError(ErrorCode.INVALID_PARAMETER, f"unknown parameter(s) {clip(', '.join(unknown), 120)}; "
                                                           f"known: {', '.join(sorted(self.used))}")
