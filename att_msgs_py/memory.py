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
:func:`rss_bytes` reads a process's resident set (``VmRSS`` of ``/proc/PID/status``).
"""
from __future__ import annotations

import ctypes
import ctypes.util

MMAP_THRESHOLD = 128 * 1024     # bytes: glibc's initial M_MMAP_THRESHOLD, kept from start to end
M_MMAP_THRESHOLD = -3           # mallopt parameter number (malloc.h)

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


def rss_bytes(pid: int | str = "self") -> int | None:
    """The resident set of process ``pid`` in bytes (``VmRSS``), None when it has none to read
    (exited, or no ``/proc``)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None
