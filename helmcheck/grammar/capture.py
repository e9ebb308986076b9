"""The wire-log (capture) format: a timestamped transcript of both directions of a link.

Version 1, one record per text line (the full description is in ``docs/contracts.md`` and the
README)::

    # helmcheck wire-log 1
    0.000000 > $OSD,G,C,S,P,,,,*5F
    0.012400 < $ACK,8,0,0*5D
    0.500000 >~ garbage\\x00\\xff$OM
    3.100000 ! lockout injected

``>`` is backseat→vehicle, ``<`` vehicle→backseat, whoever recorded. ``>``/``<`` alone mark a
line that ended in CR LF (not written); ``>~``/``<~`` mark any other run of bytes, written in
full. ``!`` is a note. Payload bytes outside 0x20–0x7E, and ``\\``, are escaped.

This module is pure text processing (no clock, no I/O beyond the file object it is handed).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import IO, Iterable, Iterator, Optional

__all__ = ["WireRecord", "WireLogError", "escape", "unescape", "format_record", "parse_record",
           "read_records", "HEADER", "TO_VEHICLE", "FROM_VEHICLE", "NOTE", "WireLogWriter"]

HEADER = "# helmcheck wire-log 1"
TO_VEHICLE = ">"
FROM_VEHICLE = "<"
NOTE = "!"
_DIRS = {">", "<", ">~", "<~", "!"}
_ESC_RE = re.compile(rb"[^\x20-\x5b\x5d-\x7e]")
_UNESC_RE = re.compile(r"\\(x[0-9A-Fa-f]{2}|r|n|t|\\)")
_RECORD_RE = re.compile(r"^(\d+(?:\.\d+)?) (>~|<~|>|<|!) ?(.*)$")


class WireLogError(ValueError):
    """A wire-log line that does not follow the format; names the line."""


@dataclass(frozen=True, slots=True)
class WireRecord:
    """One record: time (s since log start), direction, the exact bytes (or note text)."""

    t: float
    direction: str  #: ">" to the vehicle, "<" from the vehicle, "!" note
    raw: bytes  #: exact bytes on the wire, terminator included
    lineno: int = 0
    note: str = ""

    @property
    def is_note(self) -> bool:
        return self.direction == NOTE


def escape(raw: bytes) -> str:
    def sub(m: re.Match) -> str:
        b = m.group(0)[0]
        return {0x0D: "\\r", 0x0A: "\\n", 0x5C: "\\\\"}.get(b, f"\\x{b:02x}")

    return _ESC_RE.sub(lambda m: sub(m).encode(), raw).decode("ascii") if raw else ""


def unescape(text: str) -> bytes:
    def sub(m: re.Match) -> str:
        e = m.group(1)
        if e[0] == "x":
            return chr(int(e[1:], 16))
        return {"r": "\r", "n": "\n", "t": "\t", "\\": "\\"}[e]

    return _UNESC_RE.sub(sub, text).encode("latin-1")


def format_record(t: float, direction: str, raw: bytes = b"", note: str = "") -> str:
    """One log line (without newline) for bytes seen going ``direction`` at ``t``."""
    if direction == NOTE:
        return f"{t:.6f} ! {note}"
    if direction not in (TO_VEHICLE, FROM_VEHICLE):
        raise ValueError(f"direction must be '>' or '<', not {direction!r}")
    if raw.endswith(b"\r\n") and b"\n" not in raw[:-1]:
        return f"{t:.6f} {direction} {escape(raw[:-2])}"
    return f"{t:.6f} {direction}~ {escape(raw)}"


def parse_record(line: str, lineno: int = 0) -> Optional[WireRecord]:
    """A record from one log line; None for comments and blank lines."""
    line = line.rstrip("\r\n")
    if not line or line.startswith("#"):
        return None
    m = _RECORD_RE.match(line)
    if m is None:
        raise WireLogError(f"line {lineno}: not a wire-log record (want '<seconds> <dir> <payload>')")
    t = float(m.group(1))
    d = m.group(2)
    payload = m.group(3)
    if d == NOTE:
        return WireRecord(t, NOTE, b"", lineno, payload)
    raw = unescape(payload)
    if len(d) == 1:
        raw += b"\r\n"
    return WireRecord(t, d[0], raw, lineno)


def read_records(lines: Iterable[str]) -> Iterator[WireRecord]:
    """Records of a wire log, streaming; raises :class:`WireLogError` naming the bad line."""
    for n, line in enumerate(lines, 1):
        rec = parse_record(line, n)
        if rec is not None:
            yield rec


class WireLogWriter:
    """Appends records to a text file, flushing each one so a crash loses nothing recorded."""

    def __init__(self, stream: IO[str], meta: str = ""):
        self._f = stream
        self._f.write(HEADER + "\n")
        if meta:
            self._f.write(f"# {meta}\n")
        self._f.flush()

    def bytes(self, t: float, direction: str, raw: bytes) -> None:
        self._f.write(format_record(t, direction, raw) + "\n")
        self._f.flush()

    def note(self, t: float, text: str) -> None:
        self._f.write(format_record(t, NOTE, note=text.replace("\n", " ")) + "\n")
        self._f.flush()

    def close(self) -> None:
        self._f.close()
