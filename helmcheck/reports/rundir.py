"""One read of a results directory: the validated results, their digest and the wire summary.

``results.json`` is read once and the same bytes are both parsed and hashed, so the digest a
report prints is the digest of the document it rendered. Every renderer takes a :class:`Run`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .digest import Digest, digest_bytes
from .results import ReportError, parse_results, read_results_bytes
from .segments import read_session, recorded_segments
from .wirelog import summarise

__all__ = ["Run", "load_run"]


@dataclass(frozen=True, slots=True)
class Run:
    """A results directory as the renderers see it."""

    directory: Path
    results: dict[str, Any]
    digest: Digest
    wire: dict[str, Any]  #: :func:`helmcheck.reports.wirelog.summarise` of the wire log
    wire_path: Path

    @property
    def strict(self) -> bool:
        return bool(self.results["settings"].get("strict", False))


def load_run(directory: Path | str) -> Run:
    """Load ``DIR/results.json`` and ``DIR/<wire_log>``; :class:`ReportError` naming the file
    that could not be read or is not a valid results document. A missing wire log is allowed
    (the reports say so and the digest records it as absent)."""
    path, data = read_results_bytes(directory)
    results = parse_results(data, path)
    wire_path = path.parent / results["wire_log"]
    try:
        wire: bytes | None = read_session([wire_path, *(path.parent / n for n in recorded_segments(results))])
    except FileNotFoundError:
        wire = None
    except OSError as exc:
        raise ReportError(wire_path, f"cannot read the wire log: {exc.strerror or exc}") from None
    return Run(path.parent, results, digest_bytes(data, wire), summarise(wire), wire_path)
