"""Independent solves on two cores (att_planner.methods.lanes): the answers are the sequential ones,
whoever computed them; the odd jobs go to a forked child only where forking is safe; a child that
fails costs time, never an answer."""
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from att_planner.methods import lanes
from att_planner.methods.time_optimal.planner import plan_time_optimal
from att_planner.reference.celani_bruni import benchmark_problem

CHILD_CHECK = """
import os
from att_planner.methods import lanes
parent = os.getpid()
out = lanes.map_in_lanes(lambda j: (j * j, os.getpid()), list(range(5)))
assert [v for v, _ in out] == [0, 1, 4, 9, 16], out
assert {pid == parent for _, pid in out[0::2]} == {True} and {pid == parent for _, pid in out[1::2]} == {False}, out

def fails_in_the_child(j):
    if os.getpid() != parent:
        raise RuntimeError("child fault")
    return j + 1
assert lanes.map_in_lanes(fails_in_the_child, [1, 2, 3, 4]) == [2, 3, 4, 5]
assert lanes.map_in_lanes(lambda j: os._exit(3) if os.getpid() != parent else j, [1, 2]) == [1, 2]
print("ok")
"""


def test_a_single_threaded_process_sends_the_odd_jobs_to_a_child_and_survives_its_faults():
    if (os.cpu_count() or 1) < 2:
        pytest.skip("one core: the jobs are never forked")
    out = subprocess.run([sys.executable, "-c", CHILD_CHECK], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_with_another_thread_alive_every_job_runs_here():
    stop = threading.Event()
    helper = threading.Thread(target=stop.wait)
    helper.start()
    try:
        assert not lanes.can_fork()
        pids = lanes.map_in_lanes(lambda j: os.getpid(), [1, 2, 3])
        assert pids == [os.getpid()] * 3
    finally:
        stop.set()
        helper.join()


def test_the_time_optimal_starts_on_two_cores_give_the_sequential_plan():
    problem = benchmark_problem("swift")
    started = time.monotonic()
    parallel = plan_time_optimal(problem, parallel_starts=True)
    sequential = plan_time_optimal(problem, parallel_starts=False)
    assert time.monotonic() - started < 30.0
    assert parallel.success and sequential.success
    assert parallel.stats["starts"] == [dict(s, seconds=p["seconds"]) for s, p in
                                        zip(sequential.stats["starts"], parallel.stats["starts"], strict=True)]
    np.testing.assert_array_equal(parallel.t, sequential.t)
    np.testing.assert_array_equal(parallel.torque, sequential.torque)
    assert parallel.nit == sequential.nit
