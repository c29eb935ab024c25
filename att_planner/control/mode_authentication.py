"""Authentication of mode requests (no ROS): an Ed25519 signature and a rising sequence number.

With a public key set, a mode request is accepted only when its signed bytes verify against the
key (:func:`att_msgs_py.signing.check`) and its sequence number is above the last accepted one, so
a recorded request cannot be replayed. Without a key every request is accepted.
"""
from __future__ import annotations

from att_msgs_py import signing
from att_msgs_py.errors import ErrorCode, RequestError


class ModeAuthentication:
    def __init__(self, key=None):
        self.key = key                 # Ed25519 public key mode requests must verify against (None: no check)
        self.sequence = 0              # sequence of the last authenticated mode request

    def check(self, payload: bytes, signature: bytes, signer: str, sequence: int) -> RequestError | None:
        """Why a mode request (signed bytes ``payload``) is not authentic; None (and its
        ``sequence`` remembered) when it is."""
        if self.key is None:
            return None
        why = signing.check(payload, signature, signer, self.key, "the mode request")
        if why is None and sequence <= self.sequence:
            why = f"sequence {sequence} is not above the last accepted {self.sequence} (a replayed request)"
        if why is not None:
            return RequestError(ErrorCode.MODE_NOT_AUTHENTIC, why)
        self.sequence = sequence
        return None
