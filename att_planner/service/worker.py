"""Run a planning method in a child process that is killed if it overruns its time.

Flight-software style isolation for the planner node: a solver that ignores its deadline, hangs
or crashes (a segfault in a native solver) costs one child process, never the node. Children are
forked from a ``forkserver`` that has already imported the numerics, so starting one is cheap;
at most ``max_parallel`` solve at once (the rest wait, within their own budget).

A problem with a sky (issue 13) crosses to the child as it is: :class:`att_sim.ephemeris.Sky` and
:class:`att_sim.orbit.TLEOrbit` pickle as their recipes (epoch and orbit, epoch and lines), since
skyfield's and SGP4's objects do not; the child rebuilds their tables as it needs them.
"""
from __future__ import annotations

import multiprocessing
import os
import threading
import time

from att_msgs_py.types import Plan, Status
from att_planner.methods import Method
from att_planner.problem import ManeuverProblem
from att_planner.service.planning import run_method

_CONTEXT = multiprocessing.get_context("forkserver")
_CONTEXT.set_forkserver_preload(["att_planner.service.planning", "numpy", "scipy.optimize", "att_sim.ephemeris",
                                 "skyfield.api", "sgp4.api", "casadi", "att_planner.methods.time_optimal.smooth"])
_SLOTS = threading.BoundedSemaphore(max(1, os.cpu_count() or 1))
KILL_GRACE = 0.5            # s after the wait before the child is terminated


def set_max_parallel(n: int) -> None:
    global _SLOTS
    _SLOTS = threading.BoundedSemaphore(max(1, int(n)))


def warm_up() -> None:
    """Start the fork server now (it imports the numerics once), not on the first request."""
    child = _CONTEXT.Process(target=int, daemon=True)
    child.start()
    child.join()


def _child(conn, function, args: tuple, kwargs: dict) -> None:
    conn.send(function(*args, **kwargs))
    conn.close()


def call_isolated(function, args: tuple, kwargs: dict, wait: float | None, *, on_death):
    """``function(*args, **kwargs)`` in a child process (``function`` importable by name).

    Returns its result, ``None`` when it has not answered within ``wait`` s (+ grace; the child
    is then killed), or ``on_death(message)`` when the child died without answering.
    """
    start = time.monotonic()
    if not _SLOTS.acquire(timeout=wait):
        return None
    try:
        remaining = None if wait is None else max(0.0, wait - (time.monotonic() - start))
        receiver, sender = _CONTEXT.Pipe(duplex=False)
        child = _CONTEXT.Process(target=_child, args=(sender, function, args, kwargs), daemon=True)
        child.start()
        sender.close()
        try:
            if receiver.poll(None if remaining is None else remaining + KILL_GRACE):
                return receiver.recv()
            if not child.is_alive():
                return on_death(f"solver process died (exit code {child.exitcode})")
            return None
        except EOFError:
            child.join(1.0)
            return on_death(f"solver process died (exit code {child.exitcode})")
        finally:
            if child.is_alive():
                child.terminate()
                child.join(1.0)
                if child.is_alive():
                    child.kill()
            child.join()
            receiver.close()
    finally:
        _SLOTS.release()


def run_isolated(method: Method, problem: ManeuverProblem, options: dict, wait: float | None) -> Plan | None:
    """A planning method in a child; ``None`` when it has not answered within ``wait`` s (+ grace)."""
    return call_isolated(run_method, (method, problem, options), {}, wait,
                         on_death=lambda message: Plan(method=method.name, status=Status.FAILED, message=message))
