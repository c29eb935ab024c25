"""Independent solves on two cores: a forked child takes every other job.

A multistart's solves share nothing but the NLP they were built on. With ``os.fork`` the child
inherits the built NLPs (nothing is rebuilt, nothing pickled but the answers), solves the jobs of
odd index while this process solves the others, and sends its answers back through a pipe. Used
only where forking is safe and pays: Linux-like ``fork``, a single thread in this process (a fork
copies only the calling thread, so another's locks could be held for ever in the child), two or
more cores and jobs. A child that fails in any way (a crash, an answer that does not unpickle) has
its jobs solved here: the answers never depend on it, and they are the sequential answers.
"""
from __future__ import annotations

import os
import pickle
import threading


def can_fork() -> bool:
    return hasattr(os, "fork") and threading.active_count() == 1 and (os.cpu_count() or 1) >= 2


def map_in_lanes(function, jobs: list) -> list:
    """``[function(job) for job in jobs]``, the odd-indexed jobs solved by a forked child when
    :func:`can_fork` (module docstring); ``function`` returns picklable answers."""
    jobs = list(jobs)
    if len(jobs) < 2 or not can_fork():
        return [function(job) for job in jobs]
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:                                     # the child: its jobs, its answers, then out
        status = 1
        try:
            os.close(read_end)
            with os.fdopen(write_end, "wb") as pipe:
                pipe.write(pickle.dumps([function(job) for job in jobs[1::2]]))
            status = 0
        finally:
            os._exit(status)                         # never back into the parent's code (or its atexit)
    os.close(write_end)
    mine = [function(job) for job in jobs[0::2]]
    with os.fdopen(read_end, "rb") as pipe:
        data = pipe.read()
    _, status = os.waitpid(pid, 0)
    try:
        theirs = pickle.loads(data) if status == 0 else None
    except (pickle.UnpicklingError, EOFError, ValueError):
        theirs = None
    if theirs is None or len(theirs) != len(jobs[1::2]):
        theirs = [function(job) for job in jobs[1::2]]
    out = [None] * len(jobs)
    out[0::2], out[1::2] = mine, theirs
    return out
