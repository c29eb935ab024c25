"""Run a planning method in a child process that is killed if it overruns its time.

Flight-software style isolation for the planner node: a solver that ignores its deadline, hangs
or crashes (a segfault in a native solver) costs one child process, never the node. Children are
forked from a ``forkserver`` that has already imported the numerics, so starting one is cheap;
at most ``max_parallel`` solve at once (the rest wait, within their own budget).

A problem with a sky (issue 13) crosses to the child as the recipe of its sky (:class:`_Portable`:
the epoch and the orbit, a TLE orbit as its epoch and lines), since skyfield's and SGP4's objects
do not pickle; the child rebuilds the sky (about 0.1 s) and its zone fit.
"""
from __future__ import annotations

import multiprocessing
import os
import threading
import time
from dataclasses import dataclass, replace
from datetime import datetime

from att_msgs_py.types import Plan, Status
from att_planner.methods import Method
from att_planner.problem import ManeuverProblem
from att_planner.service.planning import run_method
from att_sim.ephemeris import Sky
from att_sim.orbit import Orbit, TLEOrbit

_CONTEXT = multiprocessing.get_context("forkserver")
_CONTEXT.set_forkserver_preload(["att_planner.service.planning", "numpy", "scipy.optimize", "att_sim.ephemeris",
                                 "skyfield.api", "sgp4.api"])
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


@dataclass(frozen=True)
class _Portable:
    """A problem without its sky, and what rebuilds the sky: its epoch and orbit (a TLE orbit as
    ``(epoch, line1, line2)``)."""

    problem: ManeuverProblem
    epoch: datetime
    orbit: Orbit | tuple

    @classmethod
    def of(cls, value):
        if not isinstance(value, ManeuverProblem) or value.sky is None:
            return value
        orbit = value.sky.orbit
        recipe = (orbit.epoch, orbit.line1, orbit.line2) if isinstance(orbit, TLEOrbit) else orbit
        return cls(replace(value, sky=None), value.sky.epoch, recipe)

    def restore(self) -> ManeuverProblem:
        orbit = TLEOrbit(*self.orbit) if isinstance(self.orbit, tuple) else self.orbit
        return replace(self.problem, sky=Sky(self.epoch, orbit))


def _child(conn, function, args: tuple, kwargs: dict) -> None:
    args = tuple(a.restore() if isinstance(a, _Portable) else a for a in args)
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
        portable = tuple(_Portable.of(a) for a in args)
        child = _CONTEXT.Process(target=_child, args=(sender, function, portable, kwargs), daemon=True)
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
