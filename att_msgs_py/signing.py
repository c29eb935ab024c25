"""Plan signatures: Ed25519 over the plan message's own bytes (application-level authentication).

DDS Security is not available from the PyPI Fast DDS build, so the suite authenticates plans
itself: the planner signs every ``ManeuverPlan`` it issues and the controller flies only plans
whose signature verifies against its configured public key (``cryptography``'s Ed25519, RFC 8032).

What is signed is a canonical encoding of every field of the message but ``signature``
(:func:`payload`): the header stamp and the ``key_id`` included, and every nested field (a plan's
``epoch`` seconds and nanoseconds, each of its ``zones`` with name, body, sensor axis,
half-angle, keep-in flag and direction), values exactly as they travel (floats are never
re-normalised on the way). Not the CDR bytes themselves: Fast CDR leaves its
alignment padding uninitialised, so the same message serializes to different bytes. Keys are PEM files: a
PKCS#8 private key (mode 0600) and its SubjectPublicKeyInfo public key, made by ``att-keygen``;
the bootstrap makes a pair for the demo under ``<venv>/share/att_suite/keys``
(:func:`default_key_dir`; ``$ATT_KEY_DIR`` overrides).
"""
from __future__ import annotations

import hashlib
import os
import struct
import sys
from pathlib import Path

import numpy as np
from cryptography.exceptions import InvalidSignature
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey, Ed25519PublicKey

KEY_DIR_ENV = "ATT_KEY_DIR"
PRIVATE_NAME, PUBLIC_NAME = "plan_signing.key", "plan_signing.pub"
SIGNATURE_LENGTH = 64


def default_key_dir() -> Path:
    return Path(os.environ.get(KEY_DIR_ENV) or Path(sys.prefix) / "share" / "att_suite" / "keys")


def key_id(public_key: Ed25519PublicKey) -> str:
    """16 hex digits of the SHA-256 of the raw public key."""
    raw = public_key.public_bytes(serialization.Encoding.Raw, serialization.PublicFormat.Raw)
    return hashlib.sha256(raw).hexdigest()[:16]


def generate(directory: str | Path, overwrite: bool = False) -> tuple[Path, Path]:
    """Write a new key pair into ``directory``; the paths of the private and public key files."""
    directory = Path(directory)
    private_path, public_path = directory / PRIVATE_NAME, directory / PUBLIC_NAME
    if not overwrite and (private_path.exists() or public_path.exists()):
        raise FileExistsError(f"{private_path} or {public_path} exists (use --force to replace the pair)")
    directory.mkdir(parents=True, exist_ok=True)
    key = Ed25519PrivateKey.generate()
    pem = key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                            serialization.NoEncryption())
    fd = os.open(private_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "wb") as fh:
        fh.write(pem)
    public_path.write_bytes(key.public_key().public_bytes(serialization.Encoding.PEM,
                                                          serialization.PublicFormat.SubjectPublicKeyInfo))
    return private_path, public_path


def load_private_key(path: str | Path) -> Ed25519PrivateKey:
    key = serialization.load_pem_private_key(Path(path).read_bytes(), password=None)
    if not isinstance(key, Ed25519PrivateKey):
        raise ValueError(f"{path} is not an Ed25519 private key")
    return key


def load_public_key(path: str | Path) -> Ed25519PublicKey:
    key = serialization.load_pem_public_key(Path(path).read_bytes())
    if not isinstance(key, Ed25519PublicKey):
        raise ValueError(f"{path} is not an Ed25519 public key")
    return key


_NUMBERS = {"double": "<f8", "float": "<f4", "int8": "<i1", "uint8": "<u1", "octet": "<u1", "char": "<u1",
            "int16": "<i2", "uint16": "<u2", "int32": "<i4", "uint32": "<u4", "int64": "<i8", "uint64": "<u8",
            "boolean": "<u1"}


def _element(kind: str) -> str | None:
    """The element type of a sequence or array type (``sequence<double, 3>``, ``double[3]``)."""
    if kind.startswith("sequence<"):
        return kind[len("sequence<"):-1].split(",")[0].strip()
    return kind[:kind.index("[")] if kind.endswith("]") else None


def _encode(value, kind: str, out: list) -> None:
    element = _element(kind)
    if element is not None:
        out.append(struct.pack("<Q", len(value)))
        if element in _NUMBERS:
            out.append(np.asarray(value, dtype=_NUMBERS[element]).tobytes())
            return
        fields = type(value[0]).get_fields_and_field_types() if len(value) else {}
        if fields and all(k == "double" for k in fields.values()):      # Vector3, Quaternion, ...
            out.append(np.array([[getattr(item, n) for n in fields] for item in value], "<f8").tobytes())
            return
        for item in value:
            _encode(item, element, out)
    elif kind in _NUMBERS:
        out.append(np.asarray(value, dtype=_NUMBERS[kind]).tobytes())
    elif kind in ("string", "wstring") or kind.startswith("string<"):
        data = value.encode("utf-8")
        out.append(struct.pack("<Q", len(data)) + data)
    else:
        for name, field_kind in value.get_fields_and_field_types().items():
            _encode(getattr(value, name), field_kind, out)


def payload(msg) -> bytes:
    """The bytes a signature covers: every field of ``msg`` but ``signature``, in declaration
    order (numbers little-endian, strings and sequences length-prefixed)."""
    out = [type(msg).__name__.encode()]
    for name, kind in msg.get_fields_and_field_types().items():
        if name != "signature":
            _encode(getattr(msg, name), kind, out)
    return b"".join(out)


def sign(msg, private_key: Ed25519PrivateKey) -> None:
    """Set ``msg.key_id`` and ``msg.signature`` (call after every other field is final); any
    message with those two fields (a ``ManeuverPlan``, a ``SetControllerMode`` request)."""
    msg.key_id = key_id(private_key.public_key())
    msg.signature = private_key.sign(payload(msg))


def check(data: bytes, signature: bytes, signer: str, public_key: Ed25519PublicKey,
          what: str = "the plan") -> str | None:
    """Why ``signature`` (made by key ``signer``) does not authenticate ``data``; None when it does."""
    if not signature:
        return f"{what} is not signed"
    expected = key_id(public_key)
    if signer != expected:
        return f"{what} is signed with key '{signer[:32]}', not with the configured key '{expected}'"
    if len(signature) != SIGNATURE_LENGTH:
        return f"the signature has {len(signature)} bytes, an Ed25519 signature has {SIGNATURE_LENGTH}"
    try:
        public_key.verify(bytes(signature), data)
    except InvalidSignature:
        return f"the signature does not verify ({what} was altered or signed by another key)"
    return None
