"""CasADi functions compiled to machine code once, into a cache directory (no network, no build step).

:func:`compiled` generates the C code of a CasADi ``Function`` (``casadi.CodeGenerator``), compiles it
with the system C compiler into a shared library named by the SHA-256 of that code (and of CasADi's
version and the compiler flags) under :func:`cache_dir`, and loads it with ``casadi.external``. A
second call, in this process or any later one, finds the library and only loads it. The library is
written to a temporary name and renamed into place, so processes compiling the same code at once
do not see half a file. When no compiler works the function is returned as it is (CasADi's virtual
machine: the same numbers, slower); nothing ever fails for want of a compiler.
"""
from __future__ import annotations

import functools
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

CFLAGS = ("-O2", "-fPIC", "-shared")


def cache_dir() -> Path:
    """``$ATT_CACHE_DIR``, else ``<venv>/share/att_suite/cache`` when writable, else a directory in the
    system's temporary directory."""
    configured = os.environ.get("ATT_CACHE_DIR")
    candidates = [Path(configured)] if configured else []
    candidates += [Path(sys.prefix) / "share" / "att_suite" / "cache", Path(tempfile.gettempdir()) / "att_suite_cache"]
    for path in candidates:
        try:
            path.mkdir(parents=True, exist_ok=True)
        except OSError:
            continue
        if os.access(path, os.W_OK):
            return path
    raise OSError(f"no writable cache directory among {', '.join(map(str, candidates))}")


@functools.cache
def _compiler() -> str | None:
    return os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")


def compiled(function):
    """``function`` (a ``casadi.Function``) compiled to a shared library and loaded, or itself when
    no C compiler is available or compiling fails (module docstring)."""
    import casadi as ca

    cc = _compiler()
    if cc is None:
        return function
    name = function.name()
    try:
        directory = cache_dir()
        with tempfile.TemporaryDirectory(dir=directory) as work:
            generator = ca.CodeGenerator(f"{name}.c", {"with_header": False})
            generator.add(function)
            generator.generate(work + os.sep)
            source = Path(work, f"{name}.c").read_bytes()
            key = hashlib.sha256(source + ca.__version__.encode() + " ".join(CFLAGS).encode()).hexdigest()[:20]
            library = directory / f"{name}_{key}.so"
            if not library.exists():
                partial = Path(work, library.name)
                subprocess.run([cc, *CFLAGS, str(Path(work, f"{name}.c")), "-o", str(partial)], check=True,
                               capture_output=True, timeout=600)
                os.replace(partial, library)
        return ca.external(name, str(library))
    except (OSError, subprocess.SubprocessError, RuntimeError):
        return function
