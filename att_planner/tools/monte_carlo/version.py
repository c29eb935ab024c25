"""The suite version a campaign's client and its Dask workers must share: the installed
distribution's version and a digest of the suite's Python sources — the code a worker runs, whether
it was installed from a wheel, an sdist or a checkout (docs/decisions/dask-cluster.md)."""
from __future__ import annotations

import hashlib
import importlib
from functools import lru_cache
from importlib import metadata
from pathlib import Path

DISTRIBUTION = "att_suite"                             # setup.py's name
PACKAGES = ("att_msgs_py", "att_sim", "att_planner")   # whose sources the digest covers
DIGEST_CHARS = 12


def sources_digest() -> str:
    """The first :data:`DIGEST_CHARS` hex digits of the SHA-256 of every ``.py`` file of
    :data:`PACKAGES` (its path inside the package and its bytes, in path order), as imported here."""
    digest = hashlib.sha256()
    for name in PACKAGES:
        root = Path(importlib.import_module(name).__file__).parent
        for path in sorted(p for p in root.rglob("*.py") if "__pycache__" not in p.parts):
            digest.update(f"{name}/{path.relative_to(root).as_posix()}\0".encode())
            digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()[:DIGEST_CHARS]


@lru_cache(maxsize=1)
def suite_version() -> str:
    """``VERSION+DIGEST``: the distribution's version (``unknown`` when it is not installed, only on
    the path) and :func:`sources_digest`; computed once a process."""
    try:
        release = metadata.version(DISTRIBUTION)
    except metadata.PackageNotFoundError:
        release = "unknown"
    return f"{release}+{sources_digest()}"
