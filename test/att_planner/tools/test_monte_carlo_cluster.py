"""``att-mc --scheduler`` on a Dask cluster of separate processes (a ``dask scheduler`` and two
``dask worker`` processes on localhost, :mod:`att_planner.tools.monte_carlo.processes`): the same
rows as the local cluster's, also when a worker is killed mid-campaign (its runs flown again on
the other, every run in the table once). The campaign is the tests' 1° slew (test/data), 40 runs,
one run a task."""
from __future__ import annotations

import math
import os
from pathlib import Path

import pytest

import att_planner.tools.monte_carlo as mc
from att_planner.tools.monte_carlo import report
from att_planner.tools.monte_carlo.processes import dask_processes
from att_sim.truth import dispersions as disp

DATA = Path(__file__).resolve().parents[2] / "data"
CAMPAIGN = DATA / "campaigns" / "short.yaml"
RUNS = 40


@pytest.fixture(autouse=True)
def short_scenario(monkeypatch):
    monkeypatch.setenv("ATT_CONFIG_PATH", str(DATA / "config"))


@pytest.fixture(scope="module")
def local_rows(tmp_path_factory):
    """The 40-run campaign's rows on the local cluster (two worker processes)."""
    out = tmp_path_factory.mktemp("local")
    with pytest.MonkeyPatch.context() as m:
        m.setenv("ATT_CONFIG_PATH", str(DATA / "config"))
        assert mc.main([str(CAMPAIGN), "--runs", str(RUNS), "--workers", "2", "--out", str(out),
                        "--no-figures", "--no-progress"]) == 0
    return report.read_table(out / "runs.csv")


def assert_same_rows(rows: list[dict], expected: list[dict]) -> None:
    """Every run once, in run order, each row ``expected``'s but for ``cpu_seconds``: numbers to
    1e-12 relative (a batch's rows do not depend on the runs flown with them, to rounding)."""
    assert [r["run"] for r in rows] == [r["run"] for r in expected] == list(range(len(expected)))
    for row, want in zip(rows, expected):
        assert set(row) == set(want)
        for key, value in want.items():
            if key == "cpu_seconds":
                continue
            if isinstance(value, float) and not math.isnan(value):
                assert math.isclose(row[key], value, rel_tol=1e-12, abs_tol=0.0), (row["run"], key, row[key], value)
            elif isinstance(value, float):
                assert math.isnan(row[key]), (row["run"], key)
            else:
                assert row[key] == value, (row["run"], key)


@pytest.mark.slow
def test_a_campaign_survives_a_worker_killed_mid_way_with_the_local_clusters_rows(tmp_path, local_rows, monkeypatch):
    assert [r["seed"] for r in local_rows] == [disp.run_seed(7, i) for i in range(RUNS)]
    streamed, killed = mc.stream, {}

    def killing_a_busy_worker(client, setup, runs, chunk):
        """The campaign's stream; once its first rows are here, the worker busiest with the rest is killed."""
        for got in streamed(client, setup, runs, chunk):
            if not killed:
                busy = max(client.processing().items(), key=lambda item: len(item[1]))
                pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
                victim = next(w for w in cluster.workers if w.pid == pid)
                victim.kill()
                victim.wait(10)
                killed.update(pending=len(busy[1]), rows_before=len(got))
            yield got

    monkeypatch.setattr(mc, "stream", killing_a_busy_worker)
    with dask_processes(tmp_path / "cluster", workers=2) as cluster:
        code = mc.main([str(CAMPAIGN), "--runs", str(RUNS), "--scheduler", cluster.address, "--chunk", "1",
                        "--out", str(tmp_path / "mc"), "--no-figures", "--no-progress"])
        assert code == 0
        assert sum(w.poll() is None for w in cluster.workers) == 1          # one worker killed, one flew on
    assert killed["pending"] > 0 and killed["rows_before"] < RUNS         # killed while it held runs
    assert_same_rows(report.read_table(tmp_path / "mc" / "runs.csv"), local_rows)
