"""Cluster: a campaign's throughput on a Dask cluster of separate processes against the local
cluster, and its workers' memory over the runs.

Flies ``--campaign`` (``--runs`` runs) twice with ``att-mc`` (:mod:`att_planner.tools.monte_carlo`):
on the local cluster of ``--workers`` processes, then through ``--scheduler`` on a ``dask
scheduler`` and ``--workers`` ``dask worker`` processes started on this machine
(:func:`~att_planner.tools.monte_carlo.processes.dask_processes`). Reported: each campaign's runs
per second (from the first task out to the last row back, as ``att-mc`` counts it), their ratio
against :data:`THROUGHPUT_RATIO` (the cluster at least 0.9× the local cluster), whether the two
tables hold the same rows (to 1e-12 relative, ``cpu_seconds`` aside), and each cluster worker's
resident set (``Rss`` of ``smaps_rollup``, :func:`att_msgs_py.memory.rss_bytes`) sampled every
``--sample-s`` with the rows done: its growth from the sample when a tenth of the runs were done
(imports, the first batches and the allocator's pools by then in place) to the end, against
:data:`GROWTH_LIMIT_MIB`.
"""
from __future__ import annotations

import math
import tempfile
import threading
import time
from pathlib import Path

from att_msgs_py import memory

THROUGHPUT_RATIO = 0.9          # the cluster's runs/s at least this fraction of the local cluster's
GROWTH_LIMIT_MIB = 50.0         # a worker's resident set growth from a tenth of the runs to the end
WARM_FRACTION = 0.1             # of the runs done when a worker's baseline is taken
MIB = 1024 * 1024


def configure(parser):
    parser.add_argument("--campaign", default="campaigns/swift_demo.yaml", help="campaign YAML")
    parser.add_argument("--runs", type=int, default=1000, help="runs of each campaign (default 1000)")
    parser.add_argument("--workers", type=int, default=2, help="worker processes of each cluster (default 2)")
    parser.add_argument("--sample-s", type=float, default=1.0, help="s between RSS samples (default 1)")
    parser.add_argument("--out", default=None, help="folder of the tables and logs (default: a temporary one)")


def table_rows(path: Path) -> int:
    """Complete rows of the table ``att-mc`` appends to (0 before it exists)."""
    try:
        return max(path.read_bytes().count(b"\n") - 1, 0)
    except OSError:
        return 0


class Sampler(threading.Thread):
    """Samples ``(s, rows done, [RSS MiB of each pid])`` every ``period`` s until stopped."""

    def __init__(self, pids: list[int], table: Path, period: float):
        super().__init__(daemon=True)
        self.pids, self.table, self.period = pids, table, period
        self.samples: list[tuple[float, int, list[float | None]]] = []
        self.done = threading.Event()
        self.start_time = time.monotonic()

    def sample(self) -> None:
        rss = [memory.rss_bytes(pid) for pid in self.pids]
        self.samples.append((time.monotonic() - self.start_time, table_rows(self.table),
                             [None if r is None else r / MIB for r in rss]))

    def run(self) -> None:
        while not self.done.wait(self.period):
            self.sample()

    def stop(self) -> list:
        self.done.set()
        self.join(10)
        self.sample()
        return self.samples


def growth(samples: list, runs: int) -> dict:
    """Per worker: its RSS at the first sample with a tenth of the runs done, its peak and its last
    (MiB), and the growth from the first to the last."""
    warm = next((s for s in samples if s[1] >= WARM_FRACTION * runs), samples[-1])
    out = []
    for i in range(len(samples[-1][2])):
        series = [s[2][i] for s in samples if s[2][i] is not None]
        first, last = warm[2][i], samples[-1][2][i]
        out.append({"warm_mib": first, "peak_mib": max(series) if series else None, "last_mib": last,
                    "growth_mib": None if first is None or last is None else last - first})
    return {"warm_rows": warm[1], "workers": out}


def campaign(args, out: Path, scheduler: str | None) -> dict:
    import json

    import att_planner.tools.monte_carlo as mc

    argv = [args.campaign, "--runs", str(args.runs), "--out", str(out), "--json", str(out / "summary.json"),
            "--no-figures", "--no-progress"]
    argv += ["--scheduler", scheduler] if scheduler else ["--workers", str(args.workers)]
    code = mc.main(argv)
    if code != 0:                # att-mc printed why (one line): the study stops with one more, exit 1
        raise SystemExit(f"att-bench cluster: att-mc {' '.join(argv)} exited {code}")
    return json.loads((out / "summary.json").read_text())


def same_rows(a: Path, b: Path) -> bool:
    """Whether two tables hold the same rows (run order; numbers to 1e-12 relative, ``cpu_seconds`` aside)."""
    from att_planner.tools.monte_carlo.report import read_table

    def equal(x, y):
        if isinstance(x, float):
            return (math.isnan(x) and math.isnan(y)) or math.isclose(x, y, rel_tol=1e-12, abs_tol=0.0)
        return x == y

    ra, rb = read_table(a), read_table(b)
    return len(ra) == len(rb) and all(
        r.keys() == s.keys() and all(equal(r[k], s[k]) for k in r if k != "cpu_seconds") for r, s in zip(ra, rb))


def run(args) -> dict:
    from att_planner.tools.monte_carlo.processes import dask_processes

    folder = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="att_bench_cluster_"))
    local = campaign(args, folder / "local", None)
    with dask_processes(folder / "processes", args.workers) as cluster:
        sampler = Sampler([w.pid for w in cluster.workers], folder / "cluster" / "runs.csv", args.sample_s)
        sampler.start()
        try:
            remote = campaign(args, folder / "cluster", cluster.address)
        finally:
            samples = sampler.stop()
    ratio = remote["runs_per_second"] / local["runs_per_second"]
    rss = growth(samples, args.runs)
    worst = max((w["growth_mib"] for w in rss["workers"] if w["growth_mib"] is not None), default=math.nan)
    equal = same_rows(folder / "local" / "runs.csv", folder / "cluster" / "runs.csv")
    passed = ratio >= THROUGHPUT_RATIO and worst <= GROWTH_LIMIT_MIB and equal
    print(f"{'cluster':<10} {'runs':>6} {'workers':>7} {'wall s':>8} {'runs/s':>8}")
    for name, s in (("local", local), ("processes", remote)):
        print(f"{name:<10} {s['runs']:>6} {s['workers']:>7} {s['wall_seconds']:>8.1f} {s['runs_per_second']:>8.3f}")
    print(f"throughput ratio {ratio:.3f} (target ≥ {THROUGHPUT_RATIO:g}); rows equal: {equal}")
    for i, w in enumerate(rss["workers"]):
        print(f"worker {i}: RSS {w['warm_mib']:.1f} MiB at {rss['warm_rows']} rows, peak {w['peak_mib']:.1f}, "
              f"last {w['last_mib']:.1f}: growth {w['growth_mib']:+.1f} MiB (limit {GROWTH_LIMIT_MIB:g})")
    return {"campaign": args.campaign, "runs": args.runs, "workers": args.workers, "local": local["runs_per_second"],
            "cluster": remote["runs_per_second"], "throughput_ratio": ratio, "throughput_target": THROUGHPUT_RATIO,
            "local_wall_s": local["wall_seconds"], "cluster_wall_s": remote["wall_seconds"],
            "rows_equal": equal, "rss": rss, "rss_growth_mib": worst, "growth_limit_mib": GROWTH_LIMIT_MIB,
            "rss_samples": [{"s": s, "rows": n, "rss_mib": r} for s, n, r in samples], "passed": passed}
