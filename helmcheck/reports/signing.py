"""Ed25519 keys and signatures for results directories (``keygen``, ``certify --sign-key``, ``verify``).

All cryptography is the ``cryptography`` package's; this module only chooses formats:

* ``PREFIX.key``: the private key, PKCS #8 PEM, unencrypted, file mode 0600;
* ``PREFIX.pub``: the public key, SubjectPublicKeyInfo PEM;
* the **key id**: the SHA-256 (hex) of the 32 raw public-key bytes — what a report prints and a
  reviewer compares with the id ``helmcheck keygen`` printed for the key they trust;
* a **signature** is Ed25519 over ``SIGNED_TAG`` + LF + the canonical JSON of a manifest
  (:func:`canonical`: sorted keys, no spaces, ASCII), so the signed bytes never depend on how a
  file was pretty-printed and cannot be mistaken for any other helmcheck message.

Every failure to read or use a key is a :class:`KeyFileError` whose message names the file.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from cryptography.exceptions import InvalidSignature
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey, Ed25519PublicKey

__all__ = ["ALGORITHM", "SIGNED_TAG", "KeyFileError", "SigningKey", "generate_keypair", "load_signing_key",
           "load_public_key", "public_key_from_b64", "key_id", "canonical", "sign", "check"]

ALGORITHM = "Ed25519"
SIGNED_TAG = b"helmcheck-signed-run-1"


class KeyFileError(ValueError):
    """A key file that cannot be read or is not an Ed25519 key; the message names the file."""


def key_id(public: Ed25519PublicKey) -> str:
    """The SHA-256 (hex) of the raw public key bytes."""
    return hashlib.sha256(_raw(public)).hexdigest()


def _raw(public: Ed25519PublicKey) -> bytes:
    return public.public_bytes(serialization.Encoding.Raw, serialization.PublicFormat.Raw)


@dataclass(frozen=True)
class SigningKey:
    """A loaded private key and where it came from."""

    private: Ed25519PrivateKey
    path: str

    @property
    def public(self) -> Ed25519PublicKey:
        return self.private.public_key()

    @property
    def key_id(self) -> str:
        return key_id(self.public)

    @property
    def public_b64(self) -> str:
        return base64.b64encode(_raw(self.public)).decode("ascii")


def generate_keypair(prefix: str | Path, *, overwrite: bool = False) -> tuple[Path, Path, str]:
    """Write ``PREFIX.key`` (0600) and ``PREFIX.pub``; returns both paths and the key id.

    ``FileExistsError`` if either exists and not *overwrite*; ``OSError`` if they cannot be written.
    """
    key_path, pub_path = Path(f"{prefix}.key"), Path(f"{prefix}.pub")
    if not overwrite:
        for p in (key_path, pub_path):
            if p.exists():
                raise FileExistsError(f"{p} exists (refusing to overwrite a key)")
    private = Ed25519PrivateKey.generate()
    pem = private.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                                serialization.NoEncryption())
    pub = private.public_key().public_bytes(serialization.Encoding.PEM,
                                            serialization.PublicFormat.SubjectPublicKeyInfo)
    flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | (0 if overwrite else os.O_EXCL)
    fd = os.open(key_path, flags, 0o600)
    with os.fdopen(fd, "wb") as fh:
        fh.write(pem)
    os.chmod(key_path, 0o600)
    pub_path.write_bytes(pub)
    return key_path, pub_path, key_id(private.public_key())


def _read(path: str | Path, what: str) -> bytes:
    try:
        return Path(path).read_bytes()
    except OSError as e:
        raise KeyFileError(f"{path}: cannot read the {what}: {e.strerror or e}") from None


def load_signing_key(path: str | Path) -> SigningKey:
    """Read an unencrypted PEM Ed25519 private key (as ``keygen`` writes it)."""
    data = _read(path, "private key")
    try:
        private = serialization.load_pem_private_key(data, password=None)
    except TypeError:
        raise KeyFileError(f"{path}: the private key is encrypted; give an unencrypted Ed25519 key") from None
    except ValueError:
        raise KeyFileError(f"{path}: not a PEM private key (make one with 'helmcheck keygen')") from None
    except Exception as e:  # noqa: BLE001 - the backend's errors for odd input vary by version
        raise KeyFileError(f"{path}: not a usable private key ({type(e).__name__})") from None
    if not isinstance(private, Ed25519PrivateKey):
        raise KeyFileError(f"{path}: a {type(private).__name__.removeprefix('_')} key, not an Ed25519 key")
    return SigningKey(private, str(path))


def load_public_key(path: str | Path) -> Ed25519PublicKey:
    """Read a PEM Ed25519 public key (as ``keygen`` writes it)."""
    data = _read(path, "public key")
    try:
        public = serialization.load_pem_public_key(data)
    except ValueError:
        raise KeyFileError(f"{path}: not a PEM public key (the .pub file 'helmcheck keygen' wrote)") from None
    except Exception as e:  # noqa: BLE001
        raise KeyFileError(f"{path}: not a usable public key ({type(e).__name__})") from None
    if not isinstance(public, Ed25519PublicKey):
        raise KeyFileError(f"{path}: not an Ed25519 public key")
    return public


def public_key_from_b64(text: str) -> Ed25519PublicKey:
    """A public key from the base64 of its 32 raw bytes (``ValueError`` if it is not one)."""
    try:
        raw = base64.b64decode(text.encode("ascii"), validate=True)
    except (binascii.Error, UnicodeEncodeError, AttributeError):
        raise ValueError("public_key is not base64") from None
    if len(raw) != 32:
        raise ValueError(f"public_key has {len(raw)} bytes, an Ed25519 key has 32")
    return Ed25519PublicKey.from_public_bytes(raw)


def canonical(manifest: Mapping[str, Any]) -> bytes:
    """The bytes a signature covers: the tag, LF, and the manifest as canonical JSON."""
    body = json.dumps(manifest, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False)
    return SIGNED_TAG + b"\n" + body.encode("ascii")


def sign(key: SigningKey, manifest: Mapping[str, Any]) -> str:
    """The base64 Ed25519 signature of *manifest*."""
    return base64.b64encode(key.private.sign(canonical(manifest))).decode("ascii")


def check(public: Ed25519PublicKey, manifest: Mapping[str, Any], signature_b64: str) -> bool:
    """Whether *signature_b64* is *public*'s signature of *manifest*."""
    try:
        sig = base64.b64decode(signature_b64.encode("ascii"), validate=True)
    except (binascii.Error, UnicodeEncodeError, AttributeError):
        return False
    try:
        public.verify(sig, canonical(manifest))
    except (InvalidSignature, ValueError, TypeError):
        return False
    return True
