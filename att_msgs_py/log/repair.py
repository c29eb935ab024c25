"""Crash-safe logs: read an MCAP file record by record up to the first missing or damaged byte,
and rewrite what was fully on disk into a valid, indexed MCAP (``att-log repair``).

A recorder killed with SIGKILL leaves its file without data end, summary, footer and closing magic,
perhaps with its last chunk cut short; ``rosbags`` and ``mcap``'s seeking reader refuse such a file.
:func:`scan_records` reads it with ``mcap``'s :class:`~mcap.stream_reader.StreamReader` (every read
bounded by what is left of the file, so a damaged length field cannot allocate more) and stops
at the first record that is cut, fails its CRC, has an opcode the MCAP specification does not
define (the specification lets a reader skip such a record; a suite log holds none, so one is a
damaged byte: a chunk's opcode flipped would otherwise drop that chunk and go on after it) or is of
a kind that cannot be where it is (a second header, a summary record before the data end, a data
record after it, a schema, channel or message outside the chunks of a chunked file). Every
CRC of the file is checked: each chunk's (a chunk whose CRC reads 0 is refused: nothing could tell
its damaged payload from the recorded one), the data section's in the data end (the header and the
message indexes, which no chunk CRC covers) and the summary's in the footer (the summary's
statistics, indexes and offsets, and the footer's summary start).
:func:`repair` writes every record read before that point (header, schemas, channels with their
metadata, messages byte for byte with their log time, publish time and sequence, attachments,
metadata) through ``mcap``'s Writer, which adds the index and the summary. A chunk the kill cut
short is dropped: the recorder flushes a chunk at least every 0.5 s, so that is all that is lost.
"""
from __future__ import annotations

import io
import itertools
import os
import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import zstandard
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.records import (
    Attachment,
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Message,
    Metadata,
    Schema,
    Statistics,
)
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import CompressionType, Writer

MAGIC = b"\x89MCAP0\r\n"
CHUNK_SIZE = 256 * 1024
MAX_CHUNK_BYTES = 64 << 20         # a chunk claiming or inflating to more is refused before it is inflated
# what a cut or damaged record raises inside mcap's readers and decompressors
DAMAGE = (McapError, ValueError, EOFError, struct.error, zstandard.ZstdError, RuntimeError, MemoryError,
          KeyError, IndexError, OverflowError)
KEPT = (Header, Schema, Channel, Message, Attachment, Metadata)
_OPCODES = frozenset(int(o) for o in Opcode)
# what each section may hold (MCAP specification): a record of another kind there is a damaged opcode
_DATA_OPCODES = frozenset(int(o) for o in (Opcode.HEADER, Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE,
                                            Opcode.CHUNK, Opcode.MESSAGE_INDEX, Opcode.ATTACHMENT,
                                            Opcode.METADATA, Opcode.DATA_END))
_SUMMARY_OPCODES = frozenset(int(o) for o in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.CHUNK_INDEX,
                                               Opcode.ATTACHMENT_INDEX, Opcode.METADATA_INDEX, Opcode.STATISTICS,
                                               Opcode.SUMMARY_OFFSET, Opcode.FOOTER))
# what a chunked data section holds only inside its chunks
_CHUNKED_OPCODES = frozenset(int(o) for o in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE))


class LogFileError(ValueError):
    """A file that is not an MCAP log, or holds nothing that can be recovered."""


class NotMcapError(LogFileError):
    """A file whose first bytes are not the MCAP magic (not a log cut short: another kind of file)."""


def printable(text: str, limit: int = 200) -> str:
    """``text`` safe to print to a terminal: control characters (C0, DEL, C1) and other
    non-printable ones escaped as ``\\xNN``/``\\uNNNN``, at most ``limit`` characters kept."""
    out = "".join(c if c.isprintable() else f"\\x{ord(c):02x}" if ord(c) < 0x100 else f"\\u{ord(c):04x}"
                  for c in str(text)[:limit])
    return out + ("..." if len(str(text)) > limit else "")


@dataclass
class Scan:
    """What :func:`scan_records` found in a file (filled while it is read)."""

    path: Path
    size: int
    profile: str = ""
    library: str = ""
    header: bool = False
    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    counts: dict[int, int] = field(default_factory=dict)     # channel id -> messages
    messages: int = 0
    start_ns: int | None = None                              # log time range of the messages read
    end_ns: int | None = None
    chunks: int = 0
    chunk_indexes: int = 0
    statistics: Statistics | None = None
    good_bytes: int = 0          # end of the last record read whole (CRC checked)
    complete: bool = False       # data end, summary, footer and closing magic all read
    problem: str = ""            # why reading stopped before the end ("" when complete)

    @property
    def damaged(self) -> bool:
        """Reading stopped at a damaged or hostile record (not merely at a cut end)."""
        return self.problem.startswith("damaged record")

    @property
    def indexed(self) -> bool:
        """Complete with a summary: statistics, and a chunk index per chunk."""
        return self.complete and self.statistics is not None and self.chunk_indexes == self.chunks

    @property
    def dropped_bytes(self) -> int:
        return self.size - self.good_bytes


class _StrictReader(StreamReader):
    """mcap's stream reader that refuses, instead of skipping or taking it, a record that cannot be
    where it is: one of an unknown opcode; a second header; in the data section, a record only the
    summary holds (a chunk whose opcode read as a summary offset would be skipped and the reading
    go on after it); after the data end, a data record (a summary's channel flipped to a message
    outside any CRC); and, once the data section has held a chunk, a schema, channel or message
    outside one (a chunked writer puts every one inside a chunk: a message index flipped to a
    message would pass its bytes on as a message no CRC covers). A file without chunks (another
    writer's flat layout) keeps its top-level messages."""

    _in_summary = False
    _chunked = False
    _header = False

    def _read_record(self, opcode: int, length: int):
        if opcode not in _OPCODES:
            raise ValueError(f"record of unknown opcode 0x{opcode:02x}")
        name = Opcode(opcode).name.lower().replace("_", " ")
        if opcode not in (_SUMMARY_OPCODES if self._in_summary else _DATA_OPCODES):
            raise ValueError(f"a {name} record {'after' if self._in_summary else 'before'} the data end")
        if opcode == Opcode.HEADER and self._header:
            raise ValueError("a second header record")
        if self._chunked and not self._in_summary and opcode in _CHUNKED_OPCODES:
            raise ValueError(f"a {name} record outside a chunk, after chunks")
        record = super()._read_record(opcode, length)
        self._header = self._header or isinstance(record, Header)
        self._in_summary = self._in_summary or isinstance(record, DataEnd)
        self._chunked = self._chunked or isinstance(record, Chunk)
        return record


class _Bounded:
    """A read-only view of a file whose reads never ask for more than what is left."""

    def __init__(self, fh, size: int):
        self._fh, self._size, self.pos = fh, size, 0

    def read(self, n: int = -1) -> bytes:
        n = self._size - self.pos if n is None or n < 0 else min(n, self._size - self.pos)
        data = self._fh.read(n)
        self.pos += len(data)
        return data


def check_magic(path: str | Path) -> int:
    """Size of the file; :class:`LogFileError` if it is missing or empty, :class:`NotMcapError` if it
    is not an MCAP file."""
    path = Path(path)
    if not path.is_file():
        raise LogFileError(f"{path}: {'not a regular file' if path.exists() else 'no such file'}")
    size = path.stat().st_size
    with open(path, "rb") as fh:
        start = fh.read(len(MAGIC))
    if size == 0:
        raise LogFileError(f"{path}: the file is empty (0 bytes: its writer stopped before writing anything)")
    if start != MAGIC[:len(start)]:
        raise NotMcapError(f"{path}: not an MCAP file (it does not start with the MCAP magic bytes)")
    if len(start) < len(MAGIC):
        raise LogFileError(f"{path}: only {size} bytes, cut inside the MCAP magic: nothing to recover")
    return size


def _inflate(chunk: Chunk) -> bytes:
    """A chunk's records, decompressed into at most its claimed size (itself at most
    :data:`MAX_CHUNK_BYTES`): a frame that claims or inflates to more is refused before, or as soon
    as, it passes the claim, so a decompression bomb never allocates more than the bound."""
    size = chunk.uncompressed_size
    if size > MAX_CHUNK_BYTES:
        raise ValueError(f"chunk claims {size} uncompressed bytes (at most {MAX_CHUNK_BYTES} are read)")
    if chunk.compression == "":
        data = chunk.data
    elif chunk.compression == "zstd":
        content = zstandard.frame_content_size(chunk.data)
        if content not in (-1, size):
            raise ValueError(f"zstd frame of {content} bytes in a chunk of {size}")
        data = bytearray()
        with zstandard.ZstdDecompressor().stream_reader(io.BytesIO(chunk.data)) as reader:
            while len(data) <= size and (piece := reader.read(size + 1 - len(data))):
                data += piece
        data = bytes(data)
    elif chunk.compression == "lz4":
        import lz4.frame

        inflater = lz4.frame.LZ4FrameDecompressor()
        data = inflater.decompress(chunk.data, max_length=size + 1)
    else:
        raise ValueError(f"chunk compressed with '{printable(chunk.compression, 20)}', not zstd, lz4 or none")
    if len(data) != size:
        raise ValueError(f"chunk inflates to {'more than ' if len(data) > size else ''}{len(data)} bytes, "
                         f"not the {size} it claims")
    return data


def _chunk_records(chunk: Chunk) -> list:
    """The records of a chunk, its CRC checked; DAMAGE for a chunk that does not decode or has no
    CRC (0: the MCAP specification's "not computed"; every writer the suite reads computes one, so
    a 0 is a damaged field, and nothing would tell a damaged payload from the recorded one)."""
    data = _inflate(chunk)
    if chunk.uncompressed_crc == 0:
        raise ValueError("chunk without a CRC (its CRC field reads 0): its records cannot be checked")
    plain = Chunk(compression="", data=data, message_end_time=chunk.message_end_time,
                  message_start_time=chunk.message_start_time, uncompressed_crc=chunk.uncompressed_crc,
                  uncompressed_size=chunk.uncompressed_size)
    return breakup_chunk(plain, validate_crc=True)


def _problem(exc: Exception, start: int, end: int, size: int, footer: bool, whole: bool) -> str:
    """Why reading stopped at the record starting at ``start``; ``whole``: the record was read to
    its end, or its length field says it ends within the file (so it is damaged or hostile, not cut:
    a flipped opcode or inner length would otherwise read on to the end and pass for a cut)."""
    if footer:
        return f"the closing magic after the footer is missing or wrong ({printable(exc)})"
    if isinstance(getattr(exc, "record", None), DataEnd):
        return (f"damaged record at byte {start}: the data end's CRC of the data section does not match its bytes "
                "(a byte of the header or of a message index is damaged: every chunk's own CRC matched)")
    if whole:
        return f"damaged record at byte {start}: {printable(exc)}"
    if start >= size:
        return (f"no data end, summary or footer after the last complete record, which ends at byte {start} "
                "(the writer did not finish)")
    if end >= size:
        return f"the last record (at byte {start}) is cut short: its writer was stopped while writing it"
    return f"damaged record at byte {start}: {printable(exc)}"


def _check_channels(scan: Scan, records: list) -> None:
    """KeyError for a message on a channel no earlier record defines (the whole chunk is refused)."""
    known = set(scan.channels)
    for r in records:
        if isinstance(r, Channel):
            known.add(r.id)
        elif isinstance(r, Message) and r.channel_id not in known:
            raise KeyError(f"message on channel {r.channel_id}, which no channel record defines")


def _check_summary_copy(scan: Scan, record) -> None:
    """ValueError for a summary's schema or channel that differs from the data section's record of
    its id (the summary has no CRC the reader checks before it is used; a difference is a damaged
    byte). One of an id the data section lacks (a writer that wrote no chunk holding it) is kept."""
    known = scan.schemas if isinstance(record, Schema) else scan.channels
    if record.id in known and known[record.id] != record:
        raise ValueError(f"the summary's {type(record).__name__.lower()} {record.id} differs from the data section's")


def _declared_end(fh, start: int) -> int:
    """Where the record starting at ``start`` ends by its own length field (read without moving ``fh``)."""
    return start + 9 + int.from_bytes(os.pread(fh.fileno(), 8, start + 1).ljust(8, b"\0"), "little")


def _summary_crc(fh, start: int, end: int) -> int:
    """CRC32 of the file's bytes ``[start, end)``, read in pieces without moving ``fh``."""
    crc, pos = 0, start
    while pos < end:
        piece = os.pread(fh.fileno(), min(1 << 20, end - pos), pos)
        if not piece:
            break
        crc, pos = zlib.crc32(piece, crc), pos + len(piece)
    return crc


def _check_footer(fh, footer: Footer, start: int, summary_start: int | None) -> None:
    """ValueError for a footer whose summary start or summary CRC (over the summary section and the
    footer's first two fields, as the MCAP specification defines it) disagrees with the file."""
    if summary_start is None:
        raise ValueError("a footer without a data end before it")
    has_summary = start > summary_start
    if footer.summary_start != (summary_start if has_summary else 0):
        raise ValueError(f"the footer's summary start {footer.summary_start} is not where the summary is "
                         f"({summary_start if has_summary else 'none'})")
    if footer.summary_crc != 0:
        crc = _summary_crc(fh, summary_start, start + 1 + 8 + 8 + 8)
        if crc != footer.summary_crc:
            raise ValueError(f"summary CRC mismatch (footer says {footer.summary_crc:#010x}, the summary's bytes "
                             f"{crc:#010x})")


def _take(scan: Scan, record) -> bool:
    """Account for one record; True when it is to be passed on."""
    if isinstance(record, Header):
        scan.header, scan.profile, scan.library = True, record.profile, record.library
    elif isinstance(record, Schema):
        if record.id in scan.schemas:
            return False
        scan.schemas[record.id] = record
    elif isinstance(record, Channel):
        if record.id in scan.channels:
            return False
        scan.channels[record.id] = record
        scan.counts[record.id] = 0
    elif isinstance(record, Message):
        scan.counts[record.channel_id] += 1
        scan.messages += 1
        scan.start_ns = record.log_time if scan.start_ns is None else min(scan.start_ns, record.log_time)
        scan.end_ns = record.log_time if scan.end_ns is None else max(scan.end_ns, record.log_time)
    elif isinstance(record, ChunkIndex):
        scan.chunk_indexes += 1
    elif isinstance(record, Statistics):
        scan.statistics = record
    return isinstance(record, KEPT)


def scan_records(path: str | Path, scan: Scan | None = None) -> Iterator:
    """Header, schemas and channels (once per id), messages, attachments and metadata of an MCAP
    file in file order, up to the first record that is cut or damaged; ``scan`` (a :class:`Scan`)
    is filled as the file is read. :class:`LogFileError` if the file is not MCAP at all."""
    path = Path(path)
    size = check_magic(path)
    scan = scan if scan is not None else Scan(path, size)
    scan.path, scan.size, scan.good_bytes = path, size, len(MAGIC)
    with open(path, "rb") as fh:
        view = _Bounded(fh, size)
        records = _StrictReader(view, emit_chunks=True, validate_crcs=True, record_size_limit=None).records
        footer, summary, start, summary_start = False, False, len(MAGIC), None
        while True:
            whole = False
            try:
                record = next(records)
                whole = True
                if _declared_end(fh, start) > size:
                    raise ValueError(f"its length field runs past the end of the file ({size} bytes)")
                if not scan.header and not isinstance(record, Header):
                    raise ValueError(f"the first record is a {type(record).__name__}, not a header")
                inner = _chunk_records(record) if isinstance(record, Chunk) else [record]
                _check_channels(scan, inner)
                if summary and isinstance(record, (Schema, Channel)):
                    _check_summary_copy(scan, record)
                if isinstance(record, Footer):
                    _check_footer(fh, record, start, summary_start)
            except StopIteration:
                scan.complete, scan.good_bytes = footer, view.pos
                return
            except DAMAGE as exc:
                whole = whole or (size - start >= 9 and _declared_end(fh, start) <= size)
                scan.problem = _problem(exc, start, view.pos, size, footer, whole)
                return
            passed = [r for r in inner if _take(scan, r)]
            scan.chunks += isinstance(record, Chunk)
            footer = footer or isinstance(record, Footer)
            summary = summary or isinstance(record, DataEnd)
            start = scan.good_bytes = view.pos
            if isinstance(record, DataEnd):
                summary_start = view.pos
            yield from passed


def salvaged_messages(path: str | Path, scan: Scan | None = None) -> Iterator[tuple[Schema | None, Channel, Message]]:
    """(schema, channel, message) of every message :func:`scan_records` reads, in file order;
    ``scan`` is filled as the file is read."""
    scan = scan if scan is not None else Scan(Path(path), 0)
    for record in scan_records(path, scan):
        if isinstance(record, Message):
            channel = scan.channels[record.channel_id]
            yield scan.schemas.get(channel.schema_id), channel, record


@dataclass
class Repair:
    """A repair: what the input held (``source``), where it went and what the output holds."""

    source: Scan
    output: Path
    result: Scan


def _beside(path: Path, suffix: str) -> Path:
    """``IN.SUFFIX.mcap`` next to ``IN.mcap`` (or next to ``IN``, a name without ``.mcap``)."""
    stem = path.name[:-len(".mcap")] if path.name.endswith(".mcap") else path.name
    return path.with_name(f"{stem}.{suffix}.mcap")


def default_output(path: str | Path) -> Path:
    """``IN.repaired.mcap`` next to ``IN.mcap``."""
    return _beside(Path(path), "repaired")


def unused_output(path: str | Path, kind: str = "repaired") -> Path:
    """``IN.KIND.mcap`` beside ``IN.mcap`` (:func:`default_output` for ``repaired``), or
    ``IN.KIND.N.mcap`` with the smallest N ≥ 2 that no file takes: a recorder restarted more than
    once on one path keeps every file it sets aside."""
    names = itertools.chain([kind], (f"{kind}.{n}" for n in itertools.count(2)))
    return next(c for c in (_beside(Path(path), name) for name in names) if not c.exists() and not c.is_symlink())


def _copy(src: Path, stream) -> Scan:
    """Write every record :func:`scan_records` reads from ``src`` to ``stream`` as a new MCAP."""
    scan = Scan(src, 0)
    writer, schemas, channels = None, {}, {}
    for r in scan_records(src, scan):
        if isinstance(r, Header):
            writer = Writer(stream, chunk_size=CHUNK_SIZE, compression=CompressionType.ZSTD, enable_data_crcs=True)
            writer.start(profile=r.profile, library=r.library)
        elif isinstance(r, Schema):
            schemas[r.id] = writer.register_schema(name=r.name, encoding=r.encoding, data=r.data)
        elif isinstance(r, Channel):
            channels[r.id] = writer.register_channel(topic=r.topic, message_encoding=r.message_encoding,
                                                     schema_id=schemas.get(r.schema_id, 0), metadata=r.metadata)
        elif isinstance(r, Message):
            writer.add_message(channels[r.channel_id], log_time=r.log_time, data=r.data,
                               publish_time=r.publish_time, sequence=r.sequence)
        elif isinstance(r, Attachment):
            writer.add_attachment(create_time=r.create_time, log_time=r.log_time, name=r.name,
                                  media_type=r.media_type, data=r.data)
        elif isinstance(r, Metadata):
            writer.add_metadata(r.name, r.metadata)
    if writer is None:
        raise LogFileError(f"{src}: {scan.problem or 'no header record'}; nothing to recover")
    writer.finish()
    return scan


def repair(path: str | Path, output: str | Path | None = None, *, in_place: bool = False) -> Repair:
    """Rewrite ``path`` into a complete, indexed MCAP at ``output`` (default ``IN.repaired.mcap``;
    ``in_place``: the input itself), written to a temporary file in the same directory and renamed
    over the target only once it has been read back whole. A complete input is copied without loss."""
    src = Path(path)
    check_magic(src)
    dst = src if in_place else Path(output) if output is not None else default_output(src)
    if not in_place and dst.resolve() == src.resolve():
        raise LogFileError(f"{dst}: the output would overwrite the input; use --in-place for that")
    tmp = dst.with_name(f".{dst.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as stream:
            source = _copy(src, stream)
            stream.flush()
            os.fsync(stream.fileno())
        result = Scan(tmp, 0)
        for _ in scan_records(tmp, result):
            pass
        if not result.indexed or result.messages != source.messages:
            raise LogFileError(f"{src}: the rewritten file did not read back whole ({result.messages} of "
                               f"{source.messages} messages; {result.problem or 'no index'}); nothing was written")
        os.replace(tmp, dst)
    finally:
        tmp.unlink(missing_ok=True)
    result.path = dst
    return Repair(source, dst, result)
