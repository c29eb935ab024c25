"""A campaign's table read back for ``att-mc --resume`` (:func:`att_planner.tools.monte_carlo.report.resumed`):
a last line cut short by a killed client is left out; a table of another campaign, a damaged line
or a run twice is refused with a ValueError naming the file, the line and the column."""
from __future__ import annotations

import math

import pytest

from att_planner.tools.monte_carlo import report
from att_planner.tools.monte_carlo.run import OUTCOMES

RUNS = [(0, 11), (1, 22), (2, 33)]


def row(run: int, seed: int, **changes) -> dict:
    outcomes = {"success": True, "code": 0, "final_error_deg": 0.01 * (run + 1), "final_rate": 1e-6,
                "min_margin_deg": math.nan, "peak_wheel_ratio": 0.5, "peak_torque_ratio": 0.25,
                "settling_time": 1.0 / 3.0, "start_time": 3.0, "cpu_seconds": 0.1, "reason": "a, \"quoted\" text"}
    return {"run": run, "seed": seed, "inertia_scale[0]": 1.0 + run / 7, **outcomes, **changes}


def test_a_table_reads_back_exactly_and_a_torn_last_line_is_left_out(tmp_path):
    rows = {r: row(r, s) for r, s in RUNS[:2]}
    table = report.Table(tmp_path / "runs.csv", dict(rows))
    assert repr(report.resumed(tmp_path / "runs.csv", RUNS)) == repr(rows)          # NaN included
    text = (tmp_path / "runs.csv").read_text()
    (tmp_path / "runs.csv").write_text(text + "2,33,1.2857")                      # a client killed mid-write
    kept = report.resumed(tmp_path / "runs.csv", RUNS)
    assert list(kept) == [0, 1] and kept[1]["settling_time"] == 1.0 / 3.0 and math.isnan(kept[0]["min_margin_deg"])
    assert kept[0]["reason"] == 'a, "quoted" text' and kept[0]["success"] is True
    table = report.Table(tmp_path / "runs.csv", kept)                            # the resumed campaign's table
    table.rows[2] = row(2, 33)
    table.add([table.rows[2]])
    assert list(report.resumed(tmp_path / "runs.csv", RUNS)) == [0, 1, 2]


def test_no_table_resumes_nothing(tmp_path):
    assert report.resumed(tmp_path / "runs.csv", RUNS) == {}


def write(path, rows):
    report.write_table(rows, path)
    return path


@pytest.mark.parametrize("rows, words", [
    ([row(0, 11), row(1, 99)], "line 3: run 1 has seed 99, this campaign's run 1 has seed 22 (a table of another"),
    ([row(0, 11), row(5, 66)], "line 3: run 5 is not a run of this campaign (runs 0 to 2)"),
    ([row(0, 11), row(0, 11)], "line 3: run 0 a second time"),
    ([row(0, 11, final_error_deg="lots")], "line 2: column final_error_deg: expected a number, found 'lots'"),
    ([row(0, 11, success="maybe")], "line 2: column success: expected True or False, found 'maybe'"),
])
def test_a_table_of_another_campaign_or_damaged_is_refused(tmp_path, rows, words):
    path = write(tmp_path / "runs.csv", rows)
    with pytest.raises(ValueError) as err:
        report.resumed(path, RUNS)
    assert str(err.value).startswith(str(path)) and words in str(err.value)


def test_a_line_missing_fields_or_a_file_that_is_no_table_is_refused(tmp_path):
    path = write(tmp_path / "runs.csv", [row(0, 11)])
    path.write_text(path.read_text() + "1,22,0.5\n")
    with pytest.raises(ValueError, match=r"line 3: 3 fields, expected the header's 14"):
        report.resumed(path, RUNS)
    path.write_text(path.read_text().splitlines()[0] + "\n" + "0,11," + ",".join(["1.0"] * 13) + "\n")
    with pytest.raises(ValueError, match=r"line 2: 15 fields, expected the header's 14"):
        report.resumed(path, RUNS)
    path.write_text("run,seed\n0,11\n")
    with pytest.raises(ValueError, match="not a campaign's table: no column " + ", ".join(OUTCOMES)):
        report.resumed(path, RUNS)
