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


_KEPT = []


def allocate_then_rss(megabytes: int, keep: bool) -> tuple[int, int]:
    """Touch ``megabytes`` MB in 64 KiB blocks from the heap, each followed by a 1 KiB block kept for
    good (so the heap cannot shrink from its top), free the large ones unless ``keep``; the worker's
    pid and the resident set it reads of itself before answering."""
    from att_msgs_py import memory

    blocks = []
    for _ in range(16 * megabytes):
        block = bytearray(64 * 1024)
        block[::4096] = b"x" * len(block[::4096])
        blocks.append(block)
        _KEPT.append(bytearray(1024))
    if keep:
        _KEPT.extend(blocks)
    del blocks
    return os.getpid(), memory.rss_bytes()


WARM_NICENESS = None


def warm_recording_niceness() -> None:
    """A warm-up that records the niceness of the thread it runs in."""
    import threading
    global WARM_NICENESS
    WARM_NICENESS = os.getpriority(os.PRIO_PROCESS, threading.get_native_id())


def niceness() -> tuple[int | None, int]:
    """The niceness the warm-up ran at and the niceness of the thread serving this task."""
    import threading
    return WARM_NICENESS, os.getpriority(os.PRIO_PROCESS, threading.get_native_id())
