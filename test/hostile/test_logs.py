"""Logs and newcomer friction under faults: a recorder killed with SIGKILL leaves a file that
``rosbags`` and ``mcap``'s reader refuse; ``att-log repair`` (and the recorder's next start on the
same path) makes it whole for both, every message decoded, at most a flush interval lost.
``att-demo``'s domain: the user's ROS_DOMAIN_ID is honoured, a malformed one refused in one line."""
from __future__ import annotations

import ast
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from att_msgs_py.log import read_log
from att_planner.tools.launch import Suite, isolated_env

ATT_LOG = Path(sys.executable).parent / "att-log"
KILL_AFTER = 4.0          # s of recording before the SIGKILL
FLUSH_PERIOD = 0.5        # the recorder's default


def rosbags_messages(path: Path) -> dict[str, list]:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        for connection, _, raw in reader.messages():
            out.setdefault(connection.topic, []).append(reader.deserialize(raw, connection.msgtype))
    return out


def mcap_messages(path: Path, decoded: bool) -> list:
    with open(path, "rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        return list(reader.iter_decoded_messages() if decoded else reader.iter_messages())


def record_and_kill(suite: Suite, path: Path) -> float:
    """Recorder + simulator (no lockstep, RTF 2); SIGKILL the recorder after KILL_AFTER s of states."""
    suite.start("recorder", {"output": str(path)})
    suite.start("simulator", {"scenario": "swift_demo", "lockstep": False, "real_time_factor": 2.0,
                              "wait_for_subscribers": 1})
    assert suite.wait_for_output("recorder", "recording", 30), suite.log_text("recorder")
    deadline = time.monotonic() + 30
    while not (path.is_file() and path.stat().st_size > 1000) and time.monotonic() < deadline:
        time.sleep(0.1)                # wait-ok: the poll period of a wait with a deadline
    time.sleep(KILL_AFTER)             # wait-ok: how long the recorder runs before the kill is the test's parameter
    suite.procs["recorder"].send_signal(signal.SIGKILL)
    killed_at = time.time()
    assert suite.procs["recorder"].wait(10) == -signal.SIGKILL
    return killed_at


@pytest.mark.ros
def test_a_killed_recorders_log_is_refused_raw_and_decoded_whole_once_repaired(tmp_path):
    from rosbags.highlevel import AnyReaderError

    assert ATT_LOG.is_file(), "att-log is not installed: run make setup"
    suite = Suite(isolated_env(), tmp_path)
    killed = tmp_path / "killed.mcap"
    try:
        killed_at = record_and_kill(suite, killed)
        # the bug: neither independent reader opens the raw file
        with pytest.raises(AnyReaderError, match="magic"):
            rosbags_messages(killed)
        for decoded in (False, True):
            with pytest.raises(McapError):
                mcap_messages(killed, decoded)
        salvaged = read_log(killed)
        counts = {t: len(v) for t, v in salvaged.items()}
        assert counts["/spacecraft/state"] > 2 * KILL_AFTER * 20 * 0.5, counts   # 40 states/s of wall time
        info = subprocess.run([str(ATT_LOG), "info", str(killed)], capture_output=True, text=True, timeout=60)
        assert info.returncode == 1 and "INCOMPLETE" in info.stdout, info.stdout + info.stderr
        done = subprocess.run([str(ATT_LOG), "repair", str(killed)], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stdout + done.stderr
        repaired = tmp_path / "killed.repaired.mcap"
        assert f"wrote {repaired}: complete and indexed" in done.stdout, done.stdout
        # both readers open the repaired file and decode every message read_log recovered
        by_rosbags = rosbags_messages(repaired)
        assert {t: len(v) for t, v in by_rosbags.items()} == counts
        decoded = mcap_messages(repaired, decoded=True)
        assert len(decoded) == sum(counts.values())
        assert [m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in by_rosbags["/spacecraft/state"]] == \
            pytest.approx(list(salvaged["/spacecraft/state"]["header.stamp"]), abs=1e-9)
        last = max(message.log_time for _, _, message, _ in decoded) * 1e-9
        assert killed_at - last < 2 * FLUSH_PERIOD, f"{killed_at - last:.2f} s lost (flush every {FLUSH_PERIOD} s)"
        # the recorder started again on the same path repairs the leftover aside before recording, to a
        # name no file takes: the earlier repair stays as it was
        repaired_bytes = repaired.read_bytes()
        suite.start("recorder", {"output": str(killed)})
        again = tmp_path / "killed.repaired.2.mcap"
        assert suite.wait_for_output("recorder", f"repaired into {again}", 30), suite.log_text("recorder")
        assert again.read_bytes() == repaired_bytes and repaired.read_bytes() == repaired_bytes
    finally:
        suite.stop()


@pytest.mark.ros
def test_a_recorder_keeps_a_file_at_its_output_unless_it_holds_no_message(tmp_path):
    """A file at ``output`` that is not an MCAP log stops the recorder (exit 2, one line naming
    ``output``) and is left byte for byte; a log killed before its first message is recorded over
    (warned), with no copy made; a complete log is moved aside, byte for byte."""
    from att_msgs_py.log import LogWriter
    from att_msgs_py.log.repair import MAGIC
    from att_msgs_py.qos import recorded_topics

    suite = Suite(isolated_env(), tmp_path)
    notes = tmp_path / "notes.mcap"
    notes.write_bytes(b"orbit: 550 km\n")
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(MAGIC + b"\x01\xff\xff")             # killed while writing its header
    try:
        proc = suite.start("recorder", {"output": str(notes)})
        assert proc.wait(60) == 2, suite.log_text("recorder")
        lines = [line for line in suite.log_text("recorder").splitlines() if line.strip()]
        assert len(lines) == 1 and "INVALID_CONFIG" in lines[0] and f"output: {notes}" in lines[0], lines
        assert notes.read_bytes() == b"orbit: 550 km\n"
        suite.start("recorder", {"output": str(empty)})
        assert suite.wait_for_output("recorder", f"recording {len(recorded_topics())} topics", 60), \
            suite.log_text("recorder")
        assert f"recording over {empty}: it holds no message" in suite.log_text("recorder")
        assert suite.stop()["recorder"] == 0
        read_log(empty)                                     # the new recording, readable (LogFileError if not)
        assert not list(tmp_path.glob("*repaired*"))
        kept = tmp_path / "kept.mcap"                       # a complete log of three messages
        writer = LogWriter(kept)
        writer.add_topic("/spacecraft/state", recorded_topics()["/spacecraft/state"][0])
        for i in range(3):
            writer.write("/spacecraft/state", bytes([0, 1, 0, 0, i]), log_time_ns=i)
        writer.close()
        complete = kept.read_bytes()
        suite.start("recorder", {"output": str(kept)})
        aside = tmp_path / "kept.previous.mcap"
        assert suite.wait_for_output("recorder", f"holds a complete log (3 messages): kept as {aside}", 60), \
            suite.log_text("recorder")
        assert aside.read_bytes() == complete
    finally:
        suite.stop()


# -- the tools' domain -------------------------------------------------------------------------

def test_a_domain_the_user_set_is_kept_and_localhost_stays_the_default():
    from att_planner.tools.demo import domain_line

    env = isolated_env(inherit=True, base={"ROS_DOMAIN_ID": "42"})
    assert env["ROS_DOMAIN_ID"] == "42" and env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert "ROS_DOMAIN_ID 42 (inherited from your environment)" in domain_line(env, {"ROS_DOMAIN_ID": "42"})
    env = isolated_env(inherit=True, base={"ROS_DOMAIN_ID": " 7 ", "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"})
    assert (env["ROS_DOMAIN_ID"], env["ROS_AUTOMATIC_DISCOVERY_RANGE"]) == ("7", "SUBNET")
    for base in ({}, {"ROS_DOMAIN_ID": ""}, {"ROS_DOMAIN_ID": "  "}):
        env = isolated_env(inherit=True, base=base)
        assert 1 <= int(env["ROS_DOMAIN_ID"]) <= 200 and env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
        assert "chosen at random: ROS_DOMAIN_ID is unset" in domain_line(env, base)
    # tests (inherit=False) always get a random domain, whatever the environment says
    domains = {isolated_env(base={"ROS_DOMAIN_ID": "42"})["ROS_DOMAIN_ID"] for _ in range(20)}
    assert domains != {"42"} and all(1 <= int(d) <= 200 for d in domains)
    assert isolated_env(5, base={"ROS_DOMAIN_ID": "42"}, inherit=True)["ROS_DOMAIN_ID"] == "5"


MALFORMED = [("abc", ""), ("-1", ""), ("233", ""), ("1e3", ""), ("4\x01", ""), ("9" * 50, ""), ("\u00b2", ""),
             ("\u0663", ""), ("3", "EVERYWHERE"), ("3", "localhost;rm")]


@pytest.mark.parametrize("domain, discovery", MALFORMED)
def test_att_demo_refuses_a_malformed_domain_in_one_line(tmp_path, monkeypatch, capsys, domain, discovery):
    from att_planner.tools import demo

    monkeypatch.setenv("ROS_DOMAIN_ID", domain)
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", discovery)
    assert demo.main(["--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    name = "ROS_DOMAIN_ID" if not discovery else "ROS_AUTOMATIC_DISCOVERY_RANGE"
    assert err.count("\n") == 1 and err.startswith(f"att-demo: {name} is '") and "expected" in err, err
    assert list(tmp_path.iterdir()) == []                 # nothing started, nothing written


@pytest.mark.parametrize("variable, value", [("ROS_DOMAIN_ID", "233"), ("ROS_DOMAIN_ID", "abc"),
                                             ("ROS_AUTOMATIC_DISCOVERY_RANGE", "EVERYWHERE")])
def test_att_mission_refuses_a_malformed_domain_in_one_line(tmp_path, monkeypatch, capsys, variable, value):
    from att_planner.tools import mission

    monkeypatch.delenv("ROS_DOMAIN_ID", raising=False)
    monkeypatch.setenv(variable, value)
    assert mission.main(["aeos_orbit", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"att-mission: {variable} is '{value}'") and "expected" in err, err
    assert list(tmp_path.iterdir()) == []                 # nothing started, nothing written


@pytest.mark.parametrize("scenario, words", [("bruni_celani", "demo"), ("no_such_scenario", "unknown")])
def test_att_demo_refuses_a_scenario_it_cannot_run_in_one_line(tmp_path, capsys, scenario, words):
    from att_planner.tools import demo

    assert demo.main(["--scenario", scenario, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("att-demo: ") and words in err, err
    assert list(tmp_path.iterdir()) == []                 # nothing started, nothing written


# -- hostile and damaged files for the log tools -------------------------------------------------

ATT_TOOLS = {name: Path(sys.executable).parent / name for name in ("att-log", "att-review", "att-replay")}
BOMB_BYTES = 1 << 30                  # what the bomb chunk inflates to


def hostile_log(path: Path, topic: str = "/a", type_name: str = "std_msgs/msg/Empty", chunk: bytes | None = None,
                finish: bool = True) -> Path:
    """A small MCAP (profile ros2, cdr) with one topic; ``chunk``: the raw content of a Chunk record
    placed after the first chunk (a forged one), the file then ends there."""
    from mcap.writer import Writer

    with open(path, "wb") as fh:
        writer = Writer(fh)
        writer.start(profile="ros2", library="test")
        channel = writer.register_channel(topic, "cdr", writer.register_schema(type_name, "ros2msg", b""))
        for i in range(3):
            writer.add_message(channel, log_time=i, data=b"\x00\x01\x00\x00\x00\x00\x00\x00", publish_time=i,
                               sequence=i)
        if chunk is None and finish:
            writer.finish()
            return path
        writer.flush()                         # the chunk written now; no summary or footer
    if chunk is not None:
        with open(path, "ab") as fh:
            fh.write(b"\x06" + len(chunk).to_bytes(8, "little") + chunk)
    return path


def chunk_content(data: bytes, uncompressed_size: int, compression: str) -> bytes:
    """A Chunk record's content (times, uncompressed size, CRC 0, compression, records)."""
    name = compression.encode()
    return (bytes(16) + uncompressed_size.to_bytes(8, "little") + bytes(4) + len(name).to_bytes(4, "little") + name
            + len(data).to_bytes(8, "little") + data)


@pytest.fixture(scope="module")
def zstd_bomb() -> bytes:
    """A zstd frame of 1 GiB of zeros (a few tens of kB), its content size written in the frame."""
    import zstandard

    cctx = zstandard.ZstdCompressor(level=1)
    out = bytearray()
    zeros = bytes(1 << 24)
    chunker = cctx.chunker(size=BOMB_BYTES, chunk_size=1 << 20)
    for _ in range(BOMB_BYTES // len(zeros)):
        for piece in chunker.compress(zeros):
            out += piece
    for piece in chunker.finish():
        out += piece
    return bytes(out)


def unsized_zstd_bomb(size: int = 1 << 28) -> bytes:
    """A zstd frame of ``size`` zeros that does not say its content size (only inflating tells)."""
    import zstandard

    writer = zstandard.ZstdCompressor(level=1, write_content_size=False).compressobj()
    zeros = bytes(1 << 24)
    return b"".join(writer.compress(zeros) for _ in range(size // len(zeros))) + writer.flush()


@pytest.fixture(scope="module")
def damaged_logs(tmp_path_factory, zstd_bomb) -> dict[str, Path]:
    import lz4.frame

    from helpers.regression_log import FIXTURE

    where = tmp_path_factory.mktemp("hostile")
    fixture = FIXTURE.read_bytes()
    files = {"cut after 9 bytes": fixture[:9]}
    with open(FIXTURE, "rb") as fh:
        chunks = sorted(make_reader(fh).get_summary().chunk_indexes, key=lambda c: c.chunk_start_offset)
    flipped = bytearray(fixture)
    middle = chunks[len(chunks) // 2]
    for i in range(16):
        flipped[middle.chunk_start_offset + 9 + i * max(1, middle.chunk_length // 17)] ^= 0x5A
    files["16 flipped bytes in a chunk"] = bytes(flipped)
    out = {name: where / f"{i}.mcap" for i, name in enumerate(files)}
    for name, data in files.items():
        out[name].write_bytes(data)
    lz4_bomb = lz4.frame.LZ4FrameCompressor(content_checksum=False)
    frame = lz4_bomb.begin(source_size=BOMB_BYTES) + b"".join(lz4_bomb.compress(bytes(1 << 24)) for _ in range(64))
    frame += lz4_bomb.flush()
    for name, chunk in (("zstd bomb claimed", chunk_content(zstd_bomb, BOMB_BYTES, "zstd")),
                        ("zstd bomb unclaimed", chunk_content(zstd_bomb, 4096, "zstd")),
                        ("zstd bomb unsized", chunk_content(unsized_zstd_bomb(), 4096, "zstd")),
                        ("lz4 bomb", chunk_content(frame, 4096, "lz4"))):
        out[name] = hostile_log(where / f"{name.replace(' ', '_')}.mcap", chunk=chunk)
    return out


TOOL_COMMANDS = {
    "att-log info": lambda p, out: [str(ATT_TOOLS["att-log"]), "info", str(p)],
    "att-log repair": lambda p, out: [str(ATT_TOOLS["att-log"]), "repair", str(p), "-o", str(out / "r.mcap")],
    "att-review": lambda p, out: [str(ATT_TOOLS["att-review"]), str(p), "--out", str(out)],
    "att-replay": lambda p, out: [str(ATT_TOOLS["att-replay"]), str(p), "--wait", "0", "--linger", "0"],
}


@pytest.mark.parametrize("tool", TOOL_COMMANDS)
@pytest.mark.parametrize("damage", ["cut after 9 bytes", "16 flipped bytes in a chunk", "zstd bomb claimed",
                                    "zstd bomb unclaimed", "zstd bomb unsized", "lz4 bomb"])
def test_log_tools_answer_a_damaged_or_hostile_file_in_one_line(damaged_logs, tmp_path, tool, damage):
    """Each tool answers a cut, flipped or decompression-bomb file with one line naming the problem
    and its byte offset, exit 1 or 2, no traceback, within 256 MB of resident memory (the tool's peak
    RSS, measured by a parent that runs only it) and without hanging (30 s; how fast it answers is a
    wall-clock figure, which depends on the machine's load, not a unit test's)."""
    path = damaged_logs[damage]
    argv = TOOL_COMMANDS[tool](path, tmp_path)
    probe = ("import resource, subprocess, sys, time; t = time.monotonic(); "
             "r = subprocess.run(sys.argv[1:], capture_output=True, text=True, timeout=30); "
             "print(repr((r.returncode, r.stdout, r.stderr, time.monotonic() - t, "
             "resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)))")
    probed = subprocess.run([sys.executable, "-c", probe, *argv], capture_output=True, text=True, timeout=60)
    code, out, err, _, maxrss_kb = ast.literal_eval(probed.stdout)
    assert code in (1, 2), (code, out, err)
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert "byte" in err or "bytes" in err, err
    assert maxrss_kb < 256 * 1024, f"{tool} grew to {maxrss_kb / 1024:.0f} MB"


def test_a_log_never_chooses_which_module_is_imported(tmp_path, capsys):
    """A schema named ``this/msg/x`` must not import the module ``this``: only the suite's interface
    packages are resolved, anything else refused in one line before any import."""
    from att_msgs_py.log import replay

    assert "this" not in sys.modules
    for type_name in ("this/msg/x", "os/msg/Path", "std_msgs/msg/../../os", "att_msgs/srv/Plan", "antigravity"):
        path = hostile_log(tmp_path / "named.mcap", type_name=type_name)
        assert replay.main([str(path), "--wait", "0", "--linger", "0"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "not one of the suite's interface types" in err, err
        assert "this" not in sys.modules and "antigravity" not in sys.modules


HOSTILE_NAMES = ["/a\x1b[2J\x1b]0;pwned\x07", "/b\r\n/fake 1", "/c\x00\x7f\x9b31m"]


@pytest.mark.parametrize("topic", HOSTILE_NAMES)
def test_file_provided_names_reach_the_terminal_escaped(tmp_path, capsys, topic):
    """Topic, type, profile and library strings of a file are printed with their control characters
    escaped by ``att-log info``, ``att-replay`` refuses such a topic naming it escaped, and neither
    ``att-log repair`` nor ``att-review`` prints them raw."""
    from att_msgs_py.log import replay
    from att_msgs_py.log.cli import main as att_log
    from att_planner.tools.review import main as att_review

    def assert_escaped(text: str) -> None:
        assert not any((ord(c) < 0x20 and c != "\n") or 0x7f <= ord(c) < 0xa0 for c in text), repr(text)

    path = hostile_log(tmp_path / "names.mcap", topic=topic, type_name="std_msgs/msg/Empty\x1b[1m")
    assert att_log(["info", str(path)]) in (0, 1)
    printed = capsys.readouterr()
    assert_escaped(printed.out + printed.err)
    assert "\\x1b" in printed.out
    assert replay.main([str(path), "--wait", "0", "--linger", "0"]) == 2
    printed = capsys.readouterr()
    assert_escaped(printed.out + printed.err)
    assert printed.err.count("\n") == 1 and "is not a ROS topic name" in printed.err, printed.err
    assert att_log(["repair", str(path), "-o", str(tmp_path / "out.mcap")]) == 0
    assert att_review([str(path), "--out", str(tmp_path / "review")]) == 1     # no state to review
    printed = capsys.readouterr()
    assert_escaped(printed.out + printed.err)
