"""``att-bench cluster``: a worker's memory growth taken from the sample at a tenth of the runs, and
the study's history line (every figure read from its JSON)."""
from __future__ import annotations

import json

import pytest

from att_planner.tools.bench import cluster, main
from att_planner.tools.bench import history as hist


def samples():
    """Two workers: one importing then steady, one leaking 1 MiB a sample after its warm-up."""
    return [(float(i), 10 * i, [100.0 + min(i, 2) * 40, 150.0 + (i if i >= 3 else 0)]) for i in range(11)]


def test_a_workers_growth_is_from_a_tenth_of_the_runs_to_the_end():
    rss = cluster.growth(samples(), runs=300)             # a tenth: 30 rows, the fourth sample
    assert rss["warm_rows"] == 30
    steady, leaking = rss["workers"]
    assert steady == {"warm_mib": 180.0, "peak_mib": 180.0, "last_mib": 180.0, "growth_mib": 0.0}
    assert leaking["warm_mib"] == 153.0 and leaking["last_mib"] == 160.0 and leaking["growth_mib"] == 7.0


def test_a_worker_gone_before_the_end_has_no_growth():
    gone = [(s, n, [r[0], None if s >= 9 else r[1]]) for s, n, r in samples()]
    assert cluster.growth(gone, runs=300)["workers"][1]["growth_mib"] is None


def payload(**changes) -> dict:
    rss = cluster.growth(samples(), runs=300)
    base = {"campaign": "c.yaml", "runs": 300, "workers": 2, "local": 10.0, "cluster": 9.5, "throughput_ratio": 0.95,
            "throughput_target": cluster.THROUGHPUT_RATIO, "rows_equal": True, "rss": rss, "rss_growth_mib": 7.0,
            "growth_limit_mib": cluster.GROWTH_LIMIT_MIB, "passed": True,
            "machine": {"cores": 2, "load_1min": 1.0, "date": "2026-12-05T06:00:00Z", "commit": "abc1234"}}
    return base | changes


def test_the_history_line_holds_the_jsons_figures(tmp_path):
    path = tmp_path / "cluster.json"
    path.write_text(json.dumps(payload()))
    history = tmp_path / "history.jsonl"
    assert main(["history", "--append", str(path), "--history", str(history)]) == 0
    (row,) = hist.read(history)
    assert row["study"] == "cluster" and row["case"] == "300 runs, 2 workers" and row["value"] == 0.95
    assert row["met"] is True and row["unit"] == "×" and "≥ 0.9×" in row["target"]
    assert row["metrics"]["rss_peak_mib"] == 180.0 and row["metrics"]["cluster_runs_per_s"] == 9.5
    assert row["command"] == f"att-bench cluster --campaign c.yaml --runs 300 --workers 2 --json {path}"


@pytest.mark.parametrize("changes, says", [
    ({"throughput_ratio": float("nan")}, "'throughput_ratio' must be a finite number"),
    ({"rss": {}}, "has no 'rss.workers'"),
])
def test_a_damaged_cluster_json_is_refused(tmp_path, capsys, changes, says):
    path = tmp_path / "cluster.json"
    path.write_text(json.dumps(payload(**changes)))
    assert main(["history", "--append", str(path), "--history", str(tmp_path / "h.jsonl")]) != 0
    assert says in capsys.readouterr().out


def test_a_campaign_that_fails_stops_the_study_in_one_line(tmp_path, capsys):
    """A campaign att-mc refuses (here: no such file) ends the study with its line and one more, exit 1."""
    with pytest.raises(SystemExit) as stop:
        main(["cluster", "--campaign", str(tmp_path / "none.yaml"), "--runs", "2", "--out", str(tmp_path)])
    assert str(stop.value).startswith("att-bench cluster: att-mc ") and str(stop.value).endswith("exited 2")
    assert "none.yaml" in capsys.readouterr().err
