"""Where a campaign's runs fly: a Dask cluster, local by default (``LocalCluster``, one
single-threaded worker process per core: the runs are pure Python and numpy on small arrays, so
threads would only share one interpreter lock) or an existing one reached by its scheduler address
— one code path; each worker of an existing cluster is checked to run the client's suite version
(:func:`check_versions`, and each task again: a worker may join later). The shared
:class:`~att_planner.tools.monte_carlo.run.Setup` is scattered to every worker once; runs go out in
chunks of ``chunk`` seeds and their rows come back as each chunk finishes (:func:`stream`); an
interrupt (Ctrl-C) cancels what has not finished and keeps the rows that have.
"""
from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager

from att_msgs_py.errors import ErrorCode, clip
from att_planner.tools.monte_carlo import version
from att_planner.tools.monte_carlo.run import Setup, fly_batch

# The local cluster's housekeeping, slowed: the runs keep every core busy, and Dask's defaults wake
# its processes every 10-500 ms (the event-loop watchdog's tick, the system monitor, the nannies'
# memory checks, the workers' statistical profiler sampling the running task every 10 ms). An idle
# 2-worker cluster took 1.06 s of CPU in 20 s with them, 0.24 s with these (measured; BENCHMARKS.md).
QUIET = {"distributed.admin.tick.interval": "1s", "distributed.admin.system-monitor.interval": "5s",
         "distributed.worker.memory.monitor-interval": "1s", "distributed.worker.profile.enabled": False}

# no dashboard, and the scheduler's own HTTP server (health, metrics) on a free port rather than Dask's
# 8787, which a second cluster on the machine would find taken (a warning, the port moved)
HTTP_ON_A_FREE_PORT = {"dashboard_address": ":0"}


class ClusterError(RuntimeError):
    """A cluster that cannot be reached or started (one sentence)."""


class VersionMismatch(ClusterError):
    """A worker that runs another suite version (:func:`~att_planner.tools.monte_carlo.version.suite_version`)
    than the client: refused (one sentence naming the worker and both versions)."""

    code = ErrorCode.VERSION_MISMATCH


def mismatch(workers: list[str], theirs: str, ours: str) -> VersionMismatch:
    """The refusal of ``workers`` (addresses) running suite version ``theirs`` (client: ``ours``)."""
    who = f"Dask worker {workers[0]} runs" if len(workers) == 1 else f"Dask workers {', '.join(workers)} run"
    return VersionMismatch(clip(f"{who} suite version {theirs}, this client {ours}: install the client's version "
                                f"on every worker (docs/monte-carlo.md, multi-machine campaigns)"))


def check_versions(client) -> dict[str, str]:
    """Every worker's suite version (by address), each the client's, else :class:`VersionMismatch`
    naming the workers of one other version, the first in address order (a worker that cannot
    import the suite: its error as its version)."""
    ours = version.suite_version()
    found = {address: (v if isinstance(v, str) else f"unknown ({type(v).__name__}: {clip(v, 80)})")
             for address, v in client.run(worker_version, on_error="return").items()}
    others: dict[str, list[str]] = {}
    for address, theirs in sorted(found.items()):
        if theirs != ours:
            others.setdefault(theirs, []).append(address)
    if others:
        theirs, workers = next(iter(others.items()))
        raise mismatch(workers, theirs, ours)
    return found


def worker_version() -> str:
    """This process's suite version (run on each worker by :func:`check_versions`)."""
    return version.suite_version()


@contextmanager
def client_for(scheduler: str | None, workers: int, timeout: float):
    """A ``distributed.Client`` of the cluster at ``scheduler`` (reached within ``timeout`` s, else
    :class:`ClusterError`) or of a local cluster of ``workers`` processes; closed on exit."""
    import logging

    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.ERROR)      # its connection retries are our one line
    if scheduler:
        try:
            client = Client(scheduler, timeout=timeout)
        except (OSError, TimeoutError, ValueError) as exc:
            raise ClusterError(f"--scheduler {scheduler}: no Dask scheduler reached within {timeout:g} s "
                               f"({' '.join(str(exc).split())[:160]})") from None
        try:
            check_versions(client)
            yield client
        finally:
            client.close()
        return
    import dask

    with environment_kept(), dask.config.set(QUIET), \
            LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                         scheduler_kwargs=HTTP_ON_A_FREE_PORT, silence_logs=40,
                         env={"OMP_NUM_THREADS": "1"}) as cluster, Client(cluster) as client:
        yield client


@contextmanager
def environment_kept():
    """This process's environment as it was on entry, put back on exit. A Dask nanny writes its
    workers' ``distributed.nanny.pre-spawn-environ`` (``MALLOC_TRIM_THRESHOLD_=65536``,
    ``OMP_NUM_THREADS``, ...) into its parent's ``os.environ`` before each spawn
    (``distributed/nanny.py``), where every process started later (nodes, tools, tests) would
    inherit settings meant for the workers."""
    saved = dict(os.environ)
    try:
        yield
    finally:
        for name in set(os.environ) - set(saved):
            del os.environ[name]
        os.environ.update(saved)


def fly_chunk(setup: Setup, seeds: list[tuple[int, int]], client_version: str) -> list[dict]:
    """The rows of ``(run, seed)`` pairs, flown as one batch in this worker (:func:`fly_batch`) —
    when it runs the client's suite version ``client_version`` (a worker that joined after
    :func:`check_versions`), else :class:`VersionMismatch`."""
    ours = version.suite_version()
    if ours != client_version:
        from distributed import get_worker

        try:
            address = get_worker().address
        except ValueError:               # not in a worker: this process
            address = "(this process)"
        raise mismatch([address], ours, client_version)
    return fly_batch(setup, seeds)


def stream(client, setup: Setup, runs: list[tuple[int, int]], chunk: int) -> Iterator[list[dict]]:
    """Rows of ``runs`` (``(run, seed)`` pairs) in chunks, each as soon as it finishes (in finishing
    order). A chunk's result is released on the cluster once it is here (a long campaign does not
    pile its rows up in the workers' memory). A worker lost mid-campaign: the scheduler runs its
    chunks again on the others (``distributed.scheduler.allowed-failures`` losses per chunk); a
    chunk comes back once, but the caller keys rows by run (:func:`merge`), so a row that does come
    twice is kept once. Closing the iterator (an interrupt) cancels the chunks still out."""
    from distributed import as_completed

    shared = client.scatter(setup, broadcast=True)
    ours = version.suite_version()
    finished = as_completed([client.submit(fly_chunk, shared, runs[i:i + chunk], ours, pure=False)
                             for i in range(0, len(runs), chunk)])
    try:
        for future in finished:
            rows = future.result()
            future.release()
            yield rows
    finally:
        client.cancel(list(finished.futures))


def merge(rows: dict[int, dict], got: list[dict]) -> list[dict]:
    """Add the rows of ``got`` to ``rows`` (by run index) that it does not hold yet; those rows."""
    new = {row["run"]: row for row in got if row["run"] not in rows}
    rows.update(new)
    return list(new.values())


def local_workers() -> int:
    """Worker processes of the default local cluster: the cores this process may use."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
