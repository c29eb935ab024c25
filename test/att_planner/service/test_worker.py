"""The planner's solver workers (issue 18): warm before they serve, kept when they overrun and
then finish, killed when they hang."""
import math
import time

import pytest

from att_planner.service import worker
from att_planner.service.warm import warm, warm_requests
from att_planner.verification import TOLERANCES
from helpers import worker_tasks


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


def test_a_worker_that_overruns_and_then_finishes_is_kept_warm():
    """Its slot is held while it finishes (no more workers compute than the slots), then freed."""
    assert worker.call_isolated(worker_tasks.sleep_then_pid, (1.5,), {}, 0.1, on_death=on_death) is None
    assert [worker._SLOTS.acquire(blocking=False) for _ in range(2)] == [True, False]     # one held by it
    worker._SLOTS.release()
    deadline = time.monotonic() + 20.0
    while not worker.idle_workers() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert worker.idle_workers() == 1                  # back from the reaper, not killed
    time.sleep(0.1)
    assert [worker._SLOTS.acquire(blocking=False) for _ in range(2)] == [True, True]      # its slot freed
    worker._SLOTS.release()
    worker._SLOTS.release()
    (process, _), = worker._IDLE
    assert worker.call_isolated(worker_tasks.sleep_then_pid, (0.0,), {}, 10.0, on_death=on_death) == process.pid


def test_a_worker_that_hangs_is_killed_after_the_reaping_time(monkeypatch):
    monkeypatch.setattr(worker, "REAP_SECONDS", 1.0)
    procs = []
    spawn = worker._spawn
    monkeypatch.setattr(worker, "_spawn", lambda: procs.append(spawn()) or procs[-1])
    assert worker.call_isolated(worker_tasks.sleep_then_pid, (3600.0,), {}, 0.1, on_death=on_death) is None
    (process, _), = procs
    process.join(10.0)
    assert not process.is_alive() and worker.idle_workers() == 0


def test_the_planner_warm_up_builds_the_nlps_before_the_first_request():
    """A worker warmed on swift_demo's demo maneuver (the default method through the service's
    pipeline) holds that maneuver's NLPs before it serves a request."""
    requests = warm_requests(["swift_demo"], frame_id="eci", default_method="smooth_collocation")
    assert [r.spacecraft for r in requests] == ["swift_demo"] and len(requests[0].problem.cones) == 3
    worker.set_warm_up(warm, (requests, TOLERANCES, math.radians(2.0)))
    worker.start_pool(1)
    assert worker.call_isolated(worker_tasks.built_nlps, (), {}, 10.0, on_death=on_death) >= 1
