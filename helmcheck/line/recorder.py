"""The recorder: every event of a live run goes to the wire log and to the judges, identically.

:class:`Recorder` is the one place a live driver reports what crossed the line (bytes each way)
and what it knows besides (notes). Each event is written to the wire log by the one wire-log
writer (:class:`helmcheck.grammar.wirelog.WireLogWriter`, format 1) and then fed to every
observer as the :class:`~helmcheck.judge.wire.WireEvent` the writer wrote: exactly the time
(rounded to the microsecond the log shows, never going back) and the line number it was written
with. An offline check of the same log reads the very same events back (the same module's
reader), and reaches the same verdicts (issue "One judge per role").

A record is written and fed inside :func:`helmcheck.signals.deferred`: Ctrl-C or SIGTERM never
leaves one logged but not judged, or judged halfway.

Writes are flushed record by record, so a crash loses nothing recorded; a write that fails
(a full disk) is remembered in :attr:`Recorder.write_error` and the run goes on judging — the
command line reports the lost log loudly at the end.
"""

from __future__ import annotations

from typing import IO, Iterable, Optional

from ..grammar.wirelog import WireLogWriter
from ..signals import deferred

__all__ = ["Recorder"]


class Recorder:
    """Writes the wire log and feeds the observers (module docstring)."""

    def __init__(self, stream: Optional[IO[str]], meta: Iterable[str] = (), observers: Iterable = (), *,
                 after: Optional[tuple[int, float]] = None):
        """``after=(lines, last_t)``: ``stream`` continues a log that already holds ``lines``
        lines up to time ``last_t`` (a resumed run): no header, numbering and time go on."""
        self.log = WireLogWriter(stream, meta, after=after)
        self.observers = list(observers)

    @property
    def lineno(self) -> int:
        """The number of the last line written."""
        return self.log.lineno

    @property
    def records(self) -> int:
        """Records written (notes included)."""
        return self.log.records

    @property
    def write_error(self) -> Optional[str]:
        """Why the wire log could not be written (None while it can)."""
        return self.log.write_error

    @property
    def last_t(self) -> float:
        """The time of the latest record (0 before the first)."""
        return self.log.last_t

    def bytes(self, t: float, direction: str, raw: bytes) -> float:
        """Bytes seen going ``direction`` (``>`` to the vehicle, ``<`` from it) at ``t``;
        returns the time as recorded."""
        if not raw:
            return t
        with deferred():
            ev = self.log.bytes(t, direction, raw)
            for o in self.observers:
                o.feed(ev)
        return ev.t  # type: ignore[union-attr]

    def note(self, t: float, text: str) -> float:
        """A note (``!``) at ``t``; returns the time as recorded."""
        with deferred():
            ev = self.log.note(t, text)
            for o in self.observers:
                o.feed(ev)
        return ev.t

    def close(self) -> None:
        self.log.close()
