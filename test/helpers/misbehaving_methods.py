"""Planning methods that misbehave on purpose, for the planner's fault tests."""
import os
import time


def plan_ignores_deadline(problem, **options):
    time.sleep(3600)      # wait-ok: a method that hangs, on purpose


def plan_crashes(problem, **options):
    os._exit(11)          # like a segfault in a native solver: the process just dies


def plan_raises(problem, **options):
    raise RuntimeError("solver exploded")
