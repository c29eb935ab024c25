"""``att-mc --scheduler`` on a Dask cluster of separate processes (a ``dask scheduler`` and two
``dask worker`` processes on localhost, :mod:`att_planner.tools.monte_carlo.processes`): the same
rows as the local cluster's, also when a worker is killed mid-campaign (its runs flown again on
the other, every run in the table once); a campaign whose client was killed, resumed from its
table; a worker of another suite version refused. The campaign is the tests' 1° slew (test/data),
40 runs, one run a task."""
from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from distributed import Client

import att_planner.tools.monte_carlo as mc
from att_msgs_py.errors import ErrorCode
from att_planner.tools.monte_carlo import cluster as cluster_module
from att_planner.tools.monte_carlo import report, version
from att_planner.tools.monte_carlo.processes import dask_processes, stop
from att_sim.truth import dispersions as disp
from helpers.other_suite_version import OTHER

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


def assert_same_rows(rows: list[dict], expected: list[dict], runs: list[int] | None = None) -> None:
    """Every run of ``runs`` (default: all) once, in run order, each row ``expected``'s but for
    ``cpu_seconds``: numbers to 1e-12 relative (a batch's rows do not depend on the runs flown with
    them, to rounding)."""
    runs = list(range(len(expected))) if runs is None else runs
    assert [r["run"] for r in rows] == [r["run"] for r in expected] == runs
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


def table_rows(path: Path) -> int:
    """Complete rows in the table at ``path`` (0 before it exists)."""
    return max(path.read_text().count("\n") - 1, 0) if path.is_file() else 0


@pytest.mark.slow
def test_a_campaign_whose_client_was_killed_resumes_from_its_table(tmp_path, local_rows, monkeypatch):
    """The client (and its local cluster: one process group) killed once a few rows are in its table;
    ``--resume`` flies exactly the runs the table does not hold, and the table is the uninterrupted one's."""
    out = tmp_path / "mc"
    client = subprocess.Popen([sys.executable, "-m", "att_planner.tools.monte_carlo", str(CAMPAIGN), "--runs",
                               str(RUNS), "--workers", "1", "--chunk", "1", "--out", str(out), "--no-figures",
                               "--no-progress"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                              start_new_session=True)
    try:
        end = time.monotonic() + 120
        while table_rows(out / "runs.csv") < 3 and client.poll() is None and time.monotonic() < end:
            time.sleep(0.01)            # wait-ok: polls the table the client appends to (its only progress signal)
        os.killpg(client.pid, signal.SIGKILL)
        client.wait(10)
    finally:
        stop(client)
    assert client.returncode == -signal.SIGKILL, client.stderr.read().decode()
    kept = report.read_table(out / "runs.csv")
    assert 3 <= len(kept) < RUNS
    assert_same_rows(sorted(kept, key=report.by_run), [local_rows[r["run"]] for r in sorted(kept, key=report.by_run)],
                     runs=sorted(r["run"] for r in kept))

    streamed, flown = mc.stream, []

    def recorded(client_, setup, runs, chunk):
        flown.extend(run for run, _ in runs)
        yield from streamed(client_, setup, runs, chunk)

    monkeypatch.setattr(mc, "stream", recorded)
    assert mc.main([str(CAMPAIGN), "--runs", str(RUNS), "--workers", "2", "--out", str(out), "--resume",
                    "--no-figures", "--no-progress"]) == 0
    assert sorted(flown) == sorted(set(range(RUNS)) - {r["run"] for r in kept})
    summary = json.loads((out / "summary.json").read_text())
    assert summary["runs"] == RUNS and summary["resumed"] == len(kept) and not summary["interrupted"]
    final = report.read_table(out / "runs.csv")
    assert_same_rows(final, local_rows)
    assert {r["run"]: r["cpu_seconds"] for r in kept}.items() <= {r["run"]: r["cpu_seconds"] for r in final}.items()


def test_a_worker_of_another_suite_version_is_refused_naming_it_and_both_versions(tmp_path, capsys):
    other = Path(__file__).resolve().parents[2] / "helpers" / "other_suite_version.py"
    ours = version.suite_version()
    assert re.fullmatch(r"\S+\+[0-9a-f]{12}", ours) and ours != OTHER
    with dask_processes(tmp_path / "cluster", workers=2, preload=[None, str(other)]) as cluster:
        with Client(cluster.address, timeout=30) as client:
            versions = client.run(cluster_module.worker_version)
            assert sorted(versions.values()) == sorted([ours, OTHER])
            odd = next(address for address, v in versions.items() if v == OTHER)
        code = mc.main([str(CAMPAIGN), "--runs", "4", "--scheduler", cluster.address, "--out", str(tmp_path / "mc"),
                        "--no-figures", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert err.startswith(f"att-mc: Dask worker {odd} runs suite version {OTHER}, this client {ours}: install")
    assert report.read_table(tmp_path / "mc" / "runs.csv") == []                # nothing flown


def test_a_task_on_a_worker_of_another_version_is_refused():
    """A worker that joins after the check: its tasks refuse to fly (the campaign stops, its rows kept)."""
    with pytest.raises(cluster_module.VersionMismatch) as err:
        cluster_module.fly_chunk(None, [(0, 1)], OTHER)
    assert err.value.code == ErrorCode.VERSION_MISMATCH
    assert str(err.value).startswith(f"Dask worker (this process) runs suite version {version.suite_version()}, "
                                     f"this client {OTHER}")
