"""``att-bench logtools`` on a reduced input (3 files, the 4 tools): the JSON holds every run with its
figures and the criterion evaluated from them, the summary per tool agrees with the runs, the exit
status follows the criterion; the 40 files are what their names say; the criterion fails what it
should. No timing threshold is asserted."""
import json
from pathlib import Path

import pytest
from mcap.opcode import Opcode

from att_planner.tools.bench import hostile_logs, logtools, main

REDUCED = ["cut after 9 bytes", "flip in a chunk's CRC", "schema named this/msg/x"]


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    where = tmp_path_factory.mktemp("logtools")
    argv = ["logtools", "--json", str(where / "out.json"), "--keep", str(where / "files")]
    code = main([*argv[:1], *(a for name in REDUCED for a in ("--case", name)), *argv[1:]])
    return code, json.loads((where / "out.json").read_text()), where / "files"


def test_every_run_is_measured_and_judged(reduced):
    code, out, _ = reduced
    assert [c["name"] for c in out["cases"]] == REDUCED and out["files"] == 3
    assert len(out["runs"]) == 3 * len(logtools.TOOLS)
    for r in out["runs"]:
        assert r["wall_s"] > 0 and r["max_rss_mb"] > 0 and r["parent_rss_mb"] < r["max_rss_mb"] + 1
        assert r["stdout_lines"] == len(r["stdout"].splitlines()) or len(r["stdout"]) == 2000
        assert r["failed"] == logtools.judge(r["tool"], r["kind"], r), r["case"]
    for tool, s in out["tools"].items():
        mine = [r for r in out["runs"] if r["tool"] == tool]
        assert s["runs"] == 3 and s["worst_rss_mb"] == max(r["max_rss_mb"] for r in mine)
        assert s["exit_codes"] == sorted({r["exit"] for r in mine})
        assert s["failures"] == [{"case": r["case"], "failed": r["failed"]} for r in mine if r["failed"]]
    failed = [f"{t}: {f['case']}" for t, s in out["tools"].items() for f in s["failures"]]
    assert out["failed"] == failed and out["passed"] == (not failed) and code == (0 if out["passed"] else 1)
    assert out["allowed_exits"]["att-log info"]["cut"] == [1, 2]
    assert len(out["machine"]["load_before"]) == 3 and out["source"]["bytes"] > 10_000


def test_the_refusals_name_the_file_and_the_offset(reduced):
    _, out, _ = reduced
    cut = {r["tool"]: r for r in out["runs"] if r["case"] == "cut after 9 bytes"}
    assert {t: r["exit"] for t, r in cut.items()} == {"att-log info": 2, "att-log repair": 2, "att-review": 1,
                                                       "att-replay": 2}
    for r in cut.values():
        assert r["stderr_lines"] == 1 and "at byte 8" in r["stderr"], r


def test_the_files_are_what_their_names_say(reduced):
    _, _, files = reduced
    assert len(hostile_logs.CASES) == 40 and len({c.name for c in hostile_logs.CASES}) == 40
    assert {c.kind for c in hostile_logs.CASES} == {"cut", "flip", "bomb", "name"}
    source = (files / "recorded.mcap").read_bytes()
    records = hostile_logs.top_records(source)
    kinds = {r.opcode for r in records}
    assert {Opcode.HEADER, Opcode.CHUNK, Opcode.MESSAGE_INDEX, Opcode.DATA_END, Opcode.SCHEMA, Opcode.CHANNEL,
            Opcode.STATISTICS, Opcode.CHUNK_INDEX, Opcode.SUMMARY_OFFSET, Opcode.FOOTER} <= kinds
    assert records[-1].end == len(source) - 8 and source[-8:] == source[:8]
    cut = files / "00_cut.mcap"
    assert cut.read_bytes() == source[:9]
    flipped = (files / "01_flip.mcap").read_bytes()
    crc = hostile_logs.nth(records, Opcode.CHUNK, 2).content + 24
    assert [i for i, (a, b) in enumerate(zip(source, flipped)) if a != b] == [crc] and len(flipped) == len(source)


def test_a_bomb_chunk_claims_and_inflates_as_named(tmp_path):
    import zstandard

    source = hostile_logs.recorded_log(tmp_path / "source.mcap", seconds=1.0).read_bytes()
    records = hostile_logs.top_records(source)
    hostile_logs.bomb(lambda: hostile_logs.zstd_bomb(1 << 24), 4096, "zstd")(source, records, tmp_path / "b.mcap")
    data = (tmp_path / "b.mcap").read_bytes()
    bomb = hostile_logs.nth(hostile_logs.top_records(data), Opcode.CHUNK, 1)
    assert int.from_bytes(data[bomb.content + 16:bomb.content + 24], "little") == 4096
    frame = data[bomb.content + 44:bomb.end]
    assert zstandard.frame_content_size(frame) == 1 << 24 and len(frame) < 4096


def run_of(**kw) -> dict:
    base = {"exit": 1, "wall_s": 0.5, "max_rss_mb": 40.0, "stdout_lines": 0, "stderr_lines": 1, "killed": False,
            "stdout": "", "stderr": "att-log: f.mcap: damaged record at byte 44: CRC\n"}
    return {**base, **kw}


@pytest.mark.parametrize("tool, kind, change, phrase", [
    ("att-log info", "flip", dict(exit=0), "exit 0"),
    ("att-log repair", "cut", dict(exit=1), "exit 1"),
    ("att-replay", "bomb", dict(stderr="Traceback (most recent call last):\n  x\nOverflowError\n", stderr_lines=3),
     "traceback"),
    ("att-replay", "flip", dict(stderr="att-replay: damaged record\n"), "no byte offset"),
    ("att-log info", "name", dict(exit=0, stderr="", stderr_lines=0, stdout="  /a\x1b[2J  std_msgs/msg/Empty\n"),
     "raw control"),
    ("att-replay", "name", dict(exit=2, stdout=logtools.ZEN + ".\n"), "imported"),
    ("att-log repair", "bomb", dict(max_rss_mb=1100.0), "peak RSS"),
    ("att-review", "flip", dict(wall_s=2.5), "2.50 s"),
    ("att-log info", "cut", dict(wall_s=31.0, killed=True, exit=-9), "killed"),
])
def test_the_criterion_fails_what_it_should(tool, kind, change, phrase):
    code = max(logtools.ALLOWED[tool][kind])             # a documented answer passes...
    base = dict(exit=code) if code else dict(exit=0, stderr="", stderr_lines=0)
    assert logtools.judge(tool, kind, run_of(**base)) == []
    failed = logtools.judge(tool, kind, run_of(**{**base, **change}))      # ...and fails with one change
    assert any(phrase in f for f in failed), failed


def test_a_review_written_from_a_readable_part_is_not_held_to_the_refusal_time():
    done = run_of(exit=0, wall_s=3.0, stderr="", stderr_lines=0, stdout="summary\n", stdout_lines=1)
    assert logtools.judge("att-review", "cut", done) == []
    assert logtools.judge("att-replay", "cut", done) == ["3.00 s"]


def test_the_probe_measures_its_child_alone(tmp_path):
    """A child that allocates 300 MB shows it; the parent's own memory does not leak into a small child."""
    import sys

    big = logtools.measure([sys.executable, "-c", "b = bytearray(300 << 20); b[::4096] = b'x' * len(b[::4096])"],
                           {}, tmp_path)
    small = logtools.measure([sys.executable, "-I", "-S", "-c", "pass"], {}, tmp_path)
    assert big["exit"] == 0 and big["max_rss_mb"] > 300
    assert small["exit"] == 0 and small["max_rss_mb"] < 60, small
    assert Path(tmp_path / "stdout.txt").exists()
