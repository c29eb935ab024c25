"""``att-mc``: Monte Carlo campaigns — how a plan fares when the model is wrong.

    att-mc campaigns/swift_demo.yaml --runs 1000 --json mc.json          # local Dask cluster, a core each
    att-mc campaigns/swift_demo.yaml --scheduler tcp://host:8786 --json mc.json
    att-mc campaigns/swift_demo.yaml --runs 1000 --resume                # the runs the table does not hold
    att-mc rerun campaigns/swift_demo.yaml SEED --mcap run.mcap           # one run's full log

The plan is made once on the nominal model (:func:`~att_planner.tools.closed_loop.plan_in_process`),
then every run flies it on its dispersed truth (:mod:`att_sim.truth.dispersions`,
:mod:`~att_planner.tools.monte_carlo.run`) on a Dask cluster
(:mod:`~att_planner.tools.monte_carlo.cluster`), rows streamed back with a progress bar, each in
the table as soon as it is back. Ctrl-C stops the campaign and writes the report of the runs that
finished; ``--resume`` flies only the runs the table does not hold (after an interrupt, or a client
killed). Writes the table (CSV), the figures and the summary JSON
(:mod:`~att_planner.tools.monte_carlo.report`); prints the summary's main figures. Exit codes: 0
done (also when runs failed: that is the campaign's finding), 1 interrupted, 2 bad input (one line
``att-mc: ...``, no traceback).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from att_msgs_py.errors import RequestError
from att_planner.tools.monte_carlo import report
from att_planner.tools.monte_carlo.cluster import ClusterError, client_for, local_workers, merge, stream
from att_planner.tools.monte_carlo.run import checked, planned
from att_planner.tools.tune import ProgressBar
from att_sim.truth import dispersions as disp

MAX_WORKERS = 1024


def positive(kind, top: int):
    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not 0 < value <= top:
            raise argparse.ArgumentTypeError(f"must be in (0, {top}], got {text}")
        return value
    return parse


def campaign_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="att-mc", description=__doc__.splitlines()[0],
                                epilog="att-mc rerun CAMPAIGN SEED --mcap PATH: one run's full log")
    p.add_argument("campaign", help="campaign YAML (campaigns/swift_demo.yaml)")
    p.add_argument("--runs", type=positive(int, disp.MAX_RUNS), default=None,
                   help="run count (default: the campaign's runs)")
    p.add_argument("--json", type=Path, default=None, help="summary JSON (default: OUT/summary.json)")
    p.add_argument("--out", type=Path, default=Path("runs/mc"), help="folder of the table and figures")
    p.add_argument("--workers", type=positive(int, MAX_WORKERS), default=None,
                   help="local cluster worker processes (default: the cores)")
    p.add_argument("--scheduler", default=None, help="Dask scheduler address: fly on that cluster")
    p.add_argument("--timeout", type=positive(float, 3600), default=10.0,
                   help="s to reach the scheduler (default 10)")
    p.add_argument("--chunk", type=positive(int, 10_000), default=None,
                   help="runs per task (default: about 4 tasks per worker, at most 50 runs)")
    p.add_argument("--resume", action="store_true",
                   help="keep the runs already in OUT/runs.csv (an interrupted campaign's) and fly the others")
    p.add_argument("--no-figures", action="store_true")
    p.add_argument("--no-progress", action="store_true")
    return p


def rerun_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="att-mc rerun", description="fly one run of a campaign again, with its full log")
    p.add_argument("campaign")
    p.add_argument("seed", type=int, help="the run's seed (the table's and the summary's 'seed')")
    p.add_argument("--mcap", type=Path, required=True, help="MCAP log to write (the recorder's layout)")
    p.add_argument("--json", type=Path, default=None, help="the run's row as JSON")
    return p


def run_campaign(args) -> int:
    campaign = disp.load_campaign(args.campaign)
    count = args.runs or campaign.runs
    runs = [(i, disp.run_seed(campaign.seed, i)) for i in range(count)]
    setup = checked(campaign, [seed for _, seed in runs])
    workers = args.workers or local_workers()
    done = report.resumed(args.out / "runs.csv", runs) if args.resume else {}
    todo, resumed, interrupted = [r for r in runs if r[0] not in done], len(done), False
    table = report.Table(args.out / "runs.csv", done)
    with client_for(args.scheduler, workers, args.timeout) as client:
        setup = planned(setup)
        workers = len(client.scheduler_info().get("workers", {})) or workers
        bar = None if args.no_progress else ProgressBar()
        chunk = args.chunk or max(1, min(50, len(todo) // (4 * workers)))
        start = time.monotonic()
        chunks = stream(client, setup, todo, chunk)
        try:
            for got in chunks:
                table.add(merge(done, got))
                if bar is not None:
                    ok = sum(bool(r["success"]) for r in done.values())
                    bar.update(len(done) / count, f"{len(done)}/{count} runs, {ok} successful")
        except KeyboardInterrupt:
            interrupted = True
        finally:
            chunks.close()
        wall = time.monotonic() - start
    rows = list(done.values())
    if bar is not None:
        bar.close()
    table = table.close()
    correlations = report.rank_correlations(rows)
    top = max(correlations, key=lambda k: abs(correlations[k])) if correlations else None
    figures = [] if args.no_figures or not rows else report.figures(rows, args.out, top)
    plan = {"duration": setup.plan.duration, "method": setup.plan.method}
    summary = report.summary(rows, runs=count, wall=wall, workers=workers, table=table, figures=figures,
                             interrupted=interrupted, campaign=str(campaign.path), scenario=setup.scenario.name,
                             plan=plan, resumed=resumed)
    path = args.json or args.out / "summary.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n")
    e = summary["final_error_deg"]
    kept = f", {resumed} resumed from the table" if resumed else ""
    print(f"att-mc: {summary['runs']} runs in {wall:.1f} s on {workers} workers "
          f"({summary['runs_per_second'] or 0:.3f} runs/s{kept}), "
          f"success {100 * (summary['success_rate'] or 0):.1f} %, final error p99 {e['p99']} deg; "
          f"{'INTERRUPTED, ' if interrupted else ''}wrote {path}")
    return 1 if interrupted else 0


def rerun(args) -> int:
    from att_planner.tools.monte_carlo.log import write_run_log

    setup = planned(checked(disp.load_campaign(args.campaign), [args.seed]))
    row = write_run_log(setup, args.seed, args.mcap)
    if args.json is not None:
        args.json.write_text(json.dumps({k: report.plain(v) for k, v in row.items()}, indent=2) + "\n")
    print(f"att-mc: seed {args.seed}: {'success' if row['success'] else 'FAILED: ' + row['reason']}, final error "
          f"{row['final_error_deg']:.5f} deg, min margin {row['min_margin_deg']:.3f} deg; MCAP: {args.mcap}")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    is_rerun = bool(argv) and argv[0] == "rerun"
    args = (rerun_parser().parse_args(argv[1:]) if is_rerun else campaign_parser().parse_args(argv))
    try:
        return rerun(args) if is_rerun else run_campaign(args)
    except (ValueError, ClusterError, RequestError) as err:
        print(f"att-mc: {' '.join(str(err).split())}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
