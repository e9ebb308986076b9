"""File digests of a results directory and the signed manifest.

A run's evidence is three files: ``results.json`` (the verdicts), the wire log (what crossed the
line) and ``profile.toml`` (what the implementation claimed; the judges' settings). This module
owns hashing them (SHA-256, streamed) and the **manifest** a signature covers::

    {"format": "helmcheck-manifest-1",
     "files": {"results.json": HEX, "wire.log": HEX, "profile.toml": HEX},
     "tool": {"name": "helmcheck", "version": "0.1.0", "revision": "…"}}

``results.json`` records the digests of the other two (``digests``), so a changed byte of the
wire log or a swapped profile shows even in an unsigned run; the manifest adds ``results.json``
itself and the tool, and only a signature makes the whole set trustworthy.
"""

from __future__ import annotations

import hashlib
from pathlib import Path, PurePosixPath
from typing import Any, Mapping

from .segments import recorded_segments

__all__ = ["MANIFEST_FORMAT", "PROFILE_NAME", "RESULTS_NAME", "sha256_file", "sha256_bytes", "evidence_files",
           "build_manifest", "differing_files"]

MANIFEST_FORMAT = "helmcheck-manifest-1"
PROFILE_NAME = "profile.toml"
RESULTS_NAME = "results.json"


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def sha256_file(path: Path | str) -> str | None:
    """The SHA-256 (hex) of a file's bytes, or ``None`` when it does not exist."""
    h = hashlib.sha256()
    try:
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    except FileNotFoundError:
        return None
    return h.hexdigest()


def evidence_files(results: Mapping[str, Any]) -> tuple[str, str]:
    """The names of the wire log and the profile in a run directory (``results.json`` aside)."""
    return str(results.get("wire_log") or "wire.log"), PROFILE_NAME


def build_manifest(directory: Path | str, results: Mapping[str, Any]) -> dict[str, Any]:
    """The manifest of the files as they are on disk now (``None`` for a missing file)."""
    directory = Path(directory)
    wire, profile = evidence_files(results)
    names = (RESULTS_NAME, wire, *recorded_segments(results), profile)
    tester = (results.get("identity") or {}).get("tester") or {}
    tool = results.get("tool") or {}
    return {
        "format": MANIFEST_FORMAT,
        "files": {name: sha256_file(directory / name) for name in names},
        "tool": {"name": tool.get("name", "helmcheck"), "version": tool.get("version"),
                 "revision": tester.get("revision", "unknown")},
    }


def _inside(name: object) -> bool:
    if not isinstance(name, str) or not name or "\\" in name or ":" in name:
        return False
    p = PurePosixPath(name)
    return not p.is_absolute() and ".." not in p.parts and name not in (".",)


def differing_files(directory: Path | str, recorded: Mapping[str, Any]) -> list[tuple[str, str | None, str | None]]:
    """``(name, recorded digest, digest now)`` for every file whose bytes are not the recorded ones."""
    directory = Path(directory)
    out = []
    for name, want in recorded.items():
        if not _inside(name):  # never read outside the results directory
            out.append((str(name), want if isinstance(want, str) else None, None))
            continue
        got = sha256_file(directory / name)
        if got != want:
            out.append((name, want if isinstance(want, str) else None, got))
    return out
