"""rosbag2's schema and QoS texts for MCAP channels (rosbag2 docs/message_definition_encoding.md).

A ``ros2msg`` schema holds the complete message definition: the type's .msg text, then every
dependency recursively, each after a line of 80 '=' and ``MSG: pkg/msg/Type``. The .msg files are
read from the installed interface packages (``<prefix>/share/<pkg>/msg``).
"""
from __future__ import annotations

import os
import re
import sys
from pathlib import Path

PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
              "uint32", "int64", "uint64", "string", "wstring"}
SEPARATOR = "=" * 80


def share_dirs() -> list[Path]:
    """Where installed interface definitions live (<prefix>/share/<pkg>/msg)."""
    prefixes = [Path(sys.prefix)] + [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [p / "share" for p in prefixes if (p / "share").is_dir()]


def msg_text(type_name: str) -> str:
    pkg, _, name = normalise_type(type_name).split("/")
    for share in share_dirs():
        path = share / pkg / "msg" / f"{name}.msg"
        if path.is_file():
            return path.read_text()
    raise FileNotFoundError(f"no definition for {type_name} under {share_dirs()}")


def normalise_type(type_name: str, package: str = "") -> str:
    parts = type_name.split("/")
    if len(parts) == 1:
        return f"{package}/msg/{parts[0]}"
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return type_name


def field_types(text: str, package: str) -> list[str]:
    """Complex (non-primitive) field types referenced by a .msg text (constants skipped)."""
    out = []
    for line in text.splitlines():
        parts = line.split("#", 1)[0].split()
        if len(parts) < 2 or "=" in parts[1]:
            continue
        base = re.sub(r"(<=\d+)?(\[.*\])?$", "", parts[0])
        if base not in PRIMITIVES:
            out.append(normalise_type(base, package))
    return out


def message_definition(type_name: str) -> str:
    """Complete ros2msg definition of ``pkg/msg/Type`` (dependencies included, depth first)."""
    type_name = normalise_type(type_name)
    top = msg_text(type_name)
    parts, seen = [top.rstrip("\n")], {type_name}
    stack = list(reversed(field_types(top, type_name.split("/")[0])))
    while stack:
        dep = stack.pop()
        if dep in seen:
            continue
        seen.add(dep)
        text = msg_text(dep)
        parts.append(f"{SEPARATOR}\nMSG: {dep}\n{text.rstrip(chr(10))}")
        stack.extend(reversed(field_types(text, dep.split("/")[0])))
    return "\n".join(parts) + "\n"


def qos_metadata(qos) -> str:
    """rosbag2's offered_qos_profiles YAML for one publisher with this QoS."""
    durability = "transient_local" if qos.durability.name.lower().endswith("transient_local") else "volatile"
    reliability = "reliable" if "reliable" in qos.reliability.name.lower() else "best_effort"
    return (f"- history: keep_last\n  depth: {qos.depth}\n  reliability: {reliability}\n"
            f"  durability: {durability}\n  deadline:\n    sec: 9223372036\n    nsec: 854775807\n"
            f"  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n  liveliness: automatic\n"
            f"  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n"
            f"  avoid_ros_namespace_conventions: false\n")
