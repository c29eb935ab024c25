"""run_node: SIGINT/SIGTERM end a node cleanly wherever the signal lands.

rclpy's handler shuts the context down from its own thread, while Python raises
``KeyboardInterrupt`` in the main thread only later; when the kernel hands the signal to a thread
other than the main one (a DDS thread, say), a loop that publishes sees ``publish`` fail on the dead
context first (this made the simulator exit 1 on a CI run). The cases below signal a loop that
publishes until ``publish`` fails and an idle spin, from another thread of the node's process and from outside, at
different moments, and require exit status 0 with the node's ``close()`` run to its end.
(The other half of the race, an executor that waits again after rclpy's wake-up and before its
shutdown, hung the planner; the integration tests' exit-status checks catch that one.)
"""
from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
import time

import pytest

from att_planner.tools.launch import isolated_env

pytestmark = pytest.mark.ros

NODE_SCRIPT = textwrap.dedent("""
    import os, sys, threading, time
    import rclpy
    from rclpy.node import Node
    from std_msgs.msg import String
    from att_msgs_py.node_runner import run_node, spin_until_shutdown

    loop_kind, signum, delay = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])

    class Busy(Node):
        def __init__(self):
            super().__init__("busy")
            self.pub = self.create_publisher(String, "busy", 10)

        def close(self):
            time.sleep(0.3)                 # wait-ok: a close that takes time, which a signal must not cut short
            print("closed", flush=True)

    def loop(node, executor):
        print("running", flush=True)
        if signum:                          # delivered to this helper thread, not the main one
            threading.Timer(delay, os.kill, (os.getpid(), signum)).start()
        if loop_kind == "idle":             # what every node's default loop does
            spin_until_shutdown(executor)
            return
        while True:                         # publishes until publish fails on the dead context
            node.pub.publish(String(data="x"))

    run_node(Busy, loop=loop)
""")


@pytest.mark.parametrize("loop,signum,delay,from_thread", [
    ("busy", signal.SIGINT, 0.0, True), ("busy", signal.SIGINT, 0.05, True),
    ("busy", signal.SIGINT, 0.2, True), ("busy", signal.SIGTERM, 0.1, True),
    ("idle", signal.SIGINT, 0.1, True), ("busy", signal.SIGINT, 0.1, False),
    ("idle", signal.SIGTERM, 0.0, False)])
def test_signal_stops_node_cleanly(loop, signum, delay, from_thread):
    args = [loop, str(int(signum) if from_thread else 0), str(delay)]
    proc = subprocess.Popen([sys.executable, "-c", NODE_SCRIPT, *args], env=isolated_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        assert proc.stdout.readline().strip() == "running"
        if not from_thread:
            time.sleep(delay)               # wait-ok: the signal's moment in the node's life is the parameter
            proc.send_signal(signum)
        out, _ = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, out
    assert out.strip().endswith("closed"), out


def test_refusals_are_logged_once_a_second_per_kind_with_their_count():
    from att_msgs_py.errors import ErrorCode, RequestError
    from att_msgs_py.node_runner import RefusalLog

    class Logger:
        lines: list = []

        def warning(self, line):
            self.lines.append(line)

    log = RefusalLog(Logger(), period=3600.0)
    for _ in range(1000):                                 # a flood of one kind...
        log("state", RequestError(ErrorCode.STATE_TIME_JUMP, "stamp jumps"))
    log("published plan", RequestError(ErrorCode.PLAN_NOT_AUTHENTIC, "not signed " + "x" * 1000))
    log("state", RequestError(ErrorCode.STATE_TIME_JUMP, "stamp jumps"))
    # ...does not hide another kind
    assert Logger.lines[0] == "state refused (1 so far) [311 STATE_TIME_JUMP]: stamp jumps"
    assert len(Logger.lines) == 2 and Logger.lines[1].startswith("published plan refused (1 so far) [306 ")
    assert len(Logger.lines[1]) <= 400 and log.counts == {"state": 1001, "published plan": 1}


FREEZE_SCRIPT = textwrap.dedent("""
    import gc
    import rclpy
    from rclpy.node import Node
    from att_msgs_py.node_runner import run_node

    held = []

    class Holder(Node):
        def __init__(self):
            super().__init__("holder")
            held.append([{"start-up": i} for i in range(1000)])     # what a node keeps from its start-up

    def loop(node, executor):
        young = [[] for _ in range(10)]                              # made after the start-up
        tracked = {id(o) for o in gc.get_objects()}
        frozen = gc.get_freeze_count()
        print(frozen >= 1000, id(held[0]) in tracked, id(held[0][0]) in tracked, id(young[0]) in tracked,
              flush=True)

    run_node(Holder, loop=loop)
""")


def test_a_node_start_up_heap_is_out_of_the_collector_reach():
    """What the node built before it spins is frozen (gc.get_objects, which lists what collections
    walk, no longer holds it); what it makes later is still collected."""
    out = subprocess.run([sys.executable, "-c", FREEZE_SCRIPT], env=isolated_env(), capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "False", "False", "True"], out.stdout
