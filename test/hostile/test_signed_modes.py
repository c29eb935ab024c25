"""Mode changes from the ground, authenticated: with ``require_signed_modes`` only a request signed
with the ground's key and a fresh sequence changes the controller's mode (its own module: it
starts its own suite and client session)."""
from __future__ import annotations

import time

import pytest
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs.srv import SetControllerMode
from att_msgs_py import signing
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import ControlMode

pytestmark = pytest.mark.ros


def test_with_signed_modes_required_only_the_ground_key_changes_the_mode(ros_suite, tmp_path):
    record = tmp_path / "mode_sequences.json"
    with ros_suite("swift_demo", nodes=("controller",), name="signed_modes_test",
                   params={"controller": {"require_signed_modes": True, "state_source": "truth",
                                          "mode_sequence_file": str(record)}}) as s:
        client = s.client
        assert client.mode_client.wait_for_service(timeout_sec=30)
        unsigned = client.set_mode(ControlMode.SAFE, key=None)
        assert unsigned.error_code == ErrorCode.MODE_NOT_AUTHENTIC and "not signed" in unsigned.message
        forged = client.set_mode(ControlMode.SAFE, key=Ed25519PrivateKey.generate())
        assert forged.error_code == ErrorCode.MODE_NOT_AUTHENTIC
        signed = SetControllerMode.Request(mode=ControlMode.SAFE, sequence=time.time_ns())
        signing.sign(signed, signing.load_private_key(signing.default_key_dir() / signing.PRIVATE_NAME))
        assert client._call(client.mode_client, signed, 10).success       # the ground's key: accepted
        replayed = client._call(client.mode_client, signed, 10)
        assert replayed.error_code == ErrorCode.MODE_NOT_AUTHENTIC and "replayed" in replayed.message
        exhausting = SetControllerMode.Request(mode=ControlMode.SAFE, sequence=2**64 - 1)
        signing.sign(exhausting, signing.load_private_key(signing.default_key_dir() / signing.PRIVATE_NAME))
        refused = client._call(client.mode_client, exhausting, 10)
        assert refused.error_code == ErrorCode.MODE_NOT_AUTHENTIC and "ahead" in refused.message
        assert record.exists()
        assert client.set_mode(ControlMode.IDLE).success                 # default key file: signed


def test_an_accepted_request_replayed_after_a_controller_restart_is_refused(ros_suite, tmp_path):
    params = {"controller": {"require_signed_modes": True, "state_source": "truth",
                             "mode_sequence_file": str(tmp_path / "mode_sequences.json")}}
    recorded = SetControllerMode.Request(mode=ControlMode.SAFE, sequence=time.time_ns())
    signing.sign(recorded, signing.load_private_key(signing.default_key_dir() / signing.PRIVATE_NAME))
    with ros_suite("swift_demo", nodes=("controller",), name="signed_modes_before", params=params) as s:
        assert s.client.mode_client.wait_for_service(timeout_sec=30)
        assert s.client._call(s.client.mode_client, recorded, 10).success
    with ros_suite("swift_demo", nodes=("controller",), name="signed_modes_after", params=params) as s:
        assert s.client.mode_client.wait_for_service(timeout_sec=30)
        replayed = s.client._call(s.client.mode_client, recorded, 10)
        assert replayed.error_code == ErrorCode.MODE_NOT_AUTHENTIC and "replayed" in replayed.message
        assert s.client.set_mode(ControlMode.IDLE).success              # a fresh request still works
