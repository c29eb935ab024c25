"""Plan signatures: Ed25519 over the plan message's own bytes (application-level authentication).

DDS Security is not available from the PyPI Fast DDS build, so the suite authenticates plans
itself: the planner signs every ``ManeuverPlan`` it issues and the controller flies only plans
whose signature verifies against its configured public key (``cryptography``'s Ed25519, RFC 8032).

What is signed is the CDR serialization of the message with ``signature`` emptied
(:func:`payload`): every field the controller reads, the header stamp and the ``key_id`` included,
and exactly what arrives (floats are never re-normalised on the way). Keys are PEM files: a
PKCS#8 private key (mode 0600) and its SubjectPublicKeyInfo public key, made by ``att-keygen``;
the bootstrap makes a pair for the demo under ``<venv>/share/att_suite/keys``
(:func:`default_key_dir`; ``$ATT_KEY_DIR`` overrides).
"""
from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

from cryptography.exceptions import InvalidSignature
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey, Ed25519PublicKey
from rclpy.serialization import serialize_message

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


def payload(msg) -> bytes:
    """The bytes a signature covers: the message serialized with an empty ``signature``."""
    signature = msg.signature
    msg.signature = b""
    try:
        return serialize_message(msg)
    finally:
        msg.signature = signature


def sign(msg, private_key: Ed25519PrivateKey) -> None:
    """Set ``msg.key_id`` and ``msg.signature`` (call after every other field is final)."""
    msg.key_id = key_id(private_key.public_key())
    msg.signature = private_key.sign(payload(msg))


def check(data: bytes, signature: bytes, signer: str, public_key: Ed25519PublicKey) -> str | None:
    """Why ``signature`` (made by key ``signer``) does not authenticate ``data``; None when it does."""
    if not signature:
        return "the plan is not signed"
    expected = key_id(public_key)
    if signer != expected:
        return f"the plan is signed with key '{signer[:32]}', not with the configured key '{expected}'"
    if len(signature) != SIGNATURE_LENGTH:
        return f"the signature has {len(signature)} bytes, an Ed25519 signature has {SIGNATURE_LENGTH}"
    try:
        public_key.verify(bytes(signature), data)
    except InvalidSignature:
        return "the signature does not verify (the plan was altered or signed by another key)"
    return None
