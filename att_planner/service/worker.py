"""Run a planning method in a child process that is killed if it overruns its time.

Flight-software style isolation for the planner node: a solver that ignores its deadline, hangs
or crashes (a segfault in a native solver) costs one worker process, never the node. Workers are
forked from a ``forkserver`` that has already imported the numerics and serve one task after
another, so what a method keeps between problems (its NLPs built for a shape, the compiled
integrator) serves the next request too. Building an NLP costs a cold worker most of a second or
more (a solve then takes a fraction of that), so:

* a worker is warm before it serves: :func:`start_pool` starts the workers and runs the warm-up
  set with :func:`set_warm_up` (the planner's: its scenarios' maneuvers, which build the NLPs of
  the shapes it serves) in each before the planner reports ready, and a worker retired later is
  replaced by a warmed one in the background;
* a worker that overruns its request (a hung solver, or one building an NLP of a shape it was not
  warmed for) is killed, and replaced by a warmed one in the background. (Letting it finish its
  build instead, holding its slot for up to 5 s, starved the answers of concurrent requests on
  this 2-core machine: the budget test's most expensive requests came 1.6-1.9 s after a 0.5 s
  budget.)
* a replacement warms in the background at a lower priority (:data:`BACKGROUND_NICENESS`, its
  warm-up thread only, :func:`at_low_priority`): the seconds of CPU it takes to build its NLPs
  otherwise compete with what the node answers meanwhile (on 2 cores, rclpy's 0.9 s of CPU
  converting a request of 100,000 zones takes 2.4 s of wall time beside a warming worker). The
  workers of :func:`start_pool` warm at full priority: nothing is served before them.

A worker that dies is replaced. At most ``max_parallel`` solve at once (the rest wait, within their
own budget).

Memory comes back: a worker hands its allocator's free pages back after every task
(:func:`att_msgs_py.memory.trim`; IPOPT's and CasADi's work arrays are freed, not returned, otherwise),
and one whose resident set is still above :data:`MAX_WORKER_RSS` after a task is retired and replaced
by a warmed one, so what a solver keeps between problems cannot accumulate without bound.

A problem with a sky crosses to the child as it is: :class:`att_sim.models.ephemeris.Ephemeris` and
:class:`att_sim.models.orbit.TLEOrbit` pickle as their recipes (epoch and orbit, epoch and lines), since
skyfield's and SGP4's objects do not; the child rebuilds their tables as it needs them.
"""
from __future__ import annotations

import multiprocessing
import os
import sys
import threading
import time

from att_msgs_py import memory
from att_msgs_py.types import Plan, Status
from att_planner.methods import Method
from att_planner.problem import ManeuverProblem
from att_planner.service.planning import run_method

_CONTEXT = multiprocessing.get_context("forkserver")
_CONTEXT.set_forkserver_preload(["att_planner.service.planning", "numpy", "scipy.optimize", "att_sim.models.ephemeris",
                                 "skyfield.api", "sgp4.api", "casadi", "att_planner.methods.time_optimal.smooth"])
_SLOTS = threading.BoundedSemaphore(max(1, os.cpu_count() or 1))
MAX_WORKER_RSS = 640 * 1024 * 1024    # bytes: a worker above it after a task is recycled (a warm one holds ~200 MB)
KILL_GRACE = 0.5            # s after the wait before the child is terminated
BACKGROUND_NICENESS = 10    # nice(2) increment of a replacement worker's warm-up thread (Linux: per thread)
WARM_UP_TIMEOUT = 300.0     # s a worker's warm-up may take before the worker is given up (the node serves anyway)


def set_max_parallel(n: int) -> None:
    global _SLOTS
    _SLOTS = threading.BoundedSemaphore(max(1, int(n)))


def warm_up() -> None:
    """Start the fork server now (it imports the numerics once), not on the first request."""
    child = _CONTEXT.Process(target=int, daemon=True)
    child.start()
    child.join()


_IDLE: list = []                # (process, connection) of the workers waiting for a task, the last used last
_IDLE_LOCK = threading.Lock()
_WARM_UP: tuple | None = None   # (function, args) every new worker of the pool runs before it serves
_POOL_SIZE = 0                  # workers kept warm (start_pool)


def _serve(conn) -> None:
    """A worker: run each ``(function, args, kwargs)`` received and send its result back, until the
    pipe closes; after each, the memory the task freed goes back to the system."""
    memory.configure()
    while True:
        try:
            function, args, kwargs = conn.recv()
        except EOFError:
            return
        result = function(*args, **kwargs)
        del function, args, kwargs
        memory.trim()                     # before the answer: the resident set the caller reads is trimmed
        conn.send(result)
        del result


def _spawn():
    """A new worker process and its end of the pipe."""
    conn, theirs = _CONTEXT.Pipe()
    process = _CONTEXT.Process(target=_serve, args=(theirs,), daemon=True)
    process.start()
    theirs.close()
    return process, conn


def set_warm_up(function, args: tuple = ()) -> None:
    """``function(*args)`` (importable by name) is run by every worker :func:`start_pool` starts
    or replaces, before it takes a request."""
    global _WARM_UP
    _WARM_UP = (function, tuple(args))


def at_low_priority(function, args: tuple):
    """``function(*args)`` run in a thread of this process whose niceness is raised by
    :data:`BACKGROUND_NICENESS` (on Linux niceness is per thread: the caller's thread, which later
    solves, keeps its own); its result, or its exception raised again here. Elsewhere it runs at the
    caller's priority."""
    outcome: list = []

    def run():
        try:
            if sys.platform == "linux":
                tid = threading.get_native_id()
                os.setpriority(os.PRIO_PROCESS, tid, os.getpriority(os.PRIO_PROCESS, tid) + BACKGROUND_NICENESS)
            outcome.append((True, function(*args)))
        except BaseException as exc:       # handed to the calling thread
            outcome.append((False, exc))

    thread = threading.Thread(target=run, name="warm-up")
    thread.start()
    thread.join()
    ok, value = outcome[0]
    if not ok:
        raise value
    return value


def _warm_worker(background: bool = False) -> bool:
    """Start a worker, run the warm-up in it (at a low priority when ``background``,
    :func:`at_low_priority`) and add it to the idle ones; False if it died or its warm-up overran
    :data:`WARM_UP_TIMEOUT`."""
    process, conn = _spawn()
    if _WARM_UP is not None:
        try:
            task = (at_low_priority, (_WARM_UP[0], _WARM_UP[1]), {}) if background else (_WARM_UP[0], _WARM_UP[1], {})
            conn.send(task)
            if not conn.poll(WARM_UP_TIMEOUT):
                raise TimeoutError
            conn.recv()
        except (EOFError, OSError):       # TimeoutError is an OSError
            _retire(process, conn)
            return False
    with _IDLE_LOCK:
        _IDLE.insert(0, (process, conn))        # the least recently used end: requests prefer a worker that served
    return True


def start_pool(n: int) -> None:
    """Start ``n`` workers and warm them (:func:`set_warm_up`) in parallel; return when all are ready."""
    global _POOL_SIZE
    _POOL_SIZE = max(0, int(n))
    threads = [threading.Thread(target=_warm_worker, daemon=True) for _ in range(_POOL_SIZE)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()


def idle_workers() -> int:
    """Workers waiting for a task (alive or not yet found dead)."""
    with _IDLE_LOCK:
        return len(_IDLE)


def _worker():
    """An idle worker (the one used last: its caches are the warmest), or a new one."""
    with _IDLE_LOCK:
        while _IDLE:
            process, conn = _IDLE.pop()
            if process.is_alive():
                return process, conn
            conn.close()
    return _spawn()


def _retire(process, conn) -> None:
    """Stop a worker (it overran or died): terminate, then kill."""
    if process.is_alive():
        process.terminate()
        process.join(1.0)
        if process.is_alive():
            process.kill()
    process.join()
    conn.close()


def _replace() -> None:
    """A warmed worker in the background for one retired, while the pool is short of its size."""
    if idle_workers() < _POOL_SIZE:
        threading.Thread(target=_warm_worker, args=(True,), daemon=True).start()


def call_isolated(function, args: tuple, kwargs: dict, wait: float | None, *, on_death):
    """``function(*args, **kwargs)`` in a worker process (``function`` importable by name).

    Returns its result, ``None`` when it has not answered within ``wait`` s (+ grace; the worker
    is then killed and replaced), or ``on_death(message)`` when the worker died without answering.
    """
    start = time.monotonic()
    if not _SLOTS.acquire(timeout=wait):
        return None
    try:
        remaining = None if wait is None else max(0.0, wait - (time.monotonic() - start))
        process, conn = _worker()
        try:
            conn.send((function, args, kwargs))
            if conn.poll(None if remaining is None else remaining + KILL_GRACE):
                result = conn.recv()
                if (memory.rss_bytes(process.pid) or 0) <= MAX_WORKER_RSS:
                    with _IDLE_LOCK:
                        _IDLE.append((process, conn))
                    process = None        # kept for the next task; else retired and replaced (finally)
                return result
            if not process.is_alive():
                return on_death(f"solver process died (exit code {process.exitcode})")
            return None
        except (EOFError, OSError):
            process.join(1.0)
            return on_death(f"solver process died (exit code {process.exitcode})")
        finally:
            if process is not None:
                _retire(process, conn)
                _replace()
    finally:
        _SLOTS.release()


def run_isolated(method: Method, problem: ManeuverProblem, options: dict, wait: float | None) -> Plan | None:
    """A planning method in a worker; ``None`` when it has not answered within ``wait`` s (+ grace)."""
    return call_isolated(run_method, (method, problem, options), {}, wait,
                         on_death=lambda message: Plan(method=method.name, status=Status.FAILED, message=message))
