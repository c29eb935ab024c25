"""A Dask scheduler and workers started as separate processes on this machine, as a user starts them
on several (``dask scheduler``, ``dask worker ADDRESS``): what the tests and the cluster benchmark
fly ``att-mc --scheduler`` against. Random ports (the scheduler's address read from its scheduler
file), every wait bounded, every process stopped on exit — also when the body fails.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from att_planner.tools.monte_carlo.cluster import QUIET, ClusterError

POLL_S = 0.05          # s between looks at the scheduler file (its writer has no other signal)


@dataclass
class Processes:
    """The running cluster: its scheduler's address and processes (workers in start order)."""

    address: str
    scheduler: subprocess.Popen
    workers: list[subprocess.Popen] = field(default_factory=list)


def quiet_environment(extra: dict[str, str] | None = None) -> dict[str, str]:
    """This process's environment with the workers' settings: one numpy thread, and the local
    cluster's slowed housekeeping (:data:`~att_planner.tools.monte_carlo.cluster.QUIET`) as Dask
    configuration variables."""
    env = dict(os.environ, OMP_NUM_THREADS="1", **(extra or {}))
    for key, value in QUIET.items():
        env["DASK_" + "__".join(part.upper().replace("-", "_") for part in key.split("."))] = str(value)
    return env


def start(command: list[str], env: dict[str, str], log: Path) -> subprocess.Popen:
    """``command`` in its own process group (stopped as one), its output to ``log``."""
    with open(log, "w") as fh:
        return subprocess.Popen(command, stdout=fh, stderr=subprocess.STDOUT, env=env, start_new_session=True)


def stop(process: subprocess.Popen, timeout: float = 10.0) -> None:
    """Stop ``process`` and its group: SIGTERM, then SIGKILL after ``timeout`` s."""
    if process.poll() is not None:
        return
    for sig, wait in ((signal.SIGTERM, timeout), (signal.SIGKILL, None)):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:
            return
        try:
            process.wait(wait)
            return
        except subprocess.TimeoutExpired:
            continue


@contextmanager
def dask_processes(folder: Path, workers: int, timeout: float = 60.0, preload: list[str | None] | None = None,
                   env: dict[str, str] | None = None) -> Iterator[Processes]:
    """A ``dask scheduler`` and ``workers`` × ``dask worker ADDRESS --nworkers 1 --nthreads 1
    --no-nanny`` (no nanny: killing a worker's process kills the worker) on 127.0.0.1, every worker
    connected within ``timeout`` s (else :class:`ClusterError`). ``preload[i]``: a module worker i
    loads at start (``--preload``). Logs and the scheduler file in ``folder``."""
    from distributed import Client

    folder.mkdir(parents=True, exist_ok=True)
    env = quiet_environment(env)
    file = folder / "scheduler.json"
    file.unlink(missing_ok=True)
    scheduler = start([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
                       "--no-dashboard", "--dashboard-address", ":0", "--scheduler-file", str(file)], env,
                      folder / "scheduler.log")
    cluster = Processes("", scheduler)
    try:
        end = time.monotonic() + timeout
        while not file.is_file() or not file.read_text().strip():
            if scheduler.poll() is not None or time.monotonic() > end:
                raise ClusterError(f"the Dask scheduler wrote no scheduler file within {timeout:g} s "
                                   f"(see {folder / 'scheduler.log'})")
            time.sleep(POLL_S)          # wait-ok: polls the file the scheduler writes once it listens
        cluster.address = json.loads(file.read_text())["address"]
        for i in range(workers):
            extra = ["--preload", preload[i]] if preload and preload[i] else []
            cluster.workers.append(start(
                [sys.executable, "-m", "distributed.cli.dask_worker", cluster.address, "--nworkers", "1",
                 "--nthreads", "1", "--no-nanny", "--no-dashboard", "--host", "127.0.0.1", *extra],
                env, folder / f"worker{i}.log"))
        with Client(cluster.address, timeout=timeout) as client:
            try:
                client.wait_for_workers(workers, timeout=max(end - time.monotonic(), 1.0))
            except TimeoutError:
                raise ClusterError(f"{workers} Dask workers did not all connect within {timeout:g} s "
                                   f"(see the logs in {folder})") from None
        yield cluster
    finally:
        for process in [*cluster.workers, scheduler]:
            stop(process)
