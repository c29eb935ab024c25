"""Where settling times are computed: in process, on local worker processes or on a Dask cluster
(:func:`make_executor`), always through :class:`BatchEvaluator`, which counts the work."""
from __future__ import annotations

import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from att_planner.tuning.settling import (
    MagnetorquerCase,
    SettlingResult,
    SimSettings,
    simulate_settling,
)


def _simulate_chunk(args) -> SettlingResult:
    """Module-level worker entry (picklable) for executors."""
    case, settings, kp, kd, h, group, stop_above, race = args
    return simulate_settling(case, kp, kd, h, settings, group=group, stop_above=stop_above, race=race)


class SerialExecutor:
    """Runs everything in this process."""

    workers = 1

    def map(self, fn, items) -> list:
        return [fn(item) for item in items]

    def close(self):
        pass


class ProcessExecutor:
    """Local worker processes (``concurrent.futures``); the default parallel back end."""

    def __init__(self, workers: int = 2):
        self.workers = int(workers)
        self._pool = ProcessPoolExecutor(max_workers=self.workers)

    def map(self, fn, items) -> list:
        return list(self._pool.map(fn, items))

    def close(self):
        self._pool.shutdown(wait=True, cancel_futures=True)


class DaskExecutor:
    """A Dask distributed cluster reached through its scheduler address (``tcp://host:8786``),
    or an existing ``distributed.Client``."""

    def __init__(self, scheduler):
        from distributed import Client  # optional dependency, imported only when asked for

        self._own = not hasattr(scheduler, "gather")
        self.client = Client(scheduler) if self._own else scheduler
        self.workers = max(1, len(self.client.scheduler_info().get("workers", {})))

    def map(self, fn, items) -> list:
        return self.client.gather(self.client.map(fn, list(items), pure=False))

    def close(self):
        if self._own:
            self.client.close()


def make_executor(workers: int = 2, scheduler=None):
    """Dask when a scheduler address (or client) is given, else local processes (serial for 1)."""
    if scheduler:
        return DaskExecutor(scheduler)
    if workers < 1:
        raise ValueError("workers must be at least 1")
    return SerialExecutor() if workers == 1 else ProcessExecutor(workers)


class BatchEvaluator:
    """The one place settling times are computed; counts the work and splits large batches.

    Batches of at least ``2 * min_chunk`` cases are split into one chunk per executor worker
    (groups kept whole, so pruning still sees a group together); smaller ones run in process,
    where a vectorised batch is already cheaper than shipping it.
    """

    def __init__(self, case: MagnetorquerCase | None = None, settings: SimSettings | None = None,
                 executor=None, min_chunk: int = 96):
        self.case = MagnetorquerCase() if case is None else case
        self.settings = SimSettings() if settings is None else settings
        self.executor = executor or SerialExecutor()
        self.min_chunk = int(min_chunk)
        self.evaluations = 0
        self.case_steps = 0
        self.batches = 0
        self.on_batch = None        # optional hook (evaluator, result) after every batch: progress

    def _done(self, res: SettlingResult) -> SettlingResult:
        self.case_steps += res.case_steps
        if self.on_batch is not None:
            self.on_batch(self, res)
        return res

    def settling(self, kp, kd, h, *, group=None, stop_above=None, race: bool = False) -> SettlingResult:
        """:func:`~att_planner.tuning.settling.simulate_settling` of the batch, split over the
        executor when large."""
        h = np.atleast_2d(np.asarray(h, float))
        n = h.shape[0]
        kp = np.broadcast_to(np.asarray(kp, float), (n,))
        kd = np.broadcast_to(np.asarray(kd, float), (n,))
        group = np.arange(n) if group is None else np.asarray(group)
        bound = None if stop_above is None else np.broadcast_to(np.asarray(stop_above, float), (n,))
        self.evaluations += n
        self.batches += 1
        workers = getattr(self.executor, "workers", 1)
        if workers <= 1 or n < 2 * self.min_chunk:
            return self._done(simulate_settling(self.case, kp, kd, h, self.settings, group=group,
                                                stop_above=bound, race=race))
        _, g_index = np.unique(group, return_inverse=True)
        chunk_of = (g_index * workers) // (g_index.max() + 1)
        parts = [np.flatnonzero(chunk_of == c) for c in range(workers)]
        parts = [p for p in parts if p.size]
        start = time.perf_counter()
        results = self.executor.map(_simulate_chunk, [
            (self.case, self.settings, kp[p], kd[p], h[p], group[p], None if bound is None else bound[p], race)
            for p in parts])
        ts, status = np.empty(n), np.empty(n, int)
        for p, r in zip(parts, results):
            ts[p], status[p] = r.ts, r.status
        return self._done(SettlingResult(ts, status, sum(r.case_steps for r in results),
                                         max(r.steps for r in results), time.perf_counter() - start))
