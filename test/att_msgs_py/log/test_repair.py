"""``att-log repair`` / ``info`` without ROS: a log whose writer stopped mid-file (cut at every
kind of offset, or damaged) is rewritten into a valid, indexed MCAP holding exactly the messages
of its whole chunks, byte for byte; a complete log is copied without loss; what is not MCAP is
refused in one line with exit 2."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from att_msgs_py.log import LogWriter, iter_records
from att_msgs_py.log.cli import main as att_log
from att_msgs_py.log.repair import LogFileError, Scan, default_output, repair, scan_records
from att_msgs_py.qos import recorded_topics
from helpers.regression_log import FIXTURE

PER_CHUNK = 25                 # messages between flushes: one chunk each
TOPICS = ("/spacecraft/state", "/actuator/command", "/clock", "/controller/status")   # types as in the fixture


def fixture_messages(n: int = 400) -> list:
    """The first ``n`` fixture messages of :data:`TOPICS` as (topic, data, log_time, publish_time)."""
    out = []
    for _, channel, m in iter_records(FIXTURE):
        if channel.topic in TOPICS:
            out.append((channel.topic, bytes(m.data), m.log_time, m.log_time + 7))
        if len(out) == n:
            break
    return out


def write_log(path: Path, messages: list, finish: bool = True) -> Path:
    """A suite log with a chunk every PER_CHUNK messages; ``finish=False``: the bytes on disk of a
    writer killed after its last flush (no data end, summary or footer)."""
    writer = LogWriter(path, flush_period=1e9)
    for topic, (type_name, qos) in recorded_topics().items():
        writer.add_topic(topic, type_name, qos)
    for i, (topic, data, log_time, publish_time) in enumerate(messages):
        writer.write(topic, data, log_time, publish_time)
        if (i + 1) % PER_CHUNK == 0:
            writer.flush()
    writer.flush()
    if finish:
        writer.close()
        return path
    killed = path.with_name("killed_" + path.name)
    shutil.copyfile(path, killed)
    writer.close()
    return killed


def records_of(path: Path) -> list:
    """Every message as mcap's own (seeking, indexed) reader sees it."""
    with open(path, "rb") as fh:
        reader = make_reader(fh)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        assert len(summary.chunk_indexes) == summary.statistics.chunk_count
        return [(c.topic, bytes(m.data), m.log_time, m.publish_time, m.sequence)
                for _, c, m in reader.iter_messages(log_time_order=False)]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    path = write_log(tmp_path_factory.mktemp("finished") / "run.mcap", fixture_messages())
    return path, records_of(path)


def chunk_ends(path: Path) -> list[int]:
    with open(path, "rb") as fh:
        summary = make_reader(fh).get_summary()
    return sorted(c.chunk_start_offset + c.chunk_length for c in summary.chunk_indexes)


def test_a_file_cut_at_any_offset_is_repaired_to_exactly_its_whole_chunks(finished, tmp_path):
    """Cut the finished file at offsets across it (in every record kind, at and around each chunk
    end): the repair holds exactly the messages of the chunks that end before the cut, in order,
    byte for byte with log time, publish time and sequence, and every reader opens it."""
    path, original = finished
    data = path.read_bytes()
    ends = chunk_ends(path)
    assert len(ends) == len(original) // PER_CHUNK
    offsets = sorted({*range(8, len(data), max(1, len(data) // 60)), *(e + d for e in ends for d in (-1, 0, 1)),
                      len(data) - 1, len(data) - 9})
    header_end = 8 + 9 + len(b"ros2") + len(b"att_suite") + 8
    for cut in offsets:
        cut_path = tmp_path / f"cut_{cut}.mcap"
        cut_path.write_bytes(data[:cut])
        if cut < header_end:
            with pytest.raises(LogFileError, match="nothing to recover"):
                repair(cut_path)
            continue
        done = repair(cut_path)
        whole = sum(e <= cut for e in ends) * PER_CHUNK
        if cut >= ends[-1]:
            whole = len(original)          # everything after the last chunk is index and summary
        got = records_of(done.output)
        assert got == original[:whole], f"cut at byte {cut}"
        assert done.source.messages == whole and done.result.indexed and not done.source.complete
        assert done.source.problem and done.source.good_bytes <= cut
        done.output.unlink()
        cut_path.unlink()


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(cut=st.floats(0.05, 1.0), flips=st.lists(st.tuples(st.floats(0.0, 1.0), st.integers(1, 255)), max_size=3))
@example(cut=0.616557717681738, flips=[(0.3897591234523544, 6)])
def test_a_cut_and_damaged_file_repairs_to_a_prefix_of_its_messages(finished, tmp_path, cut, flips):
    """Bytes flipped anywhere and the end cut: whatever is recovered is a prefix of the original
    messages (a damaged chunk fails its CRC and ends the recovery), and the output is valid."""
    path, original = finished
    data = bytearray(path.read_bytes()[:max(40, int(cut * path.stat().st_size))])
    for where, xor in flips:
        data[8 + int(where * (len(data) - 9))] ^= xor
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    try:
        done = repair(damaged, tmp_path / "out.mcap")
    except LogFileError as err:
        assert "nothing to recover" in str(err)       # the header itself was hit
        return
    got = records_of(done.output)
    assert got == original[:len(got)]


def record_ranges(data: bytes) -> dict[str, list[tuple[int, int]]]:
    """Byte ranges [start, end) of every record of a finished MCAP file by kind, found by walking
    its framing (opcode, 8-byte length, content) from the magic to the footer; a chunk is split
    into its header (opcode to records length) and its compressed payload. The suite's writer puts
    schemas and channels inside chunks (under the chunk CRC); the ones outside a CRC'd chunk are the
    summary's copies, listed as "schema" and "channel"; data end, chunk indexes, statistics, summary
    offsets and footer are "summary"."""
    kinds = {0x01: "header", 0x07: "message index"}
    out: dict[str, list[tuple[int, int]]] = {}
    pos, data_end = 8, False
    while pos < len(data) - 8:
        opcode, length = data[pos], int.from_bytes(data[pos + 1:pos + 9], "little")
        end = pos + 9 + length
        if opcode == 0x06:
            name_len = int.from_bytes(data[pos + 9 + 28:pos + 9 + 32], "little")
            payload = pos + 9 + 32 + name_len + 8
            out.setdefault("chunk header", []).append((pos, payload))
            out.setdefault("chunk payload", []).append((payload, end))
        else:
            data_end = data_end or opcode == 0x0F
            kind = {0x03: "schema", 0x04: "channel"}.get(opcode, "summary") if data_end else kinds[opcode]
            out.setdefault(kind, []).append((pos, end))
        pos = end
    assert pos == len(data) - 8 and data[pos:] == b"\x89MCAP0\r\n"
    return out


RECORD_KINDS = ("header", "schema", "channel", "chunk header", "chunk payload", "message index", "summary")


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(kind=st.sampled_from(RECORD_KINDS), which=st.floats(0.0, 1.0), cut=st.floats(0.05, 1.0),
       flips=st.lists(st.tuples(st.floats(0.0, 1.0), st.integers(1, 255)), min_size=1, max_size=4))
@example(kind="message index", which=0.0, cut=1.0, flips=[(0.0, 2)])       # 0x07 -> 0x05: a message
def test_flips_inside_any_record_kind_repair_to_a_prefix_of_its_messages(finished, tmp_path, kind, which, cut,
                                                                           flips):
    """Bytes flipped inside one record of a chosen kind (header, schema, channel, chunk header, chunk
    payload, message index, summary) and the end perhaps cut: what is recovered is a prefix of the
    recorded messages, byte for byte, or nothing."""
    path, original = finished
    data = bytearray(path.read_bytes())
    ranges = record_ranges(bytes(data))
    assert all(ranges.get(k) for k in RECORD_KINDS), sorted(ranges)
    start, end = ranges[kind][min(int(which * len(ranges[kind])), len(ranges[kind]) - 1)]
    for where, xor in flips:
        data[start + min(int(where * (end - start)), end - start - 1)] ^= xor
    if cut < 1.0:
        data = data[:max(end, int(cut * len(data)))]
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    try:
        done = repair(damaged, tmp_path / "out.mcap")
    except LogFileError as err:
        assert "nothing to recover" in str(err)
        return
    got = records_of(done.output)
    assert got == original[:len(got)], (kind, start, end, flips)


@pytest.mark.parametrize("opcode", [0x03, 0x04, 0x05])
def test_a_message_index_turned_schema_channel_or_message_ends_the_recovery_before_it(finished, tmp_path, opcode):
    """A chunked log holds its schemas, channels and messages inside chunks; a message index whose
    opcode reads as one of them is a damaged byte outside any chunk CRC, so the recovery keeps the
    chunks before it and stops there instead of passing the index's bytes on as a record."""
    path, original = finished
    data = bytearray(path.read_bytes())
    ranges = record_ranges(bytes(data))
    index = ranges["message index"][0][0]
    chunks_before = sum(pos < index for pos, _ in ranges["chunk header"])
    assert data[index] == 0x07
    data[index] = opcode
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    done = repair(damaged, tmp_path / "out.mcap")
    assert done.source.damaged and f"byte {index}" in done.source.problem, done.source.problem
    assert "outside a chunk" in done.source.problem
    assert records_of(done.output) == original[:chunks_before * PER_CHUNK]


@pytest.mark.parametrize("kind", ["header", "chunk header", "message index", "schema", "channel", "summary"])
def test_a_record_whose_opcode_reads_as_any_other_defined_kind_repairs_to_a_prefix(finished, tmp_path, kind):
    """The first, middle and last record of a kind, its opcode turned into each other opcode MCAP
    defines (0x01-0x0F): whatever that record then parses as, what is recovered is a prefix of the
    recorded messages, or nothing (unknown opcodes: the test below)."""
    path, original = finished
    data = path.read_bytes()
    starts = [pos for pos, _ in record_ranges(data)[kind]]
    for start in sorted({starts[0], starts[len(starts) // 2], starts[-1]}):
        for opcode in set(range(0x01, 0x10)) - {data[start]}:
            damaged = tmp_path / "damaged.mcap"
            damaged.write_bytes(data[:start] + bytes([opcode]) + data[start + 1:])
            try:
                got = records_of(repair(damaged, tmp_path / "out.mcap").output)
            except LogFileError as err:
                assert "nothing to recover" in str(err), (start, opcode, str(err))
                continue
            assert got == original[:len(got)], (kind, start, hex(opcode))


def test_a_second_header_ends_the_recovery_before_it(finished, tmp_path):
    """A header record anywhere but first (a well-formed one, inserted before the second chunk) is
    damage: the recovery keeps the first chunk and stops there, instead of starting a second log."""
    path, original = finished
    data = path.read_bytes()
    second = record_ranges(data)["chunk header"][1][0]
    body = (0).to_bytes(4, "little") * 2                       # empty profile and library strings
    header = bytes([0x01]) + len(body).to_bytes(8, "little") + body
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(data[:second] + header + data[second:])
    done = repair(damaged, tmp_path / "out.mcap")
    assert "a second header record" in done.source.problem and f"byte {second}" in done.source.problem
    assert records_of(done.output) == original[:PER_CHUNK]


def test_each_repair_aside_takes_a_name_no_file_takes(tmp_path):
    from att_msgs_py.log.repair import unused_output

    log = tmp_path / "run.mcap"
    assert unused_output(log) == tmp_path / "run.repaired.mcap"
    (tmp_path / "run.repaired.mcap").write_bytes(b"")
    (tmp_path / "run.repaired.3.mcap").write_bytes(b"")
    assert unused_output(log) == tmp_path / "run.repaired.2.mcap"
    (tmp_path / "run.repaired.2.mcap").symlink_to(tmp_path / "nowhere")      # a dangling link is taken too
    assert unused_output(log) == tmp_path / "run.repaired.4.mcap"


def test_a_rewrite_that_does_not_read_back_whole_is_an_error_and_leaves_no_file(finished, tmp_path, monkeypatch):
    """The rewrite is read back before it replaces the target: one that lost a message is refused
    with a :class:`LogFileError` (one line from ``att-log``) and neither the target nor a temporary
    file is left."""
    from mcap.writer import Writer

    path, _ = finished
    add = Writer.add_message
    seen = []

    def losing(self, channel_id, **kw):            # drops the tenth message it is given
        seen.append(1)
        if len(seen) != 10:
            add(self, channel_id, **kw)

    monkeypatch.setattr(Writer, "add_message", losing)
    with pytest.raises(LogFileError, match="did not read back whole .399 of 400 messages"):
        repair(path, tmp_path / "out.mcap")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("opcode", [0x00, 0x10, 0x80, 0xFF])
def test_a_chunk_whose_opcode_was_flipped_ends_the_recovery_before_it(finished, tmp_path, opcode):
    """MCAP lets a reader skip a record of unknown opcode; in a suite log that is a damaged byte, and
    skipping it would drop a whole chunk and go on after it, so the recovery stops there."""
    path, original = finished
    with open(path, "rb") as fh:
        chunks = sorted(make_reader(fh).get_summary().chunk_indexes, key=lambda c: c.chunk_start_offset)
    third = chunks[2]
    data = bytearray(path.read_bytes())
    assert data[third.chunk_start_offset] == 0x06          # a Chunk record starts there
    data[third.chunk_start_offset] = opcode
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    done = repair(damaged, tmp_path / "out.mcap")
    got = records_of(done.output)
    assert got == original[:2 * PER_CHUNK]
    assert done.source.problem.startswith(f"damaged record at byte {third.chunk_start_offset}")


def test_a_killed_writers_file_is_refused_by_rosbags_and_mcap_and_opens_once_repaired(tmp_path):
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.typesys import Stores, get_typestore

    messages = fixture_messages(230)
    killed = write_log(tmp_path / "run.mcap", messages, finish=False)
    for decoded in (False, True):
        with open(killed, "rb") as fh, pytest.raises(McapError):
            reader = make_reader(fh, decoder_factories=[DecoderFactory()])
            list(reader.iter_decoded_messages() if decoded else reader.iter_messages())
    with pytest.raises(AnyReaderError, match="magic"):
        with AnyReader([killed], default_typestore=get_typestore(Stores.EMPTY)) as reader:
            list(reader.messages())
    assert att_log(["repair", str(killed)]) == 0
    repaired = default_output(killed)
    assert repaired == tmp_path / "killed_run.repaired.mcap"
    with AnyReader([repaired], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        decoded = [(c.topic, reader.deserialize(raw, c.msgtype), t) for c, t, raw in reader.messages()]
    assert sorted((topic, t) for topic, _, t in decoded) == sorted((m[0], m[2]) for m in messages)
    with open(repaired, "rb") as fh:
        mcap_decoded = list(make_reader(fh, decoder_factories=[DecoderFactory()]).iter_decoded_messages())
    assert len(mcap_decoded) == len(messages)
    state = [m for (_, c, _, m) in mcap_decoded if c.topic == "/spacecraft/state"]
    assert state and all(abs(m.attitude.x ** 2 + m.attitude.y ** 2 + m.attitude.z ** 2 + m.attitude.w ** 2 - 1) < 1e-9
                         for m in state)


def test_a_complete_file_is_copied_without_loss_and_reported_complete(finished, tmp_path, capsys):
    path, original = finished
    out = tmp_path / "copy.mcap"
    assert att_log(["repair", str(path), "-o", str(out)]) == 0
    topics = len(recorded_topics())
    assert f"was complete and indexed: copied 400 messages on {topics} topics" in capsys.readouterr().out
    assert records_of(out) == original
    source, copy = Scan(path, 0), Scan(out, 0)
    list(scan_records(path, source))
    list(scan_records(out, copy))
    assert (copy.profile, copy.library) == (source.profile, source.library) == ("ros2", "att_suite")
    assert [(c.topic, c.message_encoding, c.metadata) for c in copy.channels.values()] == \
        [(c.topic, c.message_encoding, c.metadata) for c in source.channels.values()]
    assert all("reliability:" in c.metadata["offered_qos_profiles"] for c in copy.channels.values())
    assert [(s.name, s.encoding, s.data) for s in copy.schemas.values()] == \
        [(s.name, s.encoding, s.data) for s in source.schemas.values()]


def test_info_tells_a_complete_file_from_one_to_repair(finished, tmp_path, capsys):
    path, original = finished
    assert att_log(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "complete and indexed (16 chunks" in out
    counts = {t: sum(r[0] == t for r in original) for t in TOPICS}
    for topic, n in counts.items():
        assert any(line.split()[0] == topic and line.split()[-1] == str(n) for line in out.splitlines()), out
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(path.read_bytes()[:chunk_ends(path)[3] + 100])
    assert att_log(["info", str(cut)]) == 1
    out = capsys.readouterr().out
    channels = len(recorded_topics())
    assert "INCOMPLETE" in out and "att-log repair" in out
    assert f"messages  {4 * PER_CHUNK} on {channels} channels" in out


def test_repair_never_overwrites_its_input_unless_in_place(finished, tmp_path, capsys):
    path, original = finished
    cut = tmp_path / "run.mcap"
    cut.write_bytes(path.read_bytes()[:chunk_ends(path)[5] + 3])
    before = cut.read_bytes()
    assert att_log(["repair", str(cut), "-o", str(cut)]) == 2
    assert "would overwrite the input; use --in-place" in capsys.readouterr().err
    assert cut.read_bytes() == before
    assert att_log(["repair", str(cut), "--in-place"]) == 0
    assert records_of(cut) == original[:6 * PER_CHUNK]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.mcap"]          # no temporary file left
    with pytest.raises(SystemExit) as exit_info:
        att_log(["repair", str(cut), "--in-place", "-o", str(tmp_path / "x.mcap")])
    assert exit_info.value.code == 2


NOT_MCAP = {
    "empty": b"",
    "text": b"hello, this is not a log\n",
    "png": b"\x89PNG\r\n\x1a\n" + bytes(100),
    "zip": b"PK\x03\x04" + bytes(100),
    "random": bytes(range(256)) * 4,
    "half magic": b"\x89MCA",
    "magic only": b"\x89MCAP0\r\n",
    "magic and cut header": b"\x89MCAP0\r\n\x01\x30\x00\x00",
    "no header first": b"\x89MCAP0\r\n" + b"\x0f" + (4).to_bytes(8, "little") + bytes(4),
}


@pytest.mark.parametrize("name", [*NOT_MCAP, "missing", "directory"])
def test_what_is_not_an_mcap_log_is_refused_in_one_line(tmp_path, capsys, name):
    path = tmp_path / "in.mcap"
    if name == "directory":
        path.mkdir()
    elif name != "missing":
        path.write_bytes(NOT_MCAP[name])
    for command in (["repair", str(path)], ["info", str(path)]):
        assert att_log(command) == 2, (name, command)
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"att-log: {path}: "), err
        assert "Traceback" not in err
        if name in ("empty", "half magic", "magic only", "magic and cut header", "no header first"):
            assert "byte" in err, err          # where the file ends or what is at its start
    assert sorted(p.name for p in tmp_path.iterdir()) == ([] if name == "missing" else ["in.mcap"])


def test_a_chunk_with_a_message_on_an_undefined_channel_ends_the_recovery(tmp_path):
    from mcap.writer import Writer

    path = tmp_path / "orphan.mcap"
    with open(path, "wb") as fh:
        writer = Writer(fh)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema("std_msgs/msg/Empty", "ros2msg", b"")
        channel = writer.register_channel("/a", "cdr", schema)
        for i, channel_id in enumerate([channel] * 3 + [99] + [channel] * 3):
            writer.add_message(channel_id, log_time=i, data=bytes([i]), publish_time=i, sequence=i)
            if i in (2, 3):
                writer.flush()             # chunks: [0, 1, 2], [3 on channel 99], [4, 5, 6]
        writer.finish()
    done = repair(path)
    assert "channel 99" in done.source.problem and not done.source.complete
    assert [r[1] for r in records_of(done.output)] == [b"\x00", b"\x01", b"\x02"]


def test_an_unchunked_log_cut_anywhere_keeps_a_growing_prefix(tmp_path):
    """Messages outside chunks (another writer's layout): each cut keeps the whole records before it."""
    from mcap.writer import Writer

    path = tmp_path / "flat.mcap"
    with open(path, "wb") as fh:
        writer = Writer(fh, use_chunking=False)
        writer.start(profile="ros2", library="test")
        channel = writer.register_channel("/a", "cdr", writer.register_schema("std_msgs/msg/Empty", "ros2msg", b""))
        for i in range(40):
            writer.add_message(channel, log_time=1000 + i, data=bytes(range(i)), publish_time=2000 + i, sequence=i)
        writer.finish()
    original = records_of(path)
    data, last = path.read_bytes(), -1
    for cut in range(60, len(data), 37):
        (tmp_path / "cut.mcap").write_bytes(data[:cut])
        got = records_of(repair(tmp_path / "cut.mcap", tmp_path / "out.mcap").output)
        assert got == original[:len(got)] and len(got) >= last
        last = len(got)
    assert last == len(original)


def test_the_writer_writes_every_crc_mcap_defines(finished):
    """Chunk CRCs, the data section's CRC (data end) and the summary's (footer), all non-zero and
    each equal to an independent CRC32 of the bytes the MCAP specification says it covers."""
    import zlib

    path, _ = finished
    data = path.read_bytes()
    ranges = record_ranges(data)
    data_end = next(pos for pos, _ in ranges["summary"] if data[pos] == 0x0F)
    footer = next(pos for pos, _ in ranges["summary"] if data[pos] == 0x02)
    assert int.from_bytes(data[data_end + 9:data_end + 13], "little") == zlib.crc32(data[:data_end]) != 0
    summary_start = int.from_bytes(data[footer + 9:footer + 17], "little")
    assert summary_start == data_end + 13
    assert int.from_bytes(data[footer + 25:footer + 29], "little") == zlib.crc32(data[summary_start:footer + 25]) != 0
    for pos, _ in ranges["chunk header"]:
        assert int.from_bytes(data[pos + 9 + 24:pos + 9 + 28], "little") != 0


def damage_is_noticed(path: Path, tmp_path: Path, capsys) -> str:
    """The problem scan_records names for ``path``, after checking that att-log info and repair
    report it as damaged (exit 1, one line) and that what repair recovers is whole."""
    scan = Scan(path, 0)
    for _ in scan_records(path, scan):
        pass
    assert scan.damaged and not scan.indexed, scan.problem
    nothing = not scan.header               # the header itself damaged: nothing to recover (exit 2)
    assert att_log(["info", str(path)]) == 1 + nothing
    assert capsys.readouterr().err.count("\n") == 1
    assert att_log(["repair", str(path), "-o", str(tmp_path / "out.mcap")]) == 1 + nothing
    assert capsys.readouterr().err.count("\n") == 1
    return scan.problem


@pytest.mark.parametrize("kind", RECORD_KINDS)
@pytest.mark.parametrize("where", [0.0, 0.5, 1.0])
def test_one_flipped_byte_in_any_record_of_a_suite_log_is_noticed(finished, tmp_path, capsys, kind, where):
    """Every byte of a suite log is under a CRC: a chunk's payload under the chunk's, the header,
    chunk headers and message indexes under the data section's, the summary under the footer's."""
    path, original = finished
    data = bytearray(path.read_bytes())
    start, end = record_ranges(bytes(data))[kind][1 if kind in ("chunk header", "chunk payload") else 0]
    data[start + min(int(where * (end - start)), end - start - 1)] ^= 0x01
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    assert damage_is_noticed(damaged, tmp_path, capsys).startswith("damaged record at byte ")
    if (tmp_path / "out.mcap").exists():
        got = records_of(tmp_path / "out.mcap")
        assert got == original[:len(got)]


@pytest.mark.parametrize("field, value", [("crc", bytes(4)), ("crc and payload", bytes(4))])
def test_a_chunk_whose_crc_reads_0_ends_the_recovery_before_it(finished, tmp_path, capsys, field, value):
    """CRC 0 means "not computed" in MCAP: such a chunk cannot be told from a damaged one (its
    payload flipped too, a decoder may still inflate it into other bytes), so it is refused."""
    path, original = finished
    data = bytearray(path.read_bytes())
    start, _ = record_ranges(bytes(data))["chunk header"][2]
    data[start + 9 + 24:start + 9 + 28] = value
    if field == "crc and payload":
        payload, end = record_ranges(bytes(data))["chunk payload"][2]
        data[(payload + end) // 2] ^= 0x01
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    problem = damage_is_noticed(damaged, tmp_path, capsys)
    assert problem.startswith(f"damaged record at byte {start}: chunk without a CRC"), problem
    assert records_of(tmp_path / "out.mcap") == original[:2 * PER_CHUNK]
