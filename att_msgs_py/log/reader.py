"""The one reader of the suite's MCAP logs, for tools and tests.

:func:`read_log` returns per-topic arrays with timestamps; it also reads a file whose end is
missing (killed writer) up to its last whole record (``att-log repair`` makes such a file whole for
every reader).
"""
from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mcap_ros2.decoder import DecoderFactory

from att_msgs_py import topics as suite_topics
from att_msgs_py.log.repair import LogFileError, Scan, printable, salvaged_messages


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
            if len(value) and isinstance(value[0], str):
                out[key] = list(value)
            elif len(value) and not isinstance(value[0], (bool, int, float, np.generic)):
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
    """(schema, channel, message) of every message, in log-time order for a complete file; a file
    whose writer was killed is read in file order up to its last whole record. Every file is read by
    :func:`~att_msgs_py.log.repair.salvaged_messages` (CRCs checked, decompression bounded):
    :class:`~att_msgs_py.log.repair.LogFileError` (one line: the problem and its byte offset) for a
    file that is not MCAP, holds no whole header, or has a damaged record before its end."""
    scan = Scan(Path(path), 0)
    records = list(salvaged_messages(path, scan))
    if not scan.header:
        raise LogFileError(f"{printable(path)}: {scan.problem or 'no header record'}; nothing to read")
    if scan.damaged:
        raise LogFileError(f"{printable(path)}: {scan.problem}")
    if scan.complete:
        records.sort(key=lambda r: r[2].log_time)        # stable: the file order of equal times
    yield from records


def _decoder(factory: DecoderFactory, path, channel, schema):
    """The decoder of ``schema`` (a ros2msg text named ``pkg/msg/Name``, parsed by ``mcap_ros2``
    without importing anything); :class:`LogFileError` (one line) for a schema that does not parse:
    its name and text come from the file, so whatever the parser raises is the file's fault."""
    try:
        decoder = factory.decoder_for(channel.message_encoding, schema)
    except Exception as err:
        decoder, why = None, f"{type(err).__name__}: {printable(err)}"
    else:
        why = f"no decoder for encoding '{printable(channel.message_encoding)}'"
    if decoder is None:
        raise LogFileError(f"{printable(path)}: topic '{printable(channel.topic)}': schema '{printable(schema.name)}' "
                           f"does not decode ({why})")
    return decoder


def read_log(path: str | Path, topics: list[str] | None = None,
             keep_messages: bool | Collection[str] = (suite_topics.PLANS,)) -> dict[str, TopicLog]:
    """Read an MCAP log into ``{topic: TopicLog}``: the replay library of tools and tests.

    Per topic, in log-time order: ``log_time`` (s, the recorder's receive time, wall clock) and one
    array per field named by its dotted path with the message index first (see :func:`flatten`):
    ``log["/spacecraft/state"]["header.stamp"]`` (n,) sim time in s, ``["attitude"]`` (n, 4) xyzw,
    ``["wheel_speeds"]`` (n, W); strings give string arrays, sequences of varying length or of
    messages give lists (``log["/planner/plans"]["cones"][i]`` is a list of dicts). Every message
    is decoded from its own schema (so this also checks the log is self-describing); ``topics``
    limits the topics read; the decoded message objects are kept too (``TopicLog.messages``) for
    the topics in ``keep_messages`` (True: all; default: the plans, which tools turn into
    :class:`~att_msgs_py.types.Plan` with :func:`att_msgs_py.convert.plan_from_msg`). A file whose
    writer was killed is read up to its last complete chunk. :class:`LogFileError` (one line) for a
    read topic whose schema does not parse or whose message does not decode.
    """
    factory = DecoderFactory()
    decoders, rows = {}, {}
    for schema, channel, message in iter_records(path):
        if topics is not None and channel.topic not in topics:
            continue
        if schema is None:
            raise LogFileError(f"{printable(path)}: topic '{printable(channel.topic)}' has no schema to decode it")
        if schema.id not in decoders:
            decoders[schema.id] = _decoder(factory, path, channel, schema)
        try:
            decoded = decoders[schema.id](message.data)
        except Exception as err:      # the bytes come from the file: whatever their decoding raises
            raise LogFileError(f"{printable(path)}: message {message.sequence} of topic '{printable(channel.topic)}' "
                               f"does not decode as '{printable(schema.name)}' ({type(err).__name__}: "
                               f"{printable(err)})") from None
        entry = rows.setdefault(channel.topic, (schema.name, [], [], []))
        entry[1].append(message.log_time * 1e-9)
        entry[2].append(flatten(decoded))
        if keep_messages is True or (keep_messages and channel.topic in keep_messages):
            entry[3].append(decoded)
    out = {}
    for topic, (type_name, times, flats, msgs) in rows.items():
        keys = flats[0].keys()
        out[topic] = TopicLog(topic, type_name, np.asarray(times),
                              {k: _stack([f[k] for f in flats]) for k in keys}, msgs)
    return out
