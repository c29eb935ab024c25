"""Memory given back: the resident set read from /proc follows an allocation touched and freed, and
the allocator settings hand freed blocks back to the system."""
from __future__ import annotations

import mmap
import os
import subprocess
import sys

import pytest

from att_msgs_py import memory

MB = 1024 * 1024
glibc = pytest.mark.skipif(memory._glibc() is None, reason="malloc_trim and mallopt are glibc's")


def test_rss_follows_a_touched_allocation_and_reads_another_process():
    """A fresh anonymous mapping, every page written: 64 MB more resident. (Not an array: its
    allocation may reuse heap pages a long test process freed but kept, resident already.)"""
    before = memory.rss_bytes()
    block = mmap.mmap(-1, 64 * MB)
    block.write(b"x" * (64 * MB))
    during = memory.rss_bytes()
    assert during - before > 60 * MB
    block.close()
    assert memory.rss_bytes(os.getpid()) == pytest.approx(memory.rss_bytes(), abs=4 * MB)
    assert memory.rss_bytes(2**22 + 12345) is None       # no such process


CHILD = """
import sys
from att_msgs_py import memory
if sys.argv[1] == "configured":
    memory.configure()
base = memory.rss_bytes()
for size in (30, 20, 10, 5):                # freed large blocks raise glibc's threshold to their size
    blocks = [bytearray(size * 2**20) for _ in range(4)]
    for b in blocks:
        b[::4096] = b"x" * len(b[::4096])
    del blocks
    small = [bytearray(256 * 1024) for _ in range(200)]       # then come from the heap
    for b in small:
        b[::4096] = b"x" * len(b[::4096])
    del small
kept = memory.rss_bytes() - base
memory.trim()
print(kept, memory.rss_bytes() - base)
"""


@glibc
def test_freed_blocks_go_back_with_a_fixed_threshold_or_a_trim():
    # glibc's defaults only: no allocator setting the test run may have put in the environment
    env = {k: os.environ[k] for k in ("PATH", "HOME", "LANG") if k in os.environ}

    def run(mode):
        out = subprocess.run([sys.executable, "-c", CHILD, mode], capture_output=True, text=True, check=True,
                             env=env)
        return [int(v) / MB for v in out.stdout.split()]

    kept_default, after_trim = run("default")
    kept_configured, _ = run("configured")
    assert kept_default > 30, (f"glibc's defaults kept {kept_default:.2f} MB (environment of the run: "
                               f"{sorted(os.environ)})")          # 50 MB of 256 KiB blocks stayed in the heap
    assert after_trim < 10                       # malloc_trim gave them back
    assert kept_configured < 10                  # a fixed threshold never kept them


def test_the_middleware_is_pointed_at_the_suite_profiles_unless_the_user_chose():
    env = {}
    assert memory.middleware_env(env)
    assert env == {"RMW_FASTRTPS_USE_QOS_FROM_XML": "1", "FASTDDS_DEFAULT_PROFILES_FILE": str(memory.PROFILES)}
    text = memory.PROFILES.read_text()
    assert text.count("<historyMemoryPolicy>DYNAMIC</historyMemoryPolicy>") == 2
    # synchronous, as rmw_fastrtps publishes without a profile: an asynchronous depth-1 writer (an action
    # server's goal status) refuses a second write while the first is queued
    assert "<kind>SYNCHRONOUS</kind>" in text and "ASYNCHRONOUS" not in text
    mine = {"FASTDDS_DEFAULT_PROFILES_FILE": "/my/profiles.xml"}
    assert not memory.middleware_env(mine) and mine == {"FASTDDS_DEFAULT_PROFILES_FILE": "/my/profiles.xml"}
    other = {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}
    assert not memory.middleware_env(other) and len(other) == 1


REEXEC = """
import os, sys
from att_msgs_py import memory
print(os.getpid(), os.environ.get("PYTHONMALLOC", ""), sys.argv[1:], flush=True)
memory.reexec_with_c_allocator()
"""


@glibc
def test_a_node_runs_itself_again_with_the_c_allocator_once_keeping_pid_and_arguments(tmp_path):
    script = tmp_path / "node.py"
    script.write_text(REEXEC)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONMALLOC"}
    out = subprocess.run([sys.executable, str(script), "--ros-args", "-p", "x:=1"], env=env, capture_output=True,
                         text=True, check=True, timeout=60).stdout.splitlines()
    first, second = (line.split(" ", 2) for line in out)
    assert first[0] == second[0] and (first[1], second[1]) == ("", "malloc")
    assert first[2] == second[2] == "['--ros-args', '-p', 'x:=1']"
    kept = subprocess.run([sys.executable, str(script)], env={**env, "PYTHONMALLOC": "pymalloc"},
                          capture_output=True, text=True, check=True, timeout=60).stdout.splitlines()
    assert len(kept) == 1 and kept[0].split(" ")[1] == "pymalloc"      # the user's choice: no re-run


def test_the_launch_environment_starts_nodes_with_the_c_allocator():
    from att_planner.tools.launch import isolated_env

    assert isolated_env(base={})["PYTHONMALLOC"] == "malloc"
    assert isolated_env(base={"PYTHONMALLOC": "debug"})["PYTHONMALLOC"] == "debug"
