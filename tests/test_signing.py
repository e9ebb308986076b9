"""Signing keys and signatures: ``helmcheck keygen``, Ed25519 over a canonical manifest."""

from __future__ import annotations

import os
import stat

import pytest

from helmcheck.cli import main as cli_main
from helmcheck.reports.signing import (
    KeyFileError, canonical, check, generate_keypair, key_id, load_public_key, load_signing_key, sign,
)

MANIFEST = {"format": "helmcheck-manifest-1", "files": {"results.json": "ab" * 32, "wire.log": "cd" * 32},
            "tool": {"name": "helmcheck", "version": "0.1.0", "revision": "unknown"}}


def test_keygen_writes_a_private_key_only_its_owner_reads_and_prints_the_key_id(tmp_path, capsys):
    assert cli_main(["keygen", "--out", str(tmp_path / "lab")]) == 0
    key, pub = tmp_path / "lab.key", tmp_path / "lab.pub"
    assert stat.S_IMODE(os.stat(key).st_mode) == 0o600
    assert key.read_text().startswith("-----BEGIN PRIVATE KEY-----")
    assert pub.read_text().startswith("-----BEGIN PUBLIC KEY-----")
    out = capsys.readouterr().out
    assert f"key id:      {key_id(load_public_key(pub))}" in out
    assert load_signing_key(key).key_id == key_id(load_public_key(pub))


def test_keygen_never_overwrites_a_key_without_force(tmp_path, capsys):
    assert cli_main(["keygen", "--out", str(tmp_path / "lab")]) == 0
    before = (tmp_path / "lab.key").read_bytes()
    assert cli_main(["keygen", "--out", str(tmp_path / "lab")]) == 64
    err = capsys.readouterr().err
    assert "lab.key exists" in err and "--force" in err and "Traceback" not in err
    assert (tmp_path / "lab.key").read_bytes() == before
    assert cli_main(["keygen", "--out", str(tmp_path / "lab"), "--force"]) == 0
    assert (tmp_path / "lab.key").read_bytes() != before


def test_keygen_into_a_missing_directory_is_a_usage_error(tmp_path, capsys):
    assert cli_main(["keygen", "--out", str(tmp_path / "no" / "such" / "lab")]) == 64
    assert "cannot write" in capsys.readouterr().err


def test_a_signature_holds_for_its_manifest_and_key_only(tmp_path):
    a_key, a_pub, _ = generate_keypair(tmp_path / "a")
    _, b_pub, _ = generate_keypair(tmp_path / "b")
    signer = load_signing_key(a_key)
    sig = sign(signer, MANIFEST)
    assert check(load_public_key(a_pub), MANIFEST, sig)
    assert not check(load_public_key(b_pub), MANIFEST, sig)
    changed = {**MANIFEST, "files": {**MANIFEST["files"], "wire.log": "ce" + "cd" * 31}}
    assert not check(load_public_key(a_pub), changed, sig)
    assert not check(load_public_key(a_pub), MANIFEST, "not base64!")


def test_the_signed_bytes_do_not_depend_on_key_order():
    reordered = {"tool": MANIFEST["tool"], "files": dict(reversed(MANIFEST["files"].items())),
                 "format": MANIFEST["format"]}
    assert canonical(reordered) == canonical(MANIFEST)
    assert canonical(MANIFEST).startswith(b"helmcheck-signed-run-1\n{")


@pytest.mark.parametrize("content,needle", [
    (b"", "not a PEM private key"),
    (b"-----BEGIN PRIVATE KEY-----\nAAAA\n-----END PRIVATE KEY-----\n", "private key"),
])
def test_bad_private_key_files_are_named(tmp_path, content, needle):
    path = tmp_path / "bad.key"
    path.write_bytes(content)
    with pytest.raises(KeyFileError) as e:
        load_signing_key(path)
    assert str(path) in str(e.value) and needle in str(e.value)


def test_a_public_key_is_not_a_private_key_and_a_missing_file_is_named(tmp_path):
    _, pub, _ = generate_keypair(tmp_path / "a")
    with pytest.raises(KeyFileError, match="not a PEM private key"):
        load_signing_key(pub)
    with pytest.raises(KeyFileError, match="cannot read the public key"):
        load_public_key(tmp_path / "missing.pub")


def test_a_non_ed25519_key_is_refused(tmp_path):
    from cryptography.hazmat.primitives import serialization
    from cryptography.hazmat.primitives.asymmetric import ec

    other = ec.generate_private_key(ec.SECP256R1())
    path = tmp_path / "ec.key"
    path.write_bytes(other.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                                         serialization.NoEncryption()))
    with pytest.raises(KeyFileError, match="not an Ed25519 key"):
        load_signing_key(path)
