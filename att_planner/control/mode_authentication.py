"""Authentication of mode requests (no ROS): an Ed25519 signature and a rising, clock-bounded sequence.

With a public key set, a mode request is accepted only when its signed bytes verify against the
key (:func:`att_msgs_py.signing.check`) and its sequence number is above the last one accepted
from its signer, so a recorded request cannot be replayed. The operator's client numbers its
requests with its wall clock in nanoseconds, so a sequence more than ``max_ahead`` seconds ahead
of the controller's wall clock is refused: a single request (sequence 2^64 - 1) cannot exhaust the
counter and lock the operator out. With a ``path``, the last accepted sequence of each signer is
kept in a small JSON file, replaced atomically after each acceptance, so the replay guard survives
a restart. A missing file starts an empty record; a damaged one cannot say what was accepted, so
the guard starts at the controller's clock (every request signed before the start is refused as a
possible replay) and :attr:`warning` says so. Without a key every request is accepted.
"""
from __future__ import annotations

import json
import os
import tempfile
import time
from pathlib import Path

from att_msgs_py import signing
from att_msgs_py.errors import ErrorCode, RequestError

MAX_AHEAD = 300.0        # s a sequence (wall-clock ns) may lead the controller's wall clock
STATE_DIR_ENV = "ATT_STATE_DIR"
SEQUENCE_FILE = "mode_sequences.json"
_MAX_FILE_BYTES = 1 << 16


def default_sequence_path() -> Path:
    """``$ATT_STATE_DIR/controller/mode_sequences.json`` (default state directory
    ``$XDG_STATE_HOME/att_suite``, else ``~/.local/state/att_suite``)."""
    root = os.environ.get(STATE_DIR_ENV)
    if not root:
        xdg = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
        root = str(Path(xdg) / "att_suite")
    return Path(root) / "controller" / SEQUENCE_FILE


def _read(path: Path) -> dict[str, int]:
    """The record in ``path`` ({signer: sequence}); ValueError when it is not one."""
    with open(path, "rb") as f:
        raw = f.read(_MAX_FILE_BYTES + 1)
    if len(raw) > _MAX_FILE_BYTES:
        raise ValueError(f"larger than {_MAX_FILE_BYTES} bytes")
    record = json.loads(raw.decode("utf-8"))
    if not isinstance(record, dict) or not all(
            isinstance(k, str) and type(v) is int and 0 <= v < 1 << 64 for k, v in record.items()):
        raise ValueError("not an object of signer: sequence (an integer in [0, 2^64))")
    return record


class ModeAuthentication:
    def __init__(self, key=None, path: str | Path | None = None, max_ahead: float = MAX_AHEAD,
                 clock_ns=time.time_ns):
        self.key = key                 # Ed25519 public key mode requests must verify against (None: no check)
        self.path = None if path is None else Path(path)   # file of the last accepted sequences (None: memory)
        self.max_ahead = max_ahead
        self.clock_ns = clock_ns       # wall clock (ns) the sequences are bounded by
        self.accepted: dict[str, int] = {}   # signer -> sequence of its last authenticated request
        self.floor = 0                 # every signer's sequence must be above this (a damaged record)
        self.warning: str | None = None
        if self.path is not None:
            self._load()

    def _load(self) -> None:
        try:
            self.accepted = _read(self.path)
        except FileNotFoundError:
            return
        except (OSError, ValueError, UnicodeDecodeError) as e:
            self.floor = self.clock_ns()
            self.warning = (f"mode sequence record {self.path} is unreadable ({type(e).__name__}: {e}); "
                            f"refusing every mode request signed before now (sequence <= {self.floor}) "
                            "as a possible replay")

    @property
    def sequence(self) -> int:
        """The sequence of the last authenticated mode request (of any signer)."""
        return max([self.floor, *self.accepted.values()])

    def _save(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".mode_sequences.", dir=self.path.parent)
        try:
            with os.fdopen(fd, "w") as f:
                json.dump(self.accepted, f)
                f.flush()
                os.fsync(f.fileno())
            os.replace(tmp, self.path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    def check(self, payload: bytes, signature: bytes, signer: str, sequence: int) -> RequestError | None:
        """Why a mode request (signed bytes ``payload``) is not authentic; None (and its
        ``sequence`` remembered, in the file too) when it is."""
        if self.key is None:
            return None
        why = signing.check(payload, signature, signer, self.key, "the mode request")
        last = max(self.floor, self.accepted.get(signer, 0))
        now = self.clock_ns()
        if why is None and sequence <= last:
            why = f"sequence {sequence} is not above the last accepted {last} (a replayed request)"
        elif why is None and sequence > now + self.max_ahead * 1e9:
            why = (f"sequence {sequence} is {(sequence - now) * 1e-9:.3g} s ahead of the controller's clock "
                   f"(at most {self.max_ahead:g} s: sequences are the signer's wall clock in ns)")
        if why is not None:
            return RequestError(ErrorCode.MODE_NOT_AUTHENTIC, why)
        previous = dict(self.accepted)
        self.accepted[signer] = sequence
        if self.path is not None:
            try:
                self._save()
            except OSError as e:
                self.accepted = previous
                return RequestError(ErrorCode.MODE_NOT_AUTHENTIC,
                                    f"sequence {sequence} could not be recorded in {self.path} ({e}); "
                                    "refused so it cannot be replayed after a restart")
        return None
