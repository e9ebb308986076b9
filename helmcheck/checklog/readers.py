"""Log readers: the format detector, and one streaming reader per capture format.

This module owns turning a capture file into a stream of records (:data:`Chunk`): timed runs of
wire bytes with the log line they came from, as the :class:`~helmcheck.grammar.wirelog.WireEvent` s
the observers are fed, without keeping the file in memory. It judges nothing; the checker
(:mod:`.checker`) hands the records to the observers, which re-frame the bytes (RH-FRM-6/7) and
judge them.

Formats (detected from the first non-blank lines, :func:`detect_format`):

``wirelog``
    helmcheck wire-log 1 (``docs/contracts.md``): ``<seconds> <dir> <payload>`` per line,
    ``#`` comments (the header may carry ``time_scale K`` and ``baud N``), ``!`` notes. Read by
    the one wire-log reader, :func:`helmcheck.grammar.wirelog.read_wire_log`.

``socat-v`` and ``socat-x``
    ``socat -v`` text dumps and ``socat -x`` hex dumps (also ``socat -v -x``), read by
    :mod:`.socat`, which also says how their timestamps' fractions are read.

Every text line is accounted for: a line the reader cannot read becomes an :class:`Unreadable`
record (direction ``?``) with a reason (the checker reports it as a finding with its line number).
"""

from __future__ import annotations

from typing import BinaryIO, Iterator, Optional

from ..grammar.wirelog import RECORD_HEAD, TAG, read_wire_log
from .records import (HEAD_BYTES, NOTE, UNREADABLE, Chunk, LogMeta, Progress, Unreadable, decimals_resolution,
                      header_comment)
from .socat import HEX_LINE, SOCAT_HEADER, TimeUnit, read_socat, socat_resolution, socat_time_unit

__all__ = ["Chunk", "Unreadable", "LogMeta", "TimeUnit", "detect_format", "socat_time_unit", "timestamp_resolution",
           "read_chunks", "header_comment", "FORMATS", "UNREADABLE", "NOTE", "HEAD_BYTES"]

FORMATS = ("wirelog", "socat-v", "socat-x")

_TAG = TAG.encode()
_NOTE = NOTE.encode()


def detect_format(head: bytes) -> Optional[str]:
    """The format of a log from its first bytes (a few KiB), or None when none fits."""
    lines = [ln for ln in head.split(b"\n")[:50] if ln.strip()]
    if not lines:
        return None
    if lines[0].startswith(_TAG):
        return "wirelog"
    for i, ln in enumerate(lines):
        if ln.startswith(b"#"):
            continue
        if SOCAT_HEADER.match(ln.rstrip(b"\r")):
            nxt = lines[i + 1] if i + 1 < len(lines) else b""
            if HEX_LINE.match(nxt) or (len(nxt) > 50 and nxt[:1] == b" " and b"  " in nxt[48:]):
                return "socat-x"
            return "socat-v"
        if RECORD_HEAD.match(ln):
            return "wirelog"
        return None
    return None


def timestamp_resolution(head: bytes, fmt: str) -> float:
    """The finest timestamp step seen in the first records: a clock that never shows more
    than whole seconds gives 1.0 even if it prints six decimals. For socat captures the
    fractions are read in the unit :func:`socat_time_unit` detects (1 µs for socat 1.7.4's
    nine digits, not 1 ns)."""
    best = 1.0
    if fmt == "wirelog":
        for ln in head.split(b"\n")[:2000]:
            m = RECORD_HEAD.match(ln)
            if m and m.group(3) != _NOTE:
                best = min(best, decimals_resolution(m.group(2)))
        return best
    return socat_resolution(head)


def read_chunks(f: BinaryIO, fmt: str, meta: LogMeta, *, swap: bool = False,
                progress: Progress = None) -> Iterator[Chunk]:
    """The records of an open binary log file in format ``fmt`` (streaming, constant memory)."""
    if fmt == "wirelog":
        return _read_wirelog(f, meta, swap, progress)
    if fmt == "socat-v":
        return read_socat(f, meta, swap, progress, hex_mode=False)
    if fmt == "socat-x":
        return read_socat(f, meta, swap, progress, hex_mode=True)
    raise ValueError(f"unknown log format {fmt!r}; known: {', '.join(FORMATS)}")


def _read_wirelog(f: BinaryIO, meta: LogMeta, swap: bool, progress: Progress) -> Iterator[Chunk]:
    """helmcheck wire-log 1 records (docs/contracts.md), by the one wire-log reader."""
    meta.time_unit = "decimal"
    meta.time_unit_basis = "wire-log 1 times are decimal seconds since the log began"
    return read_wire_log(f, swap=swap, progress=progress, comment=lambda text: header_comment(text, meta))
