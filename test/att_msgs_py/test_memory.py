"""Memory given back: the resident set read from /proc follows an allocation touched and freed, and
the allocator settings hand freed blocks back to the system."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from att_msgs_py import memory

MB = 1024 * 1024
glibc = pytest.mark.skipif(memory._glibc() is None, reason="malloc_trim and mallopt are glibc's")


def test_rss_follows_a_touched_allocation_and_reads_another_process():
    before = memory.rss_bytes()
    block = np.ones(64 * MB // 8)                 # touched: resident
    during = memory.rss_bytes()
    assert during - before > 60 * MB
    del block
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
    def run(mode):
        out = subprocess.run([sys.executable, "-c", CHILD, mode], capture_output=True, text=True, check=True)
        return [int(v) / MB for v in out.stdout.split()]

    kept_default, after_trim = run("default")
    kept_configured, _ = run("configured")
    assert kept_default > 30                     # 50 MB of 256 KiB blocks stayed in the heap
    assert after_trim < 10                       # malloc_trim gave them back
    assert kept_configured < 10                  # a fixed threshold never kept them
