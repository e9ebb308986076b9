"""Byte-stream framer: cuts a serial byte stream into lines, sans-IO.

Feed it bytes as they arrive, split anywhere; it returns :class:`Line` events for every line
ended by LF and :class:`Discard` events for every run of bytes it throws away — never silently:

- bytes before a ``$`` (line noise, a torn sentence's tail) — RH-FRM-7;
- a sentence cut short by a new ``$`` before its terminator (never merged) — RH-FRM-7;
- a line longer than the limit (256 bytes with CR LF by default) — RH-FRM-6: it is discarded
  whole, and the framer resynchronises at the next ``$``. Only the first ``max_line`` bytes of
  an overlong run are kept in the event (``length`` says how long it really was), so a flood
  never grows memory;
- bytes still pending at :meth:`Framer.close` — RH-FRM-7.

Every event carries the stream offset of its first byte. Whether a line is a *valid* sentence
is for :func:`helmcheck.grammar.decode`; the framer only finds line boundaries.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Union

__all__ = ["Framer", "Line", "Discard", "FrameEvent"]


@dataclass(frozen=True, slots=True)
class Line:
    """A run from ``$`` to LF inclusive, within the length limit."""

    raw: bytes
    offset: int


@dataclass(frozen=True, slots=True)
class Discard:
    """A run of bytes thrown away, with the clause that says why."""

    raw: bytes  #: the bytes (at most ``max_line`` of them for an overlong run)
    offset: int
    length: int  #: how many bytes were really discarded
    clause: str
    reason: str

    def __str__(self) -> str:
        return f"{self.clause}: discarded {self.length} bytes at offset {self.offset}: {self.reason}"


FrameEvent = Union[Line, Discard]


class Framer:
    """Incremental line framer. ``feed`` and ``close`` return the events now complete."""

    def __init__(self, max_line: int = 256):
        self.max_line = max_line
        self._buf = bytearray()  # bytes of the current run (capped at max_line)
        self._start = 0  # stream offset of the current run
        self._len = 0  # true length of the current run
        self._in_line = False  # current run began with '$'
        self._overlong = False  # current line passed the limit; discarding until '$'
        self._offset = 0  # stream offset of the next byte fed

    def feed(self, data: bytes) -> list[FrameEvent]:
        out: list[FrameEvent] = []
        i, n = 0, len(data)
        while i < n:
            if not self._in_line:
                j = data.find(b"$", i)
                end = n if j < 0 else j
                if end > i:
                    self._take(data[i:end], self._offset + i)
                if j < 0:
                    i = n
                    break
                self._flush_garbage(out)
                self._begin_line(self._offset + j)
                i = j + 1
                self._take(b"$", self._offset + j)
                continue
            # inside a line: look for LF or the next '$'
            lf = data.find(b"\n", i)
            dollar = data.find(b"$", i)
            if dollar >= 0 and (lf < 0 or dollar < lf):
                self._take(data[i:dollar], self._offset + i)
                self._end_torn(out)
                self._begin_line(self._offset + dollar)
                self._take(b"$", self._offset + dollar)
                i = dollar + 1
                continue
            if lf < 0:
                self._take(data[i:], self._offset + i)
                i = n
                break
            self._take(data[i:lf + 1], self._offset + i)
            self._end_line(out)
            i = lf + 1
        self._offset += n
        return out

    def close(self) -> list[FrameEvent]:
        """End of stream: whatever is pending is discarded and reported."""
        out: list[FrameEvent] = []
        if self._len:
            if self._in_line and not self._overlong:
                out.append(self._discard("RH-FRM-7", "stream ended inside a sentence (no terminator)"))
            elif self._in_line:
                out.append(self._discard("RH-FRM-6", f"line longer than {self.max_line} bytes"))
            else:
                out.append(self._discard("RH-FRM-7", "bytes before '$' (noise)"))
        self._reset()
        return out

    @property
    def pending(self) -> int:
        """Bytes held for the current, unfinished run."""
        return self._len

    # ------------------------------------------------------------------ internals
    def _reset(self) -> None:
        self._buf = bytearray()
        self._len = 0
        self._in_line = False
        self._overlong = False

    def _begin_line(self, offset: int) -> None:
        self._reset()
        self._in_line = True
        self._start = offset

    def _take(self, chunk: bytes, at: int) -> None:
        if not chunk:
            return
        if not self._len:
            self._start = at
        room = self.max_line - len(self._buf)
        if room > 0:
            self._buf += chunk[:room]
        self._len += len(chunk)
        if self._in_line and self._len > self.max_line:
            self._overlong = True

    def _discard(self, clause: str, reason: str) -> Discard:
        return Discard(bytes(self._buf), self._start, self._len, clause, reason)

    def _flush_garbage(self, out: list[FrameEvent]) -> None:
        if self._len:
            out.append(self._discard("RH-FRM-7", "bytes before '$' (noise)"))
        self._reset()

    def _end_torn(self, out: list[FrameEvent]) -> None:
        if self._overlong:
            out.append(self._discard("RH-FRM-6", f"line longer than {self.max_line} bytes"))
        else:
            out.append(self._discard("RH-FRM-7", "sentence torn: a new '$' came before its terminator"))
        self._reset()

    def _end_line(self, out: list[FrameEvent]) -> None:
        if self._overlong:
            out.append(self._discard("RH-FRM-6", f"line longer than {self.max_line} bytes"))
        else:
            out.append(Line(bytes(self._buf), self._start))
        self._reset()
