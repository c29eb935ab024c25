"""Planning methods that misbehave on purpose, for the planner's fault tests."""
import os
import time


def plan_ignores_deadline(problem, **options):
    time.sleep(3600)


def plan_crashes(problem, **options):
    os._exit(11)          # like a segfault in a native solver: the process just dies


def plan_raises(problem, **options):
    raise RuntimeError("solver exploded")


_CALLS = 0


def count_after(seconds):
    """This worker's pid and how many tasks it has run, after ``seconds``."""
    global _CALLS
    time.sleep(seconds)
    _CALLS += 1
    return os.getpid(), _CALLS
