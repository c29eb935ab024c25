"""MCAP logs exactly as rosbag2 writes them, and the one reader tests and tools use.

Writing: ``ros2`` profile, one ``ros2msg`` schema per type holding the complete message definition
(the type's .msg text, then every dependency recursively, each after a line of 80 '=' and
``MSG: pkg/msg/Type``; rosbag2 docs/message_definition_encoding.md), ``cdr`` channels with the
``offered_qos_profiles`` metadata. Chunks are closed and flushed at least every
``flush_period`` seconds so a killed recorder loses at most that much.

Reading: :func:`read_log` returns per-topic arrays with timestamps; it also reads a file whose
end is missing (killed writer) up to its last complete chunk.
"""
from __future__ import annotations

import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.stream_reader import StreamReader
from mcap.records import Channel, Message, Schema
from mcap.writer import CompressionType, Writer
from mcap_ros2.decoder import DecoderFactory

PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
              "uint32", "int64", "uint64", "string", "wstring"}
SEPARATOR = "=" * 80


def share_dirs() -> list[Path]:
    """Where installed interface definitions live (<prefix>/share/<pkg>/msg)."""
    import os
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


class LogWriter:
    """Append CDR messages to an MCAP file; :meth:`close` writes the summary and index."""

    def __init__(self, path: str | Path, flush_period: float = 0.5, chunk_size: int = 256 * 1024):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._stream = open(self.path, "wb")
        self._writer = Writer(self._stream, chunk_size=chunk_size, compression=CompressionType.ZSTD)
        self._writer.start(profile="ros2", library="att_suite")
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self.counts: dict[str, int] = {}
        self.flush_period = flush_period
        self._last_flush = time.monotonic()
        self.closed = False

    def add_topic(self, topic: str, type_name: str, qos=None) -> None:
        type_name = normalise_type(type_name)
        if type_name not in self._schemas:
            self._schemas[type_name] = self._writer.register_schema(
                name=type_name, encoding="ros2msg", data=message_definition(type_name).encode())
        meta = {"offered_qos_profiles": qos_metadata(qos) if qos is not None else ""}
        self._channels[topic] = self._writer.register_channel(
            topic=topic, message_encoding="cdr", schema_id=self._schemas[type_name], metadata=meta)
        self.counts[topic] = 0

    def write(self, topic: str, data: bytes, log_time_ns: int, publish_time_ns: int | None = None) -> None:
        self._writer.add_message(self._channels[topic], log_time=log_time_ns, data=data,
                                 publish_time=log_time_ns if publish_time_ns is None else publish_time_ns,
                                 sequence=self.counts[topic])
        self.counts[topic] += 1
        if time.monotonic() - self._last_flush >= self.flush_period:
            self.flush()

    def flush(self) -> None:
        self._writer.flush()
        self._last_flush = time.monotonic()

    def close(self) -> None:
        if not self.closed:
            self._writer.finish()
            self._stream.close()
            self.closed = True


# ---------------------------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------------------------

@dataclass
class TopicLog:
    """All messages of one topic: ``log_time`` (s, (n,)), ``fields`` (dotted name -> array with
    the message index first, or a list where sizes vary) and the decoded ``messages``."""

    topic: str
    type_name: str
    log_time: np.ndarray
    fields: dict = field(default_factory=dict)
    messages: list = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.log_time)

    def __getitem__(self, name: str):
        return self.fields[name]


def flatten(msg, prefix: str = "") -> dict:
    """Dotted-name view of a decoded message: Vector3 -> (3,), Quaternion -> (4,) xyzw,
    Time -> float s, numeric sequences -> arrays, nested messages recursed."""
    slots = getattr(msg, "__slots__", None) or [k for k in vars(msg) if not k.startswith("_")]
    names = set(slots)
    if names == {"x", "y", "z"}:
        return {prefix: np.array([msg.x, msg.y, msg.z])}
    if names == {"x", "y", "z", "w"}:
        return {prefix: np.array([msg.x, msg.y, msg.z, msg.w])}
    if names == {"sec", "nanosec"}:
        return {prefix: msg.sec + msg.nanosec * 1e-9}
    out = {}
    for name in slots:
        value = getattr(msg, name)
        key = f"{prefix}.{name}" if prefix else name
        if isinstance(value, (bool, int, float, str, bytes)):
            out[key] = value
        elif isinstance(value, (list, tuple)) or isinstance(value, np.ndarray):
            if len(value) and not isinstance(value[0], (bool, int, float, np.generic)):
                items = [flatten(v) for v in value]
                out[key] = [item.get("", item) for item in items]
                if items and "" in items[0]:
                    out[key] = np.array(out[key])
            else:
                out[key] = np.asarray(value, dtype=float) if len(value) else np.zeros(0)
        else:
            out.update(flatten(value, key))
    return out


def _stack(values: list):
    try:
        arr = np.asarray(values)
        if arr.dtype != object:
            return arr
    except ValueError:
        pass
    return list(values)


def iter_records(path: str | Path):
    """(schema, channel, message) of every message; tolerant of a missing end (killed writer)."""
    with open(path, "rb") as fh:
        try:
            reader = make_reader(fh)
            summary = reader.get_summary()
            if summary is not None and summary.chunk_indexes:
                yield from reader.iter_messages(log_time_order=True)
                return
        except McapError:
            pass
    schemas, channels = {}, {}
    with open(path, "rb") as fh:
        try:
            for record in StreamReader(fh, emit_chunks=False).records:
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    channels[record.id] = record
                elif isinstance(record, Message):
                    ch = channels[record.channel_id]
                    yield schemas.get(ch.schema_id), ch, record
        except (McapError, EOFError, ValueError, KeyError) as exc:  # truncated tail: stop there
            del exc


def read_log(path: str | Path, topics: list[str] | None = None, keep_messages: bool = False) -> dict[str, TopicLog]:
    """Read an MCAP log into ``{topic: TopicLog}``: the replay library of tools and tests.

    Per topic, in log-time order: ``log_time`` (s, the recorder's receive time, wall clock) and one
    array per field named by its dotted path with the message index first (see :func:`flatten`):
    ``log["/spacecraft/state"]["header.stamp"]`` (n,) sim time in s, ``["attitude"]`` (n, 4) xyzw,
    ``["wheel_speeds"]`` (n, W); strings give string arrays, sequences of varying length or of
    messages give lists (``log["/planner/plans"]["cones"][i]`` is a list of dicts). Every message
    is decoded from its own schema (so this also checks the log is self-describing); ``topics``
    limits the topics read; ``keep_messages`` keeps the decoded message objects too. A file whose
    writer was killed is read up to its last complete chunk.
    """
    factory = DecoderFactory()
    decoders, rows = {}, {}
    for schema, channel, message in iter_records(path):
        if topics is not None and channel.topic not in topics:
            continue
        if schema.id not in decoders:
            decoders[schema.id] = factory.decoder_for(channel.message_encoding, schema)
        decoded = decoders[schema.id](message.data)
        entry = rows.setdefault(channel.topic, (schema.name, [], [], []))
        entry[1].append(message.log_time * 1e-9)
        entry[2].append(flatten(decoded))
        if keep_messages:
            entry[3].append(decoded)
    out = {}
    for topic, (type_name, times, flats, msgs) in rows.items():
        keys = flats[0].keys()
        out[topic] = TopicLog(topic, type_name, np.asarray(times),
                              {k: _stack([f[k] for f in flats]) for k in keys}, msgs)
    return out
