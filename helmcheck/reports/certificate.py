"""Closing a run as a certificate: profile, digests, identity, scope and signature.

:func:`finish_run` is the one call a certifier makes after its final ``results.json`` is
written and its wire log closed, before the reports are rendered. In the run directory it

1. writes ``profile.toml``: the resolved profile the judges used, as deterministic TOML
   (:func:`helmcheck.profile_toml.emit_profile`; command-line overrides such as ``--time-scale``
   and ``--baud`` included), so ``helmcheck verify`` re-judges under exactly that profile;
2. records in ``results.json``: ``digests`` (SHA-256 of the wire log and of ``profile.toml``),
   ``identity`` (:mod:`.identity`), ``certificate`` and ``scope`` (:mod:`.scope`) and
   ``signature`` (``null``, or the file, algorithm and key id of the signature);
3. with a signing key, writes ``signature.json``: an Ed25519 signature (:mod:`.signing`) over the
   manifest of ``results.json``, the wire log, ``profile.toml`` and the tool's name, version and
   revision (:mod:`.manifest`). Without one, a ``signature.json`` left by an earlier run in the
   same directory is removed, so it cannot vouch for this run.

``signature.json``::

    {"format": "helmcheck-signature-1", "algorithm": "Ed25519", "key_id": HEX,
     "public_key": BASE64 (32 raw bytes), "manifest": {…}, "signature": BASE64}
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

from ..profile import Profile
from ..profile_toml import emit_profile
from .atomic import write_bytes_atomic, write_text_atomic
from .identity import Declared, build_identity
from .manifest import PROFILE_NAME, build_manifest, sha256_bytes, sha256_file
from .results import write_results_atomic
from .scope import scope_of
from .segments import recorded_segments
from .signing import ALGORITHM, SigningKey, sign
from .wirelog import summarise

__all__ = ["SIGNATURE_NAME", "SIGNATURE_FORMAT", "RunDeclaration", "finish_run", "record_certificate"]

SIGNATURE_NAME = "signature.json"
SIGNATURE_FORMAT = "helmcheck-signature-1"


@dataclass(frozen=True)
class RunDeclaration:
    """What a certifier's command line declared for the certificate: who, where, what, and the
    key to sign with (``None``: unsigned)."""

    declared: Declared = field(default_factory=Declared)
    sign_key: Optional[SigningKey] = None


def record_certificate(results: dict[str, Any], run_dir: Path | str, profile: Profile,
                       declared: Optional[Declared] = None, *, sign_key: Optional[SigningKey] = None) -> str:
    """Steps 1–2 of :func:`finish_run` (in memory, plus ``profile.toml``); returns the TOML text."""
    run_dir = Path(run_dir)
    declared = declared or Declared()
    text = emit_profile(profile)
    write_text_atomic(run_dir / PROFILE_NAME, text)
    wire_name = str(results.get("wire_log") or "wire.log")
    try:
        wire: Optional[bytes] = (run_dir / wire_name).read_bytes()
    except FileNotFoundError:
        wire = None
    profile_sha = sha256_bytes(text.encode("utf-8"))
    results["digests"] = {wire_name: sha256_bytes(wire) if wire is not None else None,
                          **{name: sha256_file(run_dir / name) for name in recorded_segments(results)},
                          PROFILE_NAME: profile_sha}
    given = sha256_file(declared.profile_file) if declared.profile_file else None
    name_on_wire = summarise(wire)["osi_vehicle_name"] if results.get("role") != "backseat" else None
    results["identity"] = build_identity(results, profile, declared=declared, profile_sha256=profile_sha,
                                         profile_file_sha256=given, name_on_wire=name_on_wire)
    scope = scope_of(results)
    results["certificate"] = scope.certificate
    results["scope"] = scope.as_dict()
    results["signature"] = ({"file": SIGNATURE_NAME, "algorithm": ALGORITHM, "key_id": sign_key.key_id}
                            if sign_key is not None else None)
    return text


def finish_run(results: dict[str, Any], run_dir: Path | str, profile: Profile,
               declaration: Optional[RunDeclaration] = None) -> dict[str, Any]:
    """Record the certificate of a finished run and write it (module docstring); returns *results*.

    ``OSError`` or :class:`~helmcheck.reports.results.ReportError` when a file cannot be written.
    """
    run_dir = Path(run_dir)
    declaration = declaration or RunDeclaration()
    sign_key = declaration.sign_key
    record_certificate(results, run_dir, profile, declaration.declared, sign_key=sign_key)
    write_results_atomic(run_dir, results)
    sig_path = run_dir / SIGNATURE_NAME
    if sign_key is None:
        try:
            os.unlink(sig_path)
        except FileNotFoundError:
            pass
        return results
    manifest = build_manifest(run_dir, results)
    doc = {"format": SIGNATURE_FORMAT, "algorithm": ALGORITHM, "key_id": sign_key.key_id,
           "public_key": sign_key.public_b64, "manifest": manifest, "signature": sign(sign_key, manifest)}
    write_bytes_atomic(sig_path, (json.dumps(doc, indent=2, sort_keys=True) + "\n").encode("ascii"))
    return results
