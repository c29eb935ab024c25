"""MCAP logs exactly as rosbag2 writes them.

``ros2`` profile, one ``ros2msg`` schema per type (:func:`~att_msgs_py.log.definitions.message_definition`),
``cdr`` channels with the ``offered_qos_profiles`` metadata. Every CRC MCAP defines is written: each
chunk's, the data section's (in the data end: it covers the header and the message indexes, which
no chunk CRC does) and the summary's (in the footer), so a reader can tell a damaged byte anywhere.
Chunks are closed and flushed at least every ``flush_period`` seconds so a killed recorder loses at
most that much.
"""
from __future__ import annotations

import time
from pathlib import Path

from mcap.writer import CompressionType, Writer

from att_msgs_py.log.definitions import message_definition, normalise_type, qos_metadata


class LogWriter:
    """Append CDR messages to an MCAP file; :meth:`close` writes the summary and index."""

    def __init__(self, path: str | Path, flush_period: float = 0.5, chunk_size: int = 256 * 1024):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._stream = open(self.path, "wb")
        self._writer = Writer(self._stream, chunk_size=chunk_size, compression=CompressionType.ZSTD,
                              enable_data_crcs=True)
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
