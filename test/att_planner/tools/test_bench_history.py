"""``att-bench history``: a study's JSON summarised into one line of benchmarks/history.jsonl, hostile
inputs refused with a sentence, and the committed history's latest lines equal to the kept JSONs."""
import json
import math
import shutil
from datetime import datetime
from pathlib import Path

import pytest

from att_planner.tools.bench import history as hist
from att_planner.tools.bench import main

ROOT = Path(__file__).resolve().parents[3]
BENCHMARKS = ROOT / "benchmarks"
NOT_STUDY_RUNS = {"sky_search.json"}        # the sky case search's output


def _lines(path: Path) -> list[dict]:
    return hist.read(path) if path.exists() else []


def test_append_writes_the_study_line_from_its_json(tmp_path, capsys):
    """A smooth JSON appended twice (the second with t_f above the published DFSP): two lines, each
    with the JSON's figures, the second not met, and the latest of the case the second."""
    run = tmp_path / "smooth_swift.json"
    shutil.copy(BENCHMARKS / "smooth_swift.json", run)
    history = tmp_path / "history.jsonl"
    assert main(["history", "--append", str(run), "--history", str(history)]) == 0
    payload = json.loads(run.read_text())
    (row,) = _lines(history)
    assert row["study"] == "smooth" and row["case"] == "swift" and row["unit"] == "TU"
    assert row["value"] == payload["tf"] and row["metrics"]["solve_s"] == payload["solve_seconds"]
    assert row["met"] is True and "5.9 TU" in row["target"]
    assert row["json"] == str(run) and row["command"] == f"att-bench smooth --case swift --json {run}"
    assert row["machine"]["cores"] == payload["machine"]["cores"]
    assert row["load_1min"] == payload["machine"]["load_1min"]
    datetime.strptime(row["date"], "%Y-%m-%dT%H:%M:%SZ")
    assert list(row) == list(hist.FIELDS)

    payload["tf"] = 6.0
    payload["machine"].update(date="2030-12-05T01:02:03Z", commit="abc1234")   # after the first run
    run.write_text(json.dumps(payload))
    assert main(["history", "--append", str(run), "--history", str(history), "--case", "swift",
                 "--command", "by hand", "--no-json"]) == 0
    assert "NOT met" in capsys.readouterr().out
    first, second = _lines(history)
    assert first == row and second["value"] == 6.0 and second["met"] is False
    assert second["json"] is None and second["command"] == "by hand"
    assert second["date"] == "2030-12-05T01:02:03Z" and second["commit"] == "abc1234"   # the run's, not the append's
    assert hist.latest(_lines(history))[("smooth", "swift")] == second


@pytest.mark.parametrize("name, text, says", [
    ("broken.json", '{"tf": 1', "not JSON (line 1"),
    ("list.json", "[1, 2]", "expected a JSON object, found list"),
    ("other.json", '{"hello": 1}', "matches no study"),
    ("nan.json", None, "'tf' must be a finite number, found nan"),
    ("missing.json", None, "has no 'published.dfsp'"),
    ("absent.json", "", "cannot be read"),
    ("date.json", None, "'machine.date' must be a UTC time"),
])
def test_a_hostile_json_is_refused_and_nothing_appended(tmp_path, capsys, name, text, says):
    path = tmp_path / name
    if name == "nan.json":
        payload = json.loads((BENCHMARKS / "smooth_swift.json").read_text())
        payload["tf"] = math.nan
        path.write_text(json.dumps(payload))
    elif name == "date.json":
        payload = json.loads((BENCHMARKS / "smooth_swift.json").read_text())
        payload["machine"]["date"] = "yesterday"
        path.write_text(json.dumps(payload))
    elif name == "missing.json":
        payload = json.loads((BENCHMARKS / "smooth_swift.json").read_text())
        del payload["published"]["dfsp"]
        path.write_text(json.dumps(payload))
    elif text:
        path.write_text(text)
    history = tmp_path / "history.jsonl"
    assert main(["history", "--append", str(path), "--history", str(history)]) == 2
    out = capsys.readouterr().out
    assert says in out and out.count("\n") == 1
    assert not history.exists()


def test_a_wrong_study_name_is_refused(tmp_path):
    """A JSON named as another study's is refused by the key that study needs."""
    with pytest.raises(SystemExit):
        main(["history", "--append", str(BENCHMARKS / "timing.json"), "--study", "nonsense",
              "--history", str(tmp_path / "h.jsonl")])
    with pytest.raises(hist.HistoryError, match="has no 'case'"):
        hist.line(json.loads((BENCHMARKS / "timing.json").read_text()), study="smooth", json_path=None,
                  date="2026-01-01T00:00:00Z", commit=None, source="json")


def test_a_damaged_history_line_is_named(tmp_path):
    bad = tmp_path / "history.jsonl"
    bad.write_text('{"study": "smooth"}\n')
    with pytest.raises(hist.HistoryError, match=r"history.jsonl:1: a history line needs case"):
        hist.read(bad)
    bad.write_text("{oops\n")
    with pytest.raises(hist.HistoryError, match=r"history.jsonl:1: not JSON"):
        hist.read(bad)


def test_the_committed_history_holds_each_kept_json_as_its_latest_line():
    """Every study JSON in benchmarks/ is the latest line of exactly one study and case, and that
    line's figures are the JSON's (summarised now, as ``--append`` would)."""
    rows = hist.read(BENCHMARKS / "history.jsonl")
    latest = hist.latest(rows)
    kept = {row["json"]: row for row in latest.values() if row["json"]}
    on_disk = {f"benchmarks/{p.name}" for p in BENCHMARKS.glob("*.json") if p.name not in NOT_STUDY_RUNS}
    assert set(kept) == on_disk
    for path, row in kept.items():
        again = hist.line(hist.load_json(ROOT / path), case=row["case"], json_path=path, command=row["command"],
                          date=row["date"], commit=row["commit"], source=row["source"])
        assert {k: again[k] for k in ("study", "metric", "value", "unit", "target", "met", "metrics")} == \
               {k: row[k] for k in ("study", "metric", "value", "unit", "target", "met", "metrics")}, path
    for row in rows:
        datetime.strptime(row["date"], "%Y-%m-%dT%H:%M:%SZ")
        assert row["met"] in (True, False, None) and row["study"] in hist.BY_NAME
        assert row["json"] or row["source"] != "json"
    assert [r["date"] for r in rows] == sorted(r["date"] for r in rows)


def test_a_line_is_added_after_the_last_one_dated_no_later(tmp_path):
    history = tmp_path / "history.jsonl"
    rows = [dict(r) for r in hist.read(BENCHMARKS / "history.jsonl")[-3:]]
    for row, date in zip(rows, ("2026-12-06T09:47:20Z", "2026-12-06T10:30:12Z", "2026-12-06T10:29:24Z")):
        row["date"] = date
        hist.append(row, history)
    assert [r["date"] for r in hist.read(history)] == ["2026-12-06T09:47:20Z", "2026-12-06T10:29:24Z",
                                                      "2026-12-06T10:30:12Z"]
    early = dict(rows[0], date="2026-01-01T00:00:00Z", case="first")
    hist.append(early, history)
    assert hist.read(history)[0]["case"] == "first" and len(hist.read(history)) == 4
    same = dict(rows[0], case="same date")                   # equal dates: after the line already there
    hist.append(same, history)
    assert [r["case"] for r in hist.read(history)][1:3] == [rows[0]["case"], "same date"]
    assert list(tmp_path.iterdir()) == [history]                # replaced whole, nothing left beside it


def test_a_study_json_without_a_machine_gets_one(tmp_path, monkeypatch):
    """``att-bench <study> --json`` names the machine, load, time and commit of a run whose study
    writes none, so that its history line records where it was measured."""
    import sys
    import types

    from att_planner.tools import bench

    study = types.ModuleType("bench_fake_study", "fake: a study that writes no machine.")
    study.configure = lambda parser: None
    study.run = lambda args: {"observed": 3, "missed": 0}
    monkeypatch.setitem(sys.modules, "bench_fake_study", study)
    monkeypatch.setitem(bench.STUDIES, "fake", "bench_fake_study")
    path = tmp_path / "fake.json"
    assert main(["fake", "--json", str(path)]) == 0
    machine = json.loads(path.read_text())["machine"]
    assert machine["cores"] >= 1 and machine["load_1min"] >= 0.0
    datetime.strptime(machine["date"], "%Y-%m-%dT%H:%M:%SZ")
    assert set(machine) == {"cores", "python", "load_1min", "omp_num_threads", "date", "commit"}


def test_benchmarks_md_tables_are_the_historys(tmp_path, capsys):
    """BENCHMARKS.md's summary table and each study's table are what ``att-bench summary`` renders from
    the committed history; a changed figure or a missing row is found."""
    from att_planner.tools.bench import summary

    rows = hist.read(BENCHMARKS / "history.jsonl")
    blocks = summary.render(rows)
    page = (ROOT / "BENCHMARKS.md").read_text()
    assert page.index(summary.begin(summary.SUMMARY)) < page.index("\n## ", page.index("## Summary") + 1)
    for name, block in blocks.items():
        assert block in page, f"BENCHMARKS.md's {name} table differs from `att-bench summary` (run it with --write)"
    assert summary.differing(page, blocks) == []
    for study, case in summary.ROWS:
        assert f"| {study}, {case} |" in blocks[summary.SUMMARY]

    changed = [dict(r) for r in rows]
    changed[-1]["value"] = changed[-1]["value"] + 1.0
    history, md = tmp_path / "history.jsonl", tmp_path / "BENCHMARKS.md"
    for row in changed:
        hist.append(row, history)
    md.write_text(page)
    assert main(["summary", "--history", str(history), "--markdown", str(md), "--check"]) == 1
    assert "differs" in capsys.readouterr().out
    assert main(["summary", "--history", str(history), "--markdown", str(md), "--write"]) == 0
    assert main(["summary", "--history", str(history), "--markdown", str(md), "--check"]) == 0
    assert md.read_text().count("\n## ") == page.count("\n## ")

    with pytest.raises(hist.HistoryError, match="no line for smooth swift"):
        summary.render([r for r in rows if (r["study"], r["case"]) != ("smooth", "swift")])
    md.write_text("# no tables\n")
    assert main(["summary", "--history", str(history), "--markdown", str(md), "--write"]) == 2


@pytest.mark.parametrize("name, flags", [
    ("soak_leo_observatory.json", "--scenario leo_observatory --hours 6 --rate-Hz 5 --cpu bench_out/soak_cpu"),
    ("day_rtf_max.json", "--mission observatory_day --rtf max"),
])
def test_the_command_of_a_kept_json_carries_the_options_that_made_it(tmp_path, name, flags):
    """A line's command re-makes its figure: the scenario, length and rate of a soak (and --cpu when it
    was timed by layer), the mission and --rtf of a day (their defaults would fly another scenario or
    pace the day)."""
    run = tmp_path / name
    shutil.copy(BENCHMARKS / name, run)
    history = tmp_path / "history.jsonl"
    assert main(["history", "--append", str(run), "--history", str(history)]) == 0
    (row,) = _lines(history)
    study = name.split("_")[0]
    assert row["command"] == f"att-bench {study} {flags} --json {run}"
