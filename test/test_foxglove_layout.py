"""docs/foxglove_layout.json cannot silently rot: it is the classic Foxglove layout
(``configById`` + a mosaic ``layout`` tree naming every panel once), and every topic and message
path it references is one the suite records, down to the field."""
import json
import re
from pathlib import Path

import pytest

from att_msgs_py import topics

LAYOUT = Path(__file__).parents[1] / "docs" / "foxglove_layout.json"
PANELS = {"3D", "Plot", "StateTransitions", "RawMessages", "map"}
PATH = re.compile(r"^(/[\w/]+)((?:\.\w+(?:\[\d+\])?)*)$")


def leaves(tree):
    if isinstance(tree, str):
        return [tree]
    assert set(tree) >= {"first", "second", "direction"} and tree["direction"] in ("row", "column")
    assert 0 < tree.get("splitPercentage", 50) < 100
    return leaves(tree["first"]) + leaves(tree["second"])


def referenced_paths(config: dict) -> list[str]:
    """Every topic or message path of the layout's panels."""
    out = []
    for panel_id, panel in config.items():
        kind = panel_id.split("!")[0]
        if kind == "3D":
            out += list(panel["topics"])
        elif kind in ("Plot", "StateTransitions"):
            out += [p["value"] for p in panel["paths"]]
        elif kind == "RawMessages":
            out.append(panel["topicPath"])
        elif kind == "map":                              # the NavSatFix topics it colours and follows
            out += list(panel["topicColors"]) + [panel["followTopic"]]
    return out


def resolve(path: str) -> str:
    """The ROS type of ``/topic.field[i].sub`` (AssertionError naming what does not exist)."""
    match = PATH.match(path)
    assert match, f"{path}: not a message path"
    topic, fields = match.group(1), match.group(2)
    assert topic in topics.RECORDED, f"{path}: topic {topic} is not recorded by the suite"
    type_name = topics.RECORDED[topic]
    for part in filter(None, fields.split(".")):
        name, indexed = part.split("[")[0], "[" in part
        fields_of = topics.message_class(type_name).get_fields_and_field_types()
        assert name in fields_of, f"{path}: {type_name} has no field '{name}'"
        field_type = fields_of[name]
        is_sequence = field_type.startswith("sequence<") or field_type.endswith("]")
        assert indexed == is_sequence, f"{path}: '{name}' is {field_type}"
        base = re.sub(r"^sequence<(.*)>$", r"\1", field_type).split("[")[0]
        type_name = base.replace("/", "/msg/", 1) if "/" in base else base
    return type_name


def test_the_layout_is_a_classic_foxglove_layout_naming_each_panel_once():
    layout = json.loads(LAYOUT.read_text())
    assert set(layout) == {"configById", "globalVariables", "userNodes", "playbackConfig", "layout"}
    ids = leaves(layout["layout"])
    assert sorted(ids) == sorted(layout["configById"]) and len(set(ids)) == len(ids)
    assert {i.split("!")[0] for i in ids} == PANELS
    view = layout["configById"]["3D!attview"]
    assert view["followTf"] == "body"                   # every scenario's body_frame_id
    assert set(view["topics"]) == {topics.SIM_MARKERS, topics.PLAN_MARKERS}
    ground = layout["configById"]["map!groundtrack"]     # a mission of ground sites on Foxglove's Map panel
    assert set(ground["topicColors"]) == {topics.BORESIGHT_FIX, topics.SUBSATELLITE_FIX, topics.TARGET_FIX}
    assert {topics.RECORDED[t] for t in ground["topicColors"]} == {"sensor_msgs/msg/NavSatFix"}


def test_every_topic_and_message_path_of_the_layout_exists():
    config = json.loads(LAYOUT.read_text())["configById"]
    paths = referenced_paths(config)
    assert len(paths) >= 12
    types = {p: resolve(p) for p in paths}
    assert types["/controller/status.attitude_error"] == types["/spacecraft/state.wheel_speeds[2]"] == "double"
    assert types["/simulator/zone_margins.margins[0]"] == "double"


@pytest.mark.parametrize("bad", ["/controller/status.attitude_eror", "/spacecraft/state.wheel_speeds",
                                 "/no/such/topic", "/controller/status.mode[0]", "/spacecraft/state.attitude.v"])
def test_the_path_check_catches_a_rotten_path(bad):
    with pytest.raises(AssertionError):
        resolve(bad)
