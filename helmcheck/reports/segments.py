"""A session's wire log in segments: finding the files that make it up, and reading them as one.

A long session's log goes on in further files beside the first — ``wire.log``, ``wire.001.log``,
``wire.002.log``, … (``helmcheck monitor`` rotates by size) — each segment but the last ending in
a ``continued in NAME`` note (the format is :mod:`helmcheck.grammar.wirelog`'s, *segments*). This
module is the one place that follows those notes: ``check-log`` and ``verify`` judge the whole
session, the digest and the manifest cover every segment.

* :func:`session_files` — the segments of the log at a path, in order, and the name of a segment
  a note names but that is not there;
* :func:`read_session` — the bytes of the whole session (for the digest and the reports);
* :func:`recorded_segments` — the further segments a results document records (``wire_segments``).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Optional

from ..grammar.wirelog import NOTE, WireLogError, continued_in, parse_record

__all__ = ["Session", "session_files", "read_session", "recorded_segments", "TAIL_BYTES"]

#: How much of a segment's end is read for its continuation note.
TAIL_BYTES = 4096


@dataclass(frozen=True)
class Session:
    files: tuple[Path, ...]  #: the segments, first to last
    missing: Optional[str] = None  #: a segment the last one's note names that is not there


def _next_name(path: Path) -> Optional[str]:
    """The segment the last record of ``path`` names, if it is a continuation note."""
    try:
        with open(path, "rb") as f:
            size = os.fstat(f.fileno()).st_size
            f.seek(max(0, size - TAIL_BYTES))
            tail = f.read()
    except OSError:
        return None
    lines = [ln for ln in tail.splitlines() if ln.strip()]
    if not lines:
        return None
    try:
        rec = parse_record(lines[-1])
    except WireLogError:
        return None
    if rec is None or rec.dir != NOTE:
        return None
    return continued_in(rec.note)


def session_files(first: Path | str) -> Session:
    """The segments of the session whose log starts at ``first`` (module docstring)."""
    files = [Path(first)]
    seen = {files[0].resolve()}
    while True:
        name = _next_name(files[-1])
        if name is None:
            return Session(tuple(files))
        nxt = files[-1].parent / name
        if not nxt.is_file() or nxt.resolve() in seen:
            return Session(tuple(files), missing=name)
        seen.add(nxt.resolve())
        files.append(nxt)


def read_session(files: tuple[Path, ...] | list[Path]) -> bytes:
    """The bytes of every segment, one after another (``FileNotFoundError`` for a missing one)."""
    return b"".join(p.read_bytes() for p in files)


def recorded_segments(results: Mapping[str, Any]) -> tuple[str, ...]:
    """The names of the segments after the first that ``results.json`` records (``wire_segments``)."""
    names = results.get("wire_segments") or ()
    return tuple(str(n) for n in names) if isinstance(names, (list, tuple)) else ()
