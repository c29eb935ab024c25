"""Tasks for the solver workers' tests (importable by name in a worker process)."""
import os
import time

WARMED = False


def warm_marker() -> None:
    """A warm-up that leaves its mark in the worker."""
    global WARMED
    WARMED = True


def pid_and_warmth() -> tuple[int, bool]:
    return os.getpid(), WARMED


def sleep_then_pid(seconds: float) -> int:
    time.sleep(seconds)     # wait-ok: a task that takes time (or hangs), on purpose
    return os.getpid()


def built_nlps() -> int:
    """NLPs the collocation methods have built in this worker."""
    from att_planner.methods.time_optimal import model
    return len(model._NLPS)
