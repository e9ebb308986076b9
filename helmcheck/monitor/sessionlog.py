"""The session's wire log: every record written and flushed as it comes, rotated by size.

:class:`SessionLog` is the one writer of a monitored session's evidence. The relay thread hands
it each chunk it read (:meth:`SessionLog.bytes`), other threads their notes (:meth:`SessionLog.note`);
a lock keeps the records whole and in order. Each record is written by the one wire-log writer
(:class:`helmcheck.grammar.wirelog.WireLogWriter`) and flushed at once — a monitor killed with
SIGKILL leaves a log intact to its last record, and the judges (:mod:`.live`) follow the file as
it grows — and then handed, exactly as written, to ``on_record`` if one is given.

When the segment being written reaches ``rotate_bytes`` the log goes on in the next file beside
it (``wire.log``, ``wire.001.log``, …; the format's *segments*, :mod:`helmcheck.grammar.wirelog`):
a ``continued in`` note ends the segment, the next begins with the header, numbering and time go
on. ``check-log`` and ``verify`` read the segments as one session. ``on_rotate`` is told each new
segment's name (the session writes its results then too).
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Callable, Iterable, Optional

from ..grammar.wirelog import CONTINUED, WireEvent, WireLogWriter, segment_name

__all__ = ["SessionLog", "ROTATE_BYTES"]

#: Default segment size: a few hours of a busy 115200-baud line per segment.
ROTATE_BYTES = 64 * 1024 * 1024


class SessionLog:
    def __init__(self, directory: Path, meta: Iterable[str], *, on_record: Callable[[WireEvent], None] = lambda ev: None,
                 rotate_bytes: int = ROTATE_BYTES, on_rotate: Optional[Callable[[str], None]] = None,
                 name: str = "wire.log"):
        self.directory = Path(directory)
        self.name = name
        self.rotate_bytes = max(1024, int(rotate_bytes))
        self.on_record = on_record
        self.on_rotate = on_rotate
        self.segments: list[str] = [name]  #: every segment written so far, first to last
        self._lock = threading.Lock()
        self._f = open(self.directory / name, "w", encoding="utf-8")
        self._w = WireLogWriter(self._f, list(meta))
        self.closed = False

    @property
    def write_error(self) -> Optional[str]:
        """Why the log could not be written (None while it can)."""
        return self._w.write_error

    @property
    def records(self) -> int:
        return self._w.records

    @property
    def last_t(self) -> float:
        return self._w.last_t

    def bytes(self, t: float, direction: str, data: bytes) -> None:
        """Bytes seen going ``direction`` at ``t`` (seconds since the session began)."""
        with self._lock:
            if self.closed:
                return
            ev = self._w.bytes(t, direction, data)
            if ev is not None:
                self.on_record(ev)
                self._maybe_rotate()

    def note(self, t: float, text: str) -> None:
        with self._lock:
            if self.closed:
                return
            self.on_record(self._w.note(t, text))
            self._maybe_rotate()

    def _maybe_rotate(self) -> None:
        try:
            size = self._f.tell()
        except (OSError, ValueError):
            return
        if size < self.rotate_bytes:
            return
        nxt = segment_name(self.name, len(self.segments))
        self.on_record(self._w.note(self._w.last_t, CONTINUED + nxt))
        previous = self.segments[-1]
        try:
            new = open(self.directory / nxt, "w", encoding="utf-8")
        except OSError as e:
            self._w.write_error = self._w.write_error or f"cannot open {nxt}: {e.strerror or e}"
            return
        self._f.close()
        self._f = new
        self.segments.append(nxt)
        self._w.continue_in(new, previous)
        if self.on_rotate is not None:
            self.on_rotate(nxt)

    def close(self) -> None:
        with self._lock:
            if not self.closed:
                self.closed = True
                self._w.close()
