"""The mode requests' replay guard: a sequence bounded by the clock, remembered across restarts."""
from __future__ import annotations

import json
import os

import pytest
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs.srv import SetControllerMode
from att_msgs_py import signing
from att_msgs_py.errors import ErrorCode
from att_planner.control.mode_authentication import ModeAuthentication

KEY = Ed25519PrivateKey.generate()
NOW = 1_800_000_000 * 10**9          # the controller's wall clock (ns) in these tests


def request(sequence, mode=1, key=KEY):
    msg = SetControllerMode.Request(mode=mode, sequence=sequence)
    signing.sign(msg, key)
    return signing.payload(msg), bytes(msg.signature), msg.key_id, int(msg.sequence)


def guard(path=None, now=NOW):
    return ModeAuthentication(KEY.public_key(), path, clock_ns=lambda: now)


def test_a_maximal_sequence_cannot_exhaust_the_counter():
    auth = guard()
    refused = auth.check(*request(2**64 - 1))
    assert refused.code == ErrorCode.MODE_NOT_AUTHENTIC and "ahead of the controller's clock" in refused.message
    assert auth.sequence == 0
    assert auth.check(*request(NOW - 10**9)) is None           # the operator's next request still works
    assert auth.check(*request(NOW + 299 * 10**9)) is None     # within the clock bound: accepted
    assert auth.check(*request(NOW + 301 * 10**9)).code == ErrorCode.MODE_NOT_AUTHENTIC


def test_an_accepted_request_replayed_after_a_restart_is_refused(tmp_path):
    path = tmp_path / "state" / "modes.json"
    first = request(NOW - 5 * 10**9)
    assert guard(path).check(*first) is None
    assert json.loads(path.read_text()) == {first[2]: NOW - 5 * 10**9}
    restarted = guard(path)
    refused = restarted.check(*first)
    assert refused.code == ErrorCode.MODE_NOT_AUTHENTIC and "replayed" in refused.message
    assert restarted.check(*request(NOW - 4 * 10**9)) is None
    assert [p.name for p in path.parent.iterdir()] == ["modes.json"]    # no temporary file left


def test_a_missing_record_starts_empty(tmp_path):
    auth = guard(tmp_path / "none.json")
    assert auth.warning is None and auth.sequence == 0 and auth.check(*request(7)) is None


@pytest.mark.parametrize("content", [b"", b"{not json", b"[1, 2]", b'{"a": -1}', b'{"a": 1.5}', b"\xff\xfe",
                                     b'{"a": 18446744073709551616}', b" " * 70_000])
def test_a_damaged_record_refuses_every_request_signed_before_the_start(tmp_path, content):
    path = tmp_path / "modes.json"
    path.write_bytes(content)
    auth = guard(path)
    assert "unreadable" in auth.warning and str(path) in auth.warning
    refused = auth.check(*request(NOW - 1))
    assert refused.code == ErrorCode.MODE_NOT_AUTHENTIC and "replayed" in refused.message
    assert auth.check(*request(NOW + 1)) is None
    assert guard(path).warning is None                          # the record is whole again


def test_an_unwritable_record_refuses_rather_than_forgets(tmp_path):
    directory = tmp_path / "ro"
    directory.mkdir()
    os.chmod(directory, 0o500)
    try:
        if os.access(directory, os.W_OK):
            pytest.skip("running as a user that can write a read-only directory")
        auth = guard(directory / "modes.json")
        refused = auth.check(*request(NOW - 1))
        assert refused.code == ErrorCode.MODE_NOT_AUTHENTIC and "could not be recorded" in refused.message
        assert auth.sequence == 0
    finally:
        os.chmod(directory, 0o700)
