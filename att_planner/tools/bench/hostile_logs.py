"""Damaged and hostile MCAP files made from one real recording, for :mod:`.logtools`.

:func:`recorded_log` records 5 s of ``swift_demo``'s in-process closed loop
(:class:`~att_planner.tools.closed_loop.ClosedLoop`) through the recorder's writer
(:class:`~att_msgs_py.log.writer.LogWriter`: rosbag2 layout, zstd chunks, message indexes, a summary
with schemas, channels, statistics, chunk indexes and summary offsets, the footer), with chunks of
16 KiB so that the file has several of each record. :data:`CASES` turns its bytes into 40 files,
each named by what was done to which record (:func:`top_records` finds the records):

* ``cut``: the file ends early (after 0, 4, 9 bytes; inside the header, a chunk, a message index,
  the summary; at a chunk's end, at the data end, before the closing magic);
* ``flip``: one byte (or 16, or a field) of one record changed: header, chunk header fields
  (uncompressed size, CRC, compression, records length), chunk payload, the record's opcode and
  length, message index, data end, the summary's schema, channel, statistics, chunk index and
  summary offset, the footer;
* ``bomb``: a chunk placed before the second one whose frame inflates to 1 GiB (zstd with and
  without its content size, lz4), or that claims 2^62 bytes;
* ``name``: the recording rewritten with a schema named ``this/msg/x`` or ``os/msg/Path``, topic
  names holding terminal escape sequences (CSI, OSC, CR LF, C1) and a profile holding one.
"""
from __future__ import annotations

import io
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from mcap.opcode import Opcode

MAGIC_BYTES = 8
BOMB_BYTES = 1 << 30
SOURCE_SECONDS = 5.0
SOURCE_CHUNK = 16 * 1024


@dataclass(frozen=True)
class Record:
    """A record of the file's top level: where it starts, its opcode and content length."""

    offset: int
    opcode: int
    length: int

    @property
    def content(self) -> int:
        return self.offset + 9

    @property
    def end(self) -> int:
        return self.content + self.length


@dataclass(frozen=True)
class Case:
    name: str
    kind: str            # cut, flip, bomb or name
    make: Callable[[bytes, list[Record], Path], None]    # (source bytes, its records, output path)


def recorded_log(path: Path, seconds: float = SOURCE_SECONDS) -> Path:
    """A recording of ``seconds`` of swift_demo's closed loop, every topic the nodes publish."""
    from rclpy.serialization import serialize_message

    from att_msgs_py import qos
    from att_msgs_py.log.writer import LogWriter
    from att_planner.tools.closed_loop import ClosedLoop
    from att_planner.tools.loop_log import MESSAGES
    from att_sim.models import scenario as scen

    loop = ClosedLoop(scen.load("swift_demo"))
    log = LogWriter(path, flush_period=1e9, chunk_size=SOURCE_CHUNK)
    recorded = qos.recorded_topics()
    for topic in MESSAGES:
        log.add_topic(topic, *recorded[topic])
    loop.tap = lambda topic, t, m: log.write(topic, serialize_message(MESSAGES[topic](m)), int(round(t * 1e9)))
    loop.run(seconds)
    log.close()
    return path


def top_records(data: bytes) -> list[Record]:
    """The records between the magic bytes (opcode, 8-byte length, content), in file order."""
    out, pos = [], MAGIC_BYTES
    while pos + 9 <= len(data) - MAGIC_BYTES:
        length = int.from_bytes(data[pos + 1:pos + 9], "little")
        out.append(Record(pos, data[pos], length))
        pos += 9 + length
    return out


def nth(records: list[Record], opcode: Opcode, n: int = 0) -> Record:
    return [r for r in records if r.opcode == opcode][n]


def _write(path: Path, data: bytes) -> None:
    path.write_bytes(bytes(data))


def cut(where: Callable[[bytes, list[Record]], int]):
    return lambda data, records, path: _write(path, data[:where(data, records)])


def flip(where: Callable[[list[Record]], int], mask: int = 0x5A, count: int = 1, spread: int = 1):
    """``count`` bytes xor ``mask``, ``spread`` bytes apart, from ``where(records)``."""
    def make(data: bytes, records: list[Record], path: Path) -> None:
        out, start = bytearray(data), where(records)
        for i in range(count):
            out[start + i * spread] ^= mask
        _write(path, out)
    return make


def put(where: Callable[[list[Record]], int], value: bytes):
    """``value`` written over the bytes at ``where(records)``."""
    def make(data: bytes, records: list[Record], path: Path) -> None:
        out, start = bytearray(data), where(records)
        out[start:start + len(value)] = value
        _write(path, out)
    return make


def both(first, second):
    """``first``'s change, then ``second``'s on its result."""
    def make(data: bytes, records: list[Record], path: Path) -> None:
        first(data, records, path)
        second(path.read_bytes(), records, path)
    return make


def chunk_field(n: int, field_offset: int) -> Callable[[list[Record]], int]:
    return lambda records: nth(records, Opcode.CHUNK, n).content + field_offset


def chunk_payload(n: int, fraction: float) -> Callable[[list[Record]], int]:
    """A byte ``fraction`` of the way into the compressed records of chunk ``n``."""
    def where(records: list[Record]) -> int:
        c = nth(records, Opcode.CHUNK, n)
        return c.end - int((1.0 - fraction) * (c.length - 60))
    return where


# -- decompression bombs -------------------------------------------------------------------------

def chunk_content(data: bytes, uncompressed_size: int, compression: str) -> bytes:
    """A Chunk record's content: start and end times, uncompressed size, CRC 0, compression, records."""
    name = compression.encode()
    return (bytes(16) + uncompressed_size.to_bytes(8, "little") + bytes(4) + len(name).to_bytes(4, "little") + name
            + len(data).to_bytes(8, "little") + data)


def zstd_bomb(size: int = BOMB_BYTES, sized: bool = True) -> bytes:
    """A zstd frame of ``size`` zeros (a few tens of kB); ``sized``: its content size in the frame."""
    import zstandard

    compressor = zstandard.ZstdCompressor(level=1, write_content_size=sized)
    chunker = compressor.chunker(size=size if sized else -1, chunk_size=1 << 20)
    out, zeros = io.BytesIO(), bytes(1 << 24)
    for _ in range(size // len(zeros)):
        for piece in chunker.compress(zeros):
            out.write(piece)
    for piece in chunker.finish():
        out.write(piece)
    return out.getvalue()


def lz4_bomb(size: int = BOMB_BYTES) -> bytes:
    import lz4.frame

    compressor = lz4.frame.LZ4FrameCompressor(content_checksum=False)
    zeros = bytes(1 << 24)
    return (compressor.begin(source_size=size) + b"".join(compressor.compress(zeros) for _ in range(size // len(zeros)))
            + compressor.flush())


def bomb(frame: Callable[[], bytes], claimed: int, compression: str):
    """A forged chunk (``frame`` claiming ``claimed`` bytes) placed before the second chunk."""
    def make(data: bytes, records: list[Record], path: Path) -> None:
        content = chunk_content(frame(), claimed, compression)
        at = nth(records, Opcode.CHUNK, 1).offset
        _write(path, data[:at] + bytes([Opcode.CHUNK]) + len(content).to_bytes(8, "little") + content + data[at:])
    return make


# -- hostile names -------------------------------------------------------------------------------

def renamed(topics: dict[str, str] | None = None, schemas: dict[str, str] | None = None, profile: str | None = None):
    """The recording rewritten through mcap's Writer with some topic and schema names (or the
    profile) replaced; every message kept."""
    def make(data: bytes, records: list[Record], path: Path) -> None:
        from mcap.reader import make_reader
        from mcap.writer import CompressionType, Writer

        reader = make_reader(io.BytesIO(data))
        header = reader.get_header()
        with open(path, "wb") as fh:
            writer = Writer(fh, chunk_size=SOURCE_CHUNK, compression=CompressionType.ZSTD)
            writer.start(profile=profile if profile is not None else header.profile, library=header.library)
            schema_ids, channel_ids = {}, {}
            for schema, channel, message in reader.iter_messages(log_time_order=False):
                if schema.id not in schema_ids:
                    schema_ids[schema.id] = writer.register_schema(
                        (schemas or {}).get(schema.name, schema.name), schema.encoding, schema.data)
                if channel.id not in channel_ids:
                    channel_ids[channel.id] = writer.register_channel(
                        (topics or {}).get(channel.topic, channel.topic), channel.message_encoding,
                        schema_ids[schema.id], channel.metadata)
                writer.add_message(channel_ids[channel.id], message.log_time, message.data, message.publish_time,
                                   message.sequence)
            writer.finish()
    return make


def _summary_start(data: bytes, records: list[Record]) -> int:
    return nth(records, Opcode.DATA_END).end


CASES: tuple[Case, ...] = (
    Case("cut after 0 bytes", "cut", cut(lambda d, r: 0)),
    Case("cut after 4 bytes (inside the magic)", "cut", cut(lambda d, r: 4)),
    Case("cut after 9 bytes", "cut", cut(lambda d, r: 9)),
    Case("cut inside the header", "cut", cut(lambda d, r: nth(r, Opcode.HEADER).content + 6)),
    Case("cut inside the first chunk", "cut", cut(lambda d, r: nth(r, Opcode.CHUNK).content + 200)),
    Case("cut at the end of the second chunk", "cut", cut(lambda d, r: nth(r, Opcode.CHUNK, 1).end)),
    Case("cut inside a message index", "cut", cut(lambda d, r: nth(r, Opcode.MESSAGE_INDEX, 3).content + 5)),
    Case("cut at the data end", "cut", cut(lambda d, r: nth(r, Opcode.DATA_END).offset)),
    Case("cut inside the summary", "cut", cut(lambda d, r: nth(r, Opcode.CHANNEL).content + 20)),
    Case("cut before the closing magic", "cut", cut(lambda d, r: len(d) - MAGIC_BYTES)),
    Case("flip in the header's profile", "flip", flip(lambda r: nth(r, Opcode.HEADER).content + 5)),
    Case("flip in the header's length", "flip", flip(lambda r: nth(r, Opcode.HEADER).offset + 1, 0x01)),
    Case("flip in a chunk's uncompressed size", "flip", flip(chunk_field(2, 16), 0x01)),
    Case("high byte of a chunk's uncompressed size", "flip", flip(chunk_field(2, 23), 0x40)),
    Case("flip in a chunk's CRC", "flip", flip(chunk_field(2, 24))),
    Case("a chunk's CRC set to 0 and its payload flipped", "flip", both(put(chunk_field(2, 24), bytes(4)),
                                                                        flip(chunk_payload(2, 0.5)))),
    Case("flip in a chunk's compression name", "flip", flip(chunk_field(2, 33), 0x01)),
    Case("flip in a chunk's records length", "flip", flip(chunk_field(2, 37), 0x01)),
    Case("flip in a chunk's opcode", "flip", flip(lambda r: nth(r, Opcode.CHUNK, 2).offset, 0x01)),
    Case("flip in a chunk's record length", "flip", flip(lambda r: nth(r, Opcode.CHUNK, 2).offset + 3, 0x01)),
    Case("flip in the first chunk's payload (schemas)", "flip", flip(chunk_payload(0, 0.1))),
    Case("flip in a chunk's payload", "flip", flip(chunk_payload(2, 0.5))),
    Case("16 flipped bytes in a chunk's payload", "flip", flip(chunk_payload(5, 0.05), count=16, spread=97)),
    Case("flip in a message index", "flip", flip(lambda r: nth(r, Opcode.MESSAGE_INDEX, 4).content + 6)),
    Case("flip in the data end's CRC", "flip", flip(lambda r: nth(r, Opcode.DATA_END).content)),
    Case("flip in the summary's schema", "flip", flip(lambda r: nth(r, Opcode.SCHEMA).content + 8)),
    Case("flip in the summary's channel topic", "flip", flip(lambda r: nth(r, Opcode.CHANNEL).content + 10, 0x01)),
    Case("flip in the statistics", "flip", flip(lambda r: nth(r, Opcode.STATISTICS).content + 2)),
    Case("flip in a chunk index", "flip", flip(lambda r: nth(r, Opcode.CHUNK_INDEX, 3).content + 17)),
    Case("flip in a summary offset", "flip", flip(lambda r: nth(r, Opcode.SUMMARY_OFFSET).content + 1)),
    Case("flip in the footer", "flip", flip(lambda r: nth(r, Opcode.FOOTER).content + 1)),
    Case("zstd bomb of 1 GiB, size claimed", "bomb", bomb(zstd_bomb, BOMB_BYTES, "zstd")),
    Case("zstd bomb of 1 GiB, 4 KiB claimed", "bomb", bomb(zstd_bomb, 4096, "zstd")),
    Case("zstd bomb of 256 MiB, frame unsized", "bomb", bomb(lambda: zstd_bomb(1 << 28, sized=False), 4096, "zstd")),
    Case("lz4 bomb of 1 GiB, 4 KiB claimed", "bomb", bomb(lz4_bomb, 4096, "lz4")),
    Case("chunk claiming 2^62 bytes", "bomb", bomb(lambda: bytes(64), 1 << 62, "")),
    Case("schema named this/msg/x", "name", renamed(schemas={"att_msgs/msg/ControllerStatus": "this/msg/x"})),
    Case("topic with CSI and OSC sequences", "name", renamed(topics={"/sensors/imu": "/a\x1b[2J\x1b]0;pwned\x07"})),
    Case("topic with CR LF and a C1 CSI", "name", renamed(topics={"/sensors/imu": "/b\r\n/fake 1\x9b31m"})),
    Case("profile with an escape sequence", "name", renamed(profile="ros2\x1b[31m")),
)


def make_files(out: Path, cases=CASES, source: Path | None = None) -> tuple[Path, dict[str, Path]]:
    """The recording (``source``, or a new one in ``out``) and each case's file in ``out``."""
    source = source or recorded_log(out / "recorded.mcap")
    data = source.read_bytes()
    records = top_records(data)
    files = {}
    for i, case in enumerate(cases):
        files[case.name] = out / f"{i:02d}_{case.kind}.mcap"
        case.make(data, records, files[case.name])
    return source, files

