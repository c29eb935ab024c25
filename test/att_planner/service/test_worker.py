"""The planner's solver workers: warm before they serve; one that overruns is killed and
replaced by a warmed one."""
import math
import time

import pytest

from att_planner.service import worker
from att_planner.service.warm import warm, warm_requests
from att_planner.verification import TOLERANCES
from helpers import worker_tasks
from helpers.waiting import wait_until


def on_death(message):
    return message


@pytest.fixture(autouse=True)
def own_pool(monkeypatch):
    """Each test starts with no idle worker and its own warm-up; what it leaves is stopped."""
    worker.warm_up()
    monkeypatch.setattr(worker, "_IDLE", [])
    monkeypatch.setattr(worker, "_WARM_UP", None)
    monkeypatch.setattr(worker, "_POOL_SIZE", 0)
    monkeypatch.setattr(worker, "_SLOTS", worker.threading.BoundedSemaphore(2))
    yield
    for process, conn in worker._IDLE:
        worker._retire(process, conn)


def test_a_pool_worker_runs_the_warm_up_before_its_first_request():
    worker.set_warm_up(worker_tasks.warm_marker)
    worker.start_pool(1)
    assert worker.idle_workers() == 1
    pid, warmed = worker.call_isolated(worker_tasks.pid_and_warmth, (), {}, 10.0, on_death=on_death)
    assert warmed
    assert worker.call_isolated(worker_tasks.pid_and_warmth, (), {}, 10.0, on_death=on_death) == (pid, True)


def test_a_worker_that_overruns_is_killed_and_replaced_by_a_warmed_one():
    worker.set_warm_up(worker_tasks.warm_marker)
    worker.start_pool(1)
    (pooled, _), = worker._IDLE
    assert worker.call_isolated(worker_tasks.sleep_then_pid, (3600.0,), {}, 0.1, on_death=on_death) is None
    pooled.join(10.0)
    assert not pooled.is_alive()
    wait_until(worker.idle_workers, 60.0, "a warmed worker in place of the killed one")
    pid, warmed = worker.call_isolated(worker_tasks.pid_and_warmth, (), {}, 10.0, on_death=on_death)
    assert warmed and pid != pooled.pid


@pytest.mark.skipif(worker.sys.platform != "linux", reason="niceness is per thread on Linux only")
def test_a_replacement_warms_at_a_low_priority_and_serves_at_the_node_priority():
    """The pool's first workers warm at the node's priority; one warmed in place of a killed one
    warms BACKGROUND_NICENESS lower, in its warm-up thread only, and serves at the node's again."""
    base = worker.os.getpriority(worker.os.PRIO_PROCESS, 0)
    worker.set_warm_up(worker_tasks.warm_recording_niceness)
    worker.start_pool(1)
    assert worker.call_isolated(worker_tasks.niceness, (), {}, 10.0, on_death=on_death) == (base, base)
    assert worker.call_isolated(worker_tasks.sleep_then_pid, (3600.0,), {}, 0.1, on_death=on_death) is None
    wait_until(worker.idle_workers, 60.0, "a warmed worker in place of the killed one")
    expected = min(19, base + worker.BACKGROUND_NICENESS)
    assert worker.call_isolated(worker_tasks.niceness, (), {}, 10.0, on_death=on_death) == (expected, base)


def test_a_low_priority_call_returns_its_result_and_raises_its_error():
    assert worker.at_low_priority(divmod, (7, 2)) == (3, 1)
    with pytest.raises(ZeroDivisionError):
        worker.at_low_priority(divmod, (7, 0))
    os = worker.os
    before = os.getpriority(os.PRIO_PROCESS, 0)                 # on Linux: this thread's
    ran_at = worker.at_low_priority(os.getpriority, (os.PRIO_PROCESS, 0))
    if worker.sys.platform == "linux":
        assert ran_at == min(19, before + worker.BACKGROUND_NICENESS)
    assert os.getpriority(os.PRIO_PROCESS, 0) == before         # the caller's thread keeps its niceness


def test_a_worker_hands_back_what_a_task_freed():
    pid, before = worker.call_isolated(worker_tasks.allocate_then_rss, (0, False), {}, 30.0, on_death=on_death)
    same, _ = worker.call_isolated(worker_tasks.allocate_then_rss, (200, False), {}, 30.0, on_death=on_death)
    rss = worker.memory.rss_bytes(pid)
    assert same == pid and rss - before < 30 * 2**20        # 200 MB touched and freed: not kept


def test_a_worker_above_its_resident_bound_after_a_task_is_recycled(monkeypatch):
    first, rss = worker.call_isolated(worker_tasks.allocate_then_rss, (0, True), {}, 30.0, on_death=on_death)
    monkeypatch.setattr(worker, "MAX_WORKER_RSS", rss + 100 * 2**20)
    assert worker.call_isolated(worker_tasks.allocate_then_rss, (10, True), {}, 30.0, on_death=on_death)[0] == first
    assert worker.idle_workers() == 1                       # below the bound: kept
    held, rss = worker.call_isolated(worker_tasks.allocate_then_rss, (200, True), {}, 30.0, on_death=on_death)
    assert held == first and rss > worker.MAX_WORKER_RSS and worker.idle_workers() == 0   # above: retired
    fresh, _ = worker.call_isolated(worker_tasks.allocate_then_rss, (0, False), {}, 30.0, on_death=on_death)
    assert fresh != first


def test_a_worker_whose_warm_up_hangs_is_given_up(monkeypatch):
    monkeypatch.setattr(worker, "WARM_UP_TIMEOUT", 0.5)
    worker.set_warm_up(worker_tasks.sleep_then_pid, (3600.0,))
    start = time.monotonic()
    worker.start_pool(1)
    assert time.monotonic() - start < 10.0 and worker.idle_workers() == 0


def test_the_planner_warm_up_builds_the_nlps_before_the_first_request():
    """A worker warmed on swift_demo's demo maneuver (the default method through the service's
    pipeline) holds that maneuver's NLPs before it serves a request."""
    requests = warm_requests(["swift_demo"], frame_id="eci", default_method="smooth_collocation")
    assert [r.spacecraft for r in requests] == ["swift_demo"] and len(requests[0].problem.cones) == 3
    worker.set_warm_up(warm, (requests, TOLERANCES, math.radians(2.0)))
    worker.start_pool(1)
    assert worker.call_isolated(worker_tasks.built_nlps, (), {}, 10.0, on_death=on_death) >= 1
