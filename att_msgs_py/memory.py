"""Giving memory back to the system, and reading what a process holds (no ROS).

A node that receives a large message (a 10 MB state, a request of 100,000 zones) allocates its
deserialised copy before any check can look at it; freed, that memory stays in the C allocator
unless it is handed back. Two glibc settings decide it (``mallopt(3)``, ``malloc_trim(3)``):

* :func:`configure` fixes ``M_MMAP_THRESHOLD`` at :data:`MMAP_THRESHOLD`. glibc otherwise raises
  the threshold to the size of the largest block freed (up to 32 MB), after which blocks of that
  size come from the heap and stay there when freed; fixed, every block above it is its own
  mapping, unmapped when freed.
* :func:`trim` (``malloc_trim(0)``) hands the free pages of every arena back: the nodes call it after
  a refused oversized message and the planner after each request; a planner worker after each task.

Without glibc (another C library, another OS) both do nothing and say so (False).

Python's own small-object allocator keeps 1 MiB arenas while any object in them lives: after a
message of 100,000 nested elements (a 10 MB inline plan, a request of 100,000 zones) is freed, the
few objects allocated meanwhile that survive pin an arena each, and a node grows by about 1 MB per
such message for good (a controller refusing 10 MB inline plans: +54 MB after 40, trimmed or not).
With ``PYTHONMALLOC=malloc`` every object comes from the C allocator, whose free pages the trim
hands back at page granularity (the same 40 plans: +2.3 MB). The launch helpers start every node
with it (:data:`C_ALLOCATOR`); a node started otherwise runs itself again with it once
(:func:`reexec_with_c_allocator`, from its ``main``).

The middleware keeps memory too: rmw_fastrtps gives every reader and writer a pool of payloads
that each grow to the largest message they held and are never shrunk, so a few 10 MB messages
leave tens of MB per topic for good (+40 MB in an estimator that refused 60 of them on three
topics). :func:`middleware_env` points Fast DDS at :data:`PROFILES` (payloads allocated per sample
and freed when released; rmw_fastrtps's other defaults kept, QoS still from the code): the same
refusals then leave the estimator at its start-up size.
:func:`rss_bytes` reads a process's resident set (``Rss`` of ``/proc/PID/smaps_rollup``).
"""
from __future__ import annotations

import ctypes
import ctypes.util
import os
import sys
from pathlib import Path

MMAP_THRESHOLD = 128 * 1024     # bytes: glibc's initial M_MMAP_THRESHOLD, kept from start to end
M_MMAP_THRESHOLD = -3           # mallopt parameter number (malloc.h)
C_ALLOCATOR = {"PYTHONMALLOC": "malloc"}      # the environment of a node process (module docstring)
PROFILES = Path(__file__).with_name("fastdds_profiles.xml")
FASTDDS_SETTINGS = ("RMW_FASTRTPS_USE_QOS_FROM_XML", "FASTDDS_DEFAULT_PROFILES_FILE", "FASTRTPS_DEFAULT_PROFILES_FILE")

_libc = None


def _glibc():
    """The C library when it has ``malloc_trim`` and ``mallopt`` (glibc), else None."""
    global _libc
    if _libc is None:
        try:
            lib = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
            _libc = lib if hasattr(lib, "malloc_trim") and hasattr(lib, "mallopt") else False
        except OSError:
            _libc = False
    return _libc or None


def configure() -> bool:
    """Fix the allocator's mmap threshold at :data:`MMAP_THRESHOLD` (module docstring); False
    when the C library has no ``mallopt``."""
    lib = _glibc()
    return bool(lib is not None and lib.mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1)


def trim() -> bool:
    """Hand the allocator's free pages back to the system; False when nothing could be (no glibc,
    or nothing to release)."""
    lib = _glibc()
    return bool(lib is not None and lib.malloc_trim(0) == 1)


def middleware_env(env=None) -> bool:
    """Set ``env`` (default: this process's environment, before ``rclpy.init``) to load
    :data:`PROFILES` with rmw_fastrtps (``RMW_FASTRTPS_USE_QOS_FROM_XML=1``, its memory policy then
    being the file's); False, changing nothing, under another middleware or when the user set
    any Fast DDS profile setting of their own."""
    env = os.environ if env is None else env
    if env.get("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp") not in ("", "rmw_fastrtps_cpp", "rmw_fastrtps_dynamic_cpp"):
        return False
    if any(env.get(name) for name in FASTDDS_SETTINGS):
        return False
    env["RMW_FASTRTPS_USE_QOS_FROM_XML"] = "1"
    env["FASTDDS_DEFAULT_PROFILES_FILE"] = str(PROFILES)
    return True


def reexec_with_c_allocator() -> None:
    """Run this program again (same pid, arguments and environment) with :data:`C_ALLOCATOR`,
    unless ``PYTHONMALLOC`` is already set (by the launch helpers, or by the user: kept) or the C
    library is not glibc. Call it first thing in a node's ``main``."""
    if os.environ.get("PYTHONMALLOC") or _glibc() is None or not getattr(sys, "orig_argv", None):
        return
    os.environ.update(C_ALLOCATOR)
    sys.stdout.flush()
    sys.stderr.flush()
    os.execv(sys.executable, [sys.executable, *sys.orig_argv[1:]])


def rss_bytes(pid: int | str = "self") -> int | None:
    """The resident set of process ``pid`` in bytes, None when it has none to read (exited, or no
    ``/proc``). Read from ``/proc/PID/smaps_rollup``, which counts the mapped pages as they are:
    ``VmRSS`` of ``/proc/PID/status`` is the kernel's cached counter, which can lag by tens of MB in a
    process of many threads (a touched 64 MB array once left it unchanged)."""
    try:
        with open(f"/proc/{pid}/smaps_rollup") as fh:
            for line in fh:
                if line.startswith("Rss:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None
