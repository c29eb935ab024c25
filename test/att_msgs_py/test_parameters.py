"""Node parameter declarations and their checks, without ROS: a declaration refuses what it cannot
describe, a value is checked in the same words by every reader, and the ROS descriptor says what
the declaration says."""
from __future__ import annotations

import math
import sys

import pytest
from rcl_interfaces.msg import ParameterType
from rclpy.parameter import Parameter as RosParameter

from att_msgs_py.errors import ConfigError, ErrorCode
from att_msgs_py.node_runner import ParameterReader, descriptor
from att_msgs_py.parameters import Parameter, ParameterTable, SectionReader

RATE = Parameter("rate", float, 10.0, "a rate", "Hz", 0.0, 100.0, low_open=True, hint=" (a hint)")
COUNT = Parameter("count", int, 3, "a count", "", 1, 10)
AXIS = Parameter("axis", list, (0.0, 0.0, 1.0), "an axis", "", -1.0, 1.0, length=3)
MODE = Parameter("mode", str, "a", "a mode", choices=("a", "b"))
BOUND = Parameter("bound", float, math.inf, "a bound", "rad/s", 0.0, low_open=True, allow_inf=True,
                  refusal="expected a bound > 0 rad/s (.inf: none)")
FOUND = Parameter("found", float, None, "found at start-up", "s", 0.0, 5.0, high_open=True, default_rule="the step")
TABLE = ParameterTable("demo", (RATE, COUNT, AXIS, MODE, BOUND, FOUND))


def refusal(spec: Parameter, value, **kwargs) -> str:
    with pytest.raises(ConfigError) as err:
        spec.check(value, **kwargs)
    assert err.value.code == ErrorCode.INVALID_PARAMETER
    return err.value.message


def test_a_declaration_must_describe_itself_and_its_default_must_pass_its_own_checks():
    with pytest.raises(ValueError, match="no description"):
        Parameter("x", float, 1.0, "")
    with pytest.raises(ValueError, match="default_rule"):
        Parameter("x", float, None, "found later")
    with pytest.raises(TypeError, match="kind"):
        Parameter("x", dict, {}, "a mapping")
    with pytest.raises(ConfigError, match=r"'x' \(its declared default\) = 2.0 is outside \[0, 1\]"):
        Parameter("x", float, 2.0, "a fraction", "", 0.0, 1.0)
    with pytest.raises(ValueError, match="twice"):
        ParameterTable("n", (RATE, RATE))


def test_values_are_checked_in_the_words_of_the_suite():
    assert RATE.check(5) == 5.0 and isinstance(RATE.check(5), float)        # an integer for a float
    assert "parameter 'rate' (here) = 0.0 is outside (0, 100] (a hint)" == refusal(RATE, 0.0, where=" (here)")
    assert "outside (0, 100]" in refusal(RATE, math.nan) and "outside" in refusal(RATE, math.inf)
    assert "expected a number, got str 'fast' (a hint)" in refusal(RATE, "fast")
    assert "expected an integer, got bool True" in refusal(COUNT, True)
    assert "expected an integer, got float 2.5" in refusal(COUNT, 2.5)
    assert AXIS.check([0, 1, 0]) == [0.0, 1.0, 0.0]
    assert "expected 3 numbers, got 2" in refusal(AXIS, [0.0, 1.0])
    assert "outside [-1, 1]" in refusal(AXIS, [0.0, 2.0, 0.0])
    assert "expected a list of numbers" in refusal(AXIS, 1.0)
    assert "expected one of a, b, got 'c'" in refusal(MODE, "c")
    assert "outside [0, 5)" in refusal(FOUND, 5.0) and FOUND.check(4.999) == 4.999
    assert "outside (0, 2]" in refusal(RATE, 3.0, high=2.0)                  # a bound found at start-up


def test_a_refusal_sentence_replaces_the_interval_and_may_let_inf_through():
    assert BOUND.check(math.inf) == math.inf and BOUND.check(2) == 2.0
    for bad in (0.0, -1.0, math.nan, -math.inf):
        assert refusal(BOUND, bad) == f"parameter 'bound': expected a bound > 0 rad/s (.inf: none), got {bad!r}"


def test_a_refusal_sentence_replaces_the_list_of_choices():
    method = Parameter("method", str, "", "a method ('': the best)", choices=("", "fast", "slow"),
                       refusal="expected '' (the best) or one of fast, slow")
    assert method.check("slow") == "slow" and method.constraints() == "'' (the best) or one of fast, slow"
    assert refusal(method, "magic") == "parameter 'method': expected '' (the best) or one of fast, slow, got 'magic'"
    assert "expected a string" in refusal(method, 5)


def test_a_section_reader_takes_the_override_then_the_file_then_the_default():
    read = SectionReader(TABLE, {"rate": 20.0, "count": 4}, "demo.yaml", {"count": 5})
    assert read("rate") == 20.0 and read("count") == 5 and read("mode") == "a" and read("axis") == [0.0, 0.0, 1.0]
    assert read("found", 1.0) == 1.0
    with pytest.raises(ConfigError, match=r"parameter 'rate' \(from demo.yaml\) = 200.0 is outside"):
        SectionReader(TABLE, {"rate": 200.0}, "demo.yaml")("rate")
    with pytest.raises(ConfigError, match=r"parameter 'count' \(override\): expected an integer"):
        SectionReader(TABLE, {}, "", {"count": "many"})("count")
    with pytest.raises(TypeError, match="nowhere"):
        read("found")
    with pytest.raises(TypeError, match="twice"):
        read("rate", 3.0)
    with pytest.raises(KeyError):
        read("undeclared")
    SectionReader(TABLE, {}, "", {"rate": 1.0}).refuse_unknown()
    with pytest.raises(ConfigError, match="unknown parameter.s. raet; known: rate, count"):
        SectionReader(TABLE, {}, "", {"raet": 1.0}).refuse_unknown()


class FakeNode:
    """What :class:`ParameterReader` uses of an rclpy node: the overrides rcl parsed, declare_parameter."""

    def __init__(self, overrides: dict):
        self._parameter_overrides = {k: RosParameter(k, value=v) for k, v in overrides.items()}
        self.declared = {}

    def declare_parameter(self, name, value, d):
        value = self._parameter_overrides[name].value if name in self._parameter_overrides else value
        self.declared[name] = (value, d)
        return RosParameter(name, value=value)

    def get_name(self):
        return "demo"

    def has_parameter(self, name):
        return name in self.declared


def test_a_node_reader_hands_rclpy_an_integer_given_for_a_double_as_a_double():
    node = FakeNode({"rate": 7, "axis": [0, 1, 0]})
    read = ParameterReader(node, TABLE, {"count": 4}, "demo.yaml")
    assert read("rate") == 7.0 and read("axis") == [0.0, 1.0, 0.0] and read("count") == 4
    assert node._parameter_overrides["rate"].type_ == RosParameter.Type.DOUBLE
    assert node._parameter_overrides["axis"].type_ == RosParameter.Type.DOUBLE_ARRAY
    assert node.declared["count"][0] == 4
    with pytest.raises(ConfigError, match=r"'rate' \(from the command line or a --params-file\) = 0.0 is outside"):
        ParameterReader(FakeNode({"rate": 0.0}), TABLE, {})("rate")


def test_a_node_reader_refuses_a_typo_and_declares_what_it_did_not_read():
    node = FakeNode({"use_sim_time": True, "spacecraft.inertia": [1.0, 1.0, 1.0]})
    read = ParameterReader(node, TABLE, {})
    read("found", 1.0)
    read.refuse_unknown()
    assert set(node.declared) == set(TABLE.parameters)
    with pytest.raises(ConfigError, match=r"unknown demo parameter.s. raet \(from the command line"):
        ParameterReader(FakeNode({"raet": 1.0}), TABLE, {}).refuse_unknown()
    with pytest.raises(ConfigError, match=r"unknown demo parameter.s. cuont \(from demo.yaml\)"):
        ParameterReader(FakeNode({}), TABLE, {"cuont": 2}, "demo.yaml").refuse_unknown()
    with pytest.raises(TypeError, match="did not read parameter 'found'"):
        ParameterReader(FakeNode({}), TABLE, {}).refuse_unknown()


def test_the_ros_descriptor_says_what_the_declaration_says():
    d = descriptor(RATE)
    assert d.type == ParameterType.PARAMETER_DOUBLE and not d.dynamic_typing and d.read_only
    assert d.description == "a rate [Hz]" and d.additional_constraints == "in (0, 100]; a hint"
    (r,) = d.floating_point_range
    assert (r.from_value, r.to_value, r.step) == (0.0, 100.0, 0.0) and not d.integer_range
    assert descriptor(RATE, high=20.0).floating_point_range[0].to_value == 20.0
    (i,) = descriptor(COUNT).integer_range
    assert (i.from_value, i.to_value, i.step) == (1, 10, 1)
    assert descriptor(BOUND).floating_point_range[0].to_value == math.inf
    half = descriptor(Parameter("h", float, 0.0, "half-bounded", "", 0.0))
    assert half.floating_point_range[0].to_value == sys.float_info.max
    a = descriptor(AXIS)
    assert a.type == ParameterType.PARAMETER_DOUBLE_ARRAY and not a.floating_point_range
    assert a.additional_constraints == "each number in [-1, 1]; 3 numbers"
    m = descriptor(MODE)
    assert m.type == ParameterType.PARAMETER_STRING and m.additional_constraints == "one of 'a', 'b'"


def test_a_section_is_checked_whole_with_every_problem_at_once():
    problems = TABLE.problems({"rate": 0.0, "count": "many", "raet": 1.0, "use_sim_time": True, "mode": "b"},
                              " (from demo.yaml)", allowed=("use_sim_time",))
    assert [p.message for p in problems] == [
        "unknown demo parameter(s) raet (from demo.yaml); known: rate, count, axis, mode, bound, found",
        "parameter 'rate' (from demo.yaml) = 0.0 is outside (0, 100] (a hint)",
        "parameter 'count' (from demo.yaml): expected an integer, got str 'many'"]
    assert all(p.code == ErrorCode.INVALID_PARAMETER for p in problems)
    assert TABLE.problems({"rate": 5, "axis": [0, 0, 1]}) == []


def test_the_json_schema_says_what_the_declaration_says():
    schema = TABLE.json_schema()
    assert schema["type"] == "object" and schema["additionalProperties"] is False
    assert list(schema["properties"]) == list(TABLE.parameters)
    p = schema["properties"]
    assert p["rate"] == {"type": "number", "exclusiveMinimum": 0.0, "maximum": 100.0, "default": 10.0,
                         "description": "a rate [Hz] (in (0, 100]; a hint)"}
    assert p["count"]["type"] == "integer" and (p["count"]["minimum"], p["count"]["maximum"]) == (1, 10)
    assert p["axis"]["items"] == {"type": "number", "minimum": -1.0, "maximum": 1.0}
    assert p["axis"]["minItems"] == p["axis"]["maxItems"] == 3 and p["axis"]["default"] == [0.0, 0.0, 1.0]
    assert p["mode"]["enum"] == ["a", "b"] and p["mode"]["type"] == "string"
    assert "default" not in p["bound"] and "maximum" not in p["bound"]          # .inf: JSON cannot write it
    assert p["found"]["exclusiveMaximum"] == 5.0 and "default" not in p["found"]


def test_an_integer_range_is_written_in_full():
    seed = Parameter("seed", int, 0, "a seed", "", 0, 2**63 - 1)
    assert seed.interval() == "[0, 9223372036854775807]"
    assert seed.constraints() == "in [0, 9223372036854775807]"
    step = Parameter("step", float, 0.05, "a step", "s", 0.0, 1.0, low_open=True)
    assert step.interval() == "(0, 1]"
