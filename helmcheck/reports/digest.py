"""The certificate digest: what ties a rendered report to the exact run it describes.

Three SHA-256 hex digests:

* ``results`` — of the bytes of ``results.json``;
* ``wire`` — of the bytes of the wire log (``None`` when the log is absent);
* ``combined`` — of the text ``"helmcheck-certificate-1\\n" + results + "\\n" + (wire or "absent")
  + "\\n"`` (UTF-8), the one number to quote.

Every rendering prints all three, so changing one byte of either file, or the report itself,
shows: recomputing with :func:`digest_dir` no longer matches what the report says.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Digest", "digest_bytes", "digest_dir", "DIGEST_TAG"]

DIGEST_TAG = "helmcheck-certificate-1"


@dataclass(frozen=True, slots=True)
class Digest:
    """The three hex digests of a results directory."""

    results: str
    wire: str | None
    combined: str

    def as_dict(self) -> dict[str, str | None]:
        return {"results_sha256": self.results, "wire_sha256": self.wire, "combined_sha256": self.combined}

    def lines(self) -> list[str]:
        """Human-readable lines, the same in every rendering."""
        return [
            f"certificate digest (SHA-256): {self.combined}",
            f"results.json SHA-256: {self.results}",
            f"wire log SHA-256: {self.wire or 'absent (no wire log in the results directory)'}",
        ]


def digest_bytes(results: bytes, wire: bytes | None) -> Digest:
    """The digest of the two files' contents (*wire* ``None`` when there is no wire log)."""
    r = hashlib.sha256(results).hexdigest()
    w = hashlib.sha256(wire).hexdigest() if wire is not None else None
    combined = hashlib.sha256(f"{DIGEST_TAG}\n{r}\n{w or 'absent'}\n".encode("ascii")).hexdigest()
    return Digest(r, w, combined)


def digest_dir(directory: Path | str, wire_log: str = "wire.log") -> Digest:
    """The digest of ``DIR/results.json`` and ``DIR/<wire_log>`` as they are on disk now.

    ``OSError`` if ``results.json`` cannot be read; a missing wire log counts as absent.
    """
    directory = Path(directory)
    results = (directory / "results.json").read_bytes()
    try:
        wire: bytes | None = (directory / wire_log).read_bytes()
    except FileNotFoundError:
        wire = None
    return digest_bytes(results, wire)
