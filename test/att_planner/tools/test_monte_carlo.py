"""``att-mc``: a 20-run campaign on a local Dask cluster, its table reproduced run by run (to 1e-12
relative) from the seeds alone in this process, a run flown twice from its seed giving the same row,
the report's figures, an interrupted campaign's partial report, a run's full log, and bad input
refused in one line (an unreachable scheduler within its timeout). The campaign is the shipped
dispersions on a 1° slew (test/data), flown in about a second a run."""
from __future__ import annotations

import csv
import json
import math
import os
import socket
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import att_planner.tools.monte_carlo as mc
from att_msgs_py.log import read_log
from att_msgs_py.topics import COMMAND, ESTIMATE, IMU, PLANS, STAR_TRACKER, STATE
from att_planner.tools.monte_carlo import report
from att_planner.tools.monte_carlo import run as run_module
from att_planner.tools.monte_carlo.run import checked, fly, fly_batch, planned
from att_sim.truth import dispersions as disp

DATA = Path(__file__).resolve().parents[2] / "data"
CAMPAIGN = DATA / "campaigns" / "short.yaml"


@pytest.fixture(autouse=True)
def short_scenario(monkeypatch):
    monkeypatch.setenv("ATT_CONFIG_PATH", str(DATA / "config"))


@pytest.fixture(scope="module")
def setup():
    with pytest.MonkeyPatch.context() as m:
        m.setenv("ATT_CONFIG_PATH", str(DATA / "config"))
        return planned(checked(disp.load_campaign(CAMPAIGN)))


def rows_of(path: Path) -> list[dict]:
    with open(path) as fh:
        return list(csv.DictReader(fh))


def assert_same_row(row: dict, expected: dict) -> None:
    """``row`` is ``expected`` but for ``cpu_seconds``: its numbers to 1e-12 relative (a table's, read
    back from text, or a row's), everything else equal."""
    assert set(row) == set(expected)
    for key, want in expected.items():
        got = row[key]
        if key == "cpu_seconds":
            continue
        if isinstance(want, float):
            got = float(got)
            assert (math.isnan(got) and math.isnan(want)) or math.isclose(got, want, rel_tol=1e-12, abs_tol=0.0), \
                (key, got, want)
        else:
            assert str(got) == str(want), key


@pytest.mark.slow
def test_a_20_run_campaign_on_a_local_dask_cluster_is_reproduced_from_its_seeds(tmp_path, setup, capsys):
    out = tmp_path / "mc"
    environment = dict(os.environ)
    code = mc.main([str(CAMPAIGN), "--workers", "2", "--out", str(out), "--json", str(tmp_path / "mc.json"),
                    "--no-progress"])
    assert code == 0, capsys.readouterr().err
    assert dict(os.environ) == environment        # the nannies' worker settings did not stay in this process
    summary = json.loads((tmp_path / "mc.json").read_text())
    assert summary["runs"] == summary["requested"] == 20 and summary["workers"] == 2 and not summary["interrupted"]
    assert summary["runs_per_second"] == pytest.approx(20 / summary["wall_seconds"])
    for key in ("final_error_deg", "min_margin_deg", "peak_wheel_ratio"):
        assert set(summary[key]) >= {"mean", "p50", "p99", "max"}
    rows = rows_of(out / "runs.csv")
    assert [int(r["run"]) for r in rows] == list(range(20))
    assert [int(r["seed"]) for r in rows] == [disp.run_seed(7, i) for i in range(20)]
    success = [r["success"] == "True" for r in rows]
    assert summary["success_rate"] == pytest.approx(np.mean(success))
    errors = np.array([float(r["final_error_deg"]) for r in rows])
    assert summary["final_error_deg"]["max"] == pytest.approx(errors.max())
    assert summary["dispersions"]["inertia_scale[2]"]["mean"] == pytest.approx(
        np.mean([float(r["inertia_scale[2]"]) for r in rows]))
    worst = summary["worst"][0]
    assert worst["seed"] == int(rows[worst["run"]]["seed"])
    assert all(Path(f).is_file() for f in summary["figures"]) and len(summary["figures"]) == 2
    # the same seeds give the same table: two runs flown again here, alone, outside the cluster
    for run in (0, 13):
        assert_same_row(rows[run], fly(setup, int(rows[run]["seed"]), run))


def test_runs_flown_in_a_batch_give_the_rows_they_give_alone(setup, monkeypatch):
    """A batch's flight (the campaign's) is the runs' own flights, to 1e-12 relative — also when a
    run ends early and the batch goes on without it (here a run tumbling at 0.3 rad/s, beyond the
    star tracker's rate limit, whose estimate never converges); a run flown twice from its seed
    gives the same row."""
    runs = [(i, disp.run_seed(7, i)) for i in (1, 2, 5)]
    tumbling = runs[1][1]
    dispersed = run_module.dispersed

    def with_a_tumbling_run(setup_, seed):
        truth, values = dispersed(setup_, seed)
        return (replace(truth, omega0=np.array([0.3, 0.0, 0.0])) if seed == tumbling else truth), values
    monkeypatch.setattr(run_module, "dispersed", with_a_tumbling_run)
    batch = fly_batch(setup, runs)
    assert [row["code"] for row in batch] == [0, 313, 0]
    for (run, seed), row in zip(runs, batch):
        alone = fly(setup, seed, run)
        assert_same_row(row, alone)
    again = fly(setup, seed, run)                   # the last run, flown again from its seed: the same row
    assert {k: repr(v) for k, v in again.items() if k != "cpu_seconds"} == \
           {k: repr(v) for k, v in alone.items() if k != "cpu_seconds"}


def test_an_interrupted_campaign_keeps_its_finished_runs_and_writes_a_partial_report(tmp_path, setup, monkeypatch):
    def interrupted(client, setup_, runs, chunk):
        yield [fly(setup_, seed, run) for run, seed in runs[:2]]
        raise KeyboardInterrupt

    monkeypatch.setattr(mc, "stream", interrupted)
    code = mc.main([str(CAMPAIGN), "--runs", "6", "--workers", "1", "--out", str(tmp_path), "--no-figures",
                    "--no-progress"])
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert code == 1 and summary["interrupted"] and summary["runs"] == 2 and summary["requested"] == 6
    assert len(rows_of(tmp_path / "runs.csv")) == 2


def test_a_rerun_writes_the_full_log_of_exactly_that_run(tmp_path, setup):
    seed = disp.run_seed(7, 4)
    code = mc.main(["rerun", str(CAMPAIGN), str(seed), "--mcap", str(tmp_path / "run.mcap"),
                    "--json", str(tmp_path / "row.json")])
    assert code == 0
    row = json.loads((tmp_path / "row.json").read_text())
    assert row == pytest.approx({k: report.plain(v) for k, v in fly(setup, seed).items() if k != "cpu_seconds"}
                                | {"cpu_seconds": row["cpu_seconds"]})
    log = read_log(tmp_path / "run.mcap")
    assert {STATE, IMU, STAR_TRACKER, ESTIMATE, COMMAND, PLANS} <= set(log)
    truth, _ = disp.seed_truth(setup.campaign, setup.scenario, seed)
    assert log[STATE]["attitude"][0] == pytest.approx(truth.q0, abs=1e-12)
    assert log[STATE]["header.stamp"][-1] > setup.plan.duration


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_an_unreachable_scheduler_is_one_line_within_its_timeout(capsys):
    start = time.monotonic()
    code = mc.main([str(CAMPAIGN), "--scheduler", f"tcp://127.0.0.1:{free_port()}", "--timeout", "2",
                    "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and time.monotonic() - start < 20
    assert err.startswith("att-mc: --scheduler tcp://127.0.0.1:") and "within 2 s" in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("args, words", [
    (["no_such_campaign.yaml"], "no_such_campaign.yaml: (file): expected a readable file"),
    ([str(CAMPAIGN), "--runs", "0"], "--runs"),
    ([str(CAMPAIGN), "--workers", "many"], "--workers"),
    (["rerun", str(CAMPAIGN), "lucky", "--mcap", "x.mcap"], "seed"),
])
def test_bad_arguments_are_one_line(args, words, capsys):
    try:
        code = mc.main(args)
    except SystemExit as exit_:          # argparse: usage and one error line
        code = exit_.code
    err = capsys.readouterr().err
    assert code == 2 and words in err and "Traceback" not in err


def test_a_campaign_of_a_scenario_without_a_maneuver_is_refused(tmp_path, capsys):
    (tmp_path / "c.yaml").write_text("campaign: {scenario: bruni_celani, seed: 1, runs: 2}\n")
    assert mc.main([str(tmp_path / "c.yaml"), "--no-progress"]) == 2
    assert "no 'demo:' section" in capsys.readouterr().err


def test_rank_correlation_finds_the_dispersion_the_outcome_follows():
    rng = np.random.default_rng(0)
    x, noise = rng.normal(size=200), rng.normal(size=200)
    rows = [{"run": i, "seed": i, "a[0]": x[i], "b[0]": noise[i], "final_error_deg": math.exp(x[i])}
            for i in range(200)]
    rho = report.rank_correlations(rows)
    assert rho["a[0]"] == pytest.approx(1.0) and abs(rho["b[0]"]) < 0.2


def test_the_summary_is_the_same_whatever_order_the_runs_finished_in():
    """Rows come back in finishing order; every figure of the summary is of the rows in run order
    (a mean's float sum and the order of equally bad runs depend on it)."""
    rng = np.random.default_rng(1)
    rows = [{"run": i, "seed": 100 + i, "a[0]": float(rng.normal()), "success": i % 7 != 3,
             "code": 0 if i % 7 != 3 else 305,
             "final_error_deg": float(rng.lognormal(-4, 1)) if i % 7 != 3 else math.nan, "final_rate": 1e-5,
             "min_margin_deg": float(rng.normal(2, 0.1)), "peak_wheel_ratio": float(rng.uniform()),
             "peak_torque_ratio": float(rng.uniform()), "settling_time": float(rng.uniform(0, 5)), "start_time": 3.0,
             "cpu_seconds": 1.0, "reason": ""} for i in range(300)]
    shuffled = [rows[i] for i in rng.permutation(len(rows))]
    common = {"runs": 300, "wall": 10.0, "workers": 2, "table": Path("t.csv"), "figures": [], "interrupted": False,
              "campaign": "c.yaml", "scenario": "s", "plan": {}}
    assert json.dumps(report.summary(shuffled, **common)) == json.dumps(report.summary(rows, **common))
    assert report.summary(shuffled, **common)["worst"][0]["run"] == 3      # of the failed runs, the first by run
