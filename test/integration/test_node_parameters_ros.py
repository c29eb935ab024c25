"""Every node's parameters as a ROS user discovers them: listed and described over rclpy's parameter
services (``list_parameters``, ``describe_parameters``, ``get_parameters``) of running nodes."""
from __future__ import annotations

import math
import sys

import pytest
import rclpy
from rcl_interfaces.msg import ParameterType
from rcl_interfaces.srv import DescribeParameters, GetParameters, ListParameters

from att_planner.tools.node_parameters import NODE_PARAMETERS, declared

pytestmark = pytest.mark.ros

ROS_TYPE = {float: ParameterType.PARAMETER_DOUBLE, int: ParameterType.PARAMETER_INTEGER,
            bool: ParameterType.PARAMETER_BOOL, str: ParameterType.PARAMETER_STRING,
            list: ParameterType.PARAMETER_DOUBLE_ARRAY}
NUMERIC = (ParameterType.PARAMETER_DOUBLE, ParameterType.PARAMETER_INTEGER)
# integers given for doubles (and for a list of doubles): accepted and held as doubles
GIVEN = {"simulator": {"real_time_factor": 4, "initial_rate_rad_s": [0, 0, 0]},
         "controller": {"settle_time_s": 20, "safe_sun_axis": [0, 0, 1]},
         "bridge": {"port": 0}}


def call(client, kind, service: str, request, timeout: float = 20.0):
    """The response of ``service`` (waited for up to ``timeout`` s)."""
    cli = client.create_client(kind, service)
    try:
        assert cli.wait_for_service(timeout_sec=timeout), f"no {service}"
        future = cli.call_async(request)
        rclpy.spin_until_future_complete(client, future, timeout_sec=timeout)
        assert future.done(), f"{service} did not answer in {timeout} s"
        return future.result()
    finally:
        client.destroy_client(cli)


@pytest.fixture(scope="module")
def described(ros_suite):
    """``{node: {name: (descriptor, value)}}`` of every node of a running suite (plus the bridge)."""
    nodes = tuple(NODE_PARAMETERS)
    with ros_suite("swift_demo", nodes=nodes, params=GIVEN, name="node_parameters") as s:
        out = {}
        for node in nodes:
            names = call(s.client, ListParameters, f"/{node}/list_parameters", ListParameters.Request()).result.names
            descriptors = call(s.client, DescribeParameters, f"/{node}/describe_parameters",
                               DescribeParameters.Request(names=list(names))).descriptors
            values = call(s.client, GetParameters, f"/{node}/get_parameters",
                          GetParameters.Request(names=list(names))).values
            out[node] = {d.name: (d, v) for d, v in zip(descriptors, values)}
        return out


@pytest.mark.parametrize("node", NODE_PARAMETERS)
def test_every_parameter_has_a_description_and_a_static_type(described, node):
    params = described[node]
    assert set(declared(node).parameters) <= set(params), set(declared(node).parameters) - set(params)
    for name, (d, _) in params.items():
        assert d.description.strip(), f"{node}.{name} has no description"
        assert not d.dynamic_typing and d.type != ParameterType.PARAMETER_NOT_SET, f"{node}.{name}: {d}"


@pytest.mark.parametrize("node", NODE_PARAMETERS)
def test_each_declaration_is_what_ros_sees(described, node):
    """Type, unit in the description, constraints in words, read-only, and the range of every
    bounded number: ROS's closed range is the declared one (an absent bound: the largest finite
    number; a bound found at start-up, such as 1/step, may be tighter)."""
    for spec in declared(node):
        d, _ = described[node][spec.name]
        assert d.type == ROS_TYPE[spec.kind], spec.name
        assert d.read_only == spec.read_only, spec.name
        assert spec.description in d.description and (not spec.unit or f"[{spec.unit}]" in d.description)
        assert d.additional_constraints == spec.constraints(), spec.name
        ranges = list(d.floating_point_range) + list(d.integer_range)
        if d.type in NUMERIC and spec.bounded:
            assert len(ranges) == 1, f"{node}.{spec.name} has no range"
            r = ranges[0]
            low = -sys.float_info.max if spec.low is None else spec.low
            assert r.from_value == (low if d.type == ParameterType.PARAMETER_DOUBLE else max(int(low), -2**63))
            high = spec.high if spec.high is not None else (math.inf if spec.allow_inf else sys.float_info.max)
            assert low <= r.to_value <= high * (1 + 1e-9), (spec.name, r)
            if not spec.high_rule:
                assert r.to_value == (high if d.type == ParameterType.PARAMETER_DOUBLE else min(high, 2**63 - 1))
            if d.type == ParameterType.PARAMETER_DOUBLE:
                assert r.step == 0.0
        else:
            assert not ranges, f"{node}.{spec.name}: a range on a parameter declared without one"


def test_every_numeric_parameter_with_a_bound_has_its_range(described):
    """Across the nodes: every number whose declaration bounds it carries a ROS range, and the
    start-up bound of the simulator's rates is 1/step."""
    bounded = [(n, s.name) for n in NODE_PARAMETERS for s in declared(n) if s.bounded and s.kind in (float, int)]
    assert len(bounded) > 60
    for node, name in bounded:
        d, _ = described[node][name]
        assert d.floating_point_range or d.integer_range, f"{node}.{name}"
    step = described["simulator"]["step_s"][1].double_value
    assert described["simulator"]["publish_rate_Hz"][0].floating_point_range[0].to_value == pytest.approx(1.0 / step)


def test_integers_given_for_doubles_are_taken_as_doubles(described):
    sim, ctl = described["simulator"], described["controller"]
    assert sim["real_time_factor"][1].type == ParameterType.PARAMETER_DOUBLE
    assert sim["real_time_factor"][1].double_value == 4.0
    assert list(sim["initial_rate_rad_s"][1].double_array_value) == [0.0, 0.0, 0.0]
    assert ctl["settle_time_s"][1].double_value == 20.0
    assert list(ctl["safe_sun_axis"][1].double_array_value) == [0.0, 0.0, 1.0]


def test_a_parameter_the_node_does_not_use_is_declared_with_its_default(described):
    """The controller uses its mode-authentication parameters only with require_signed_modes; they
    are declared (typed, described, with their default) all the same, so that every parameter has
    a value (``ros2 param dump``)."""
    ctl = described["controller"]
    assert ctl["require_signed_modes"][1].bool_value is False
    assert ctl["mode_public_key"][1].string_value.endswith("plan_signing.pub")
    assert ctl["mode_sequence_file"][1].string_value.endswith("mode_sequences.json")
    assert ctl["mode_sequence_ahead_s"][1].double_value == 300.0


def test_rclpy_own_use_sim_time_is_described(described):
    for node in NODE_PARAMETERS:
        d, _ = described[node]["use_sim_time"]
        assert d.description and d.type == ParameterType.PARAMETER_BOOL and not d.read_only
