"""The recorder: every event of a live run goes to the wire log and to the judges, identically.

:class:`Recorder` is the one place a live driver reports what crossed the line (bytes each way)
and what it knows besides (notes). Each event is written to the wire log (format 1,
:mod:`helmcheck.grammar.capture`) and then fed to every observer with exactly the time
(rounded to the microsecond the log shows) and the line number it was written with. An offline
check of the same log therefore feeds the observers the very same events, and reaches the same
verdicts (issue "One judge per role").

A record is written and fed inside :func:`helmcheck.signals.deferred`: Ctrl-C or SIGTERM never
leaves one logged but not judged, or judged halfway.

Writes are flushed record by record, so a crash loses nothing recorded; a write that fails
(a full disk) is remembered in :attr:`Recorder.write_error` and the run goes on judging — the
command line reports the lost log loudly at the end.
"""

from __future__ import annotations

from typing import IO, Iterable, Optional

from ..grammar.capture import HEADER, NOTE, format_record
from ..judge.wire import WireEvent
from ..signals import deferred

__all__ = ["Recorder"]


class Recorder:
    """Writes the wire log and feeds the observers (module docstring)."""

    def __init__(self, stream: Optional[IO[str]], meta: Iterable[str] = (), observers: Iterable = (), *,
                 after: Optional[tuple[int, float]] = None):
        """``after=(lines, last_t)``: ``stream`` continues a log that already holds ``lines``
        lines up to time ``last_t`` (a resumed run): no header, numbering and time go on."""
        self._f = stream
        self.observers = list(observers)
        self.lineno = 0
        self.write_error: Optional[str] = None
        self.records = 0
        self._last_t = 0.0
        if after is not None:
            self.lineno, self._last_t = after
            return
        self._write(HEADER)
        for m in meta:
            self._write(f"# {m}".replace("\n", " "))

    def _write(self, text: str) -> int:
        self.lineno += 1
        if self._f is not None and self.write_error is None:
            try:
                self._f.write(text + "\n")
                self._f.flush()
            except OSError as e:
                self.write_error = f"{getattr(e, 'strerror', None) or e}"
        return self.lineno

    @property
    def last_t(self) -> float:
        """The time of the latest record (0 before the first)."""
        return self._last_t

    def _time(self, t: float) -> float:
        t = float(f"{max(t, self._last_t):.6f}")
        self._last_t = t
        return t

    def bytes(self, t: float, direction: str, raw: bytes) -> float:
        """Bytes seen going ``direction`` (``>`` to the vehicle, ``<`` from it) at ``t``;
        returns the time as recorded."""
        if not raw:
            return t
        with deferred():
            t = self._time(t)
            n = self._write(format_record(t, direction, raw))
            self.records += 1
            ev = WireEvent(t, direction, raw, "", n)
            for o in self.observers:
                o.feed(ev)
        return t

    def note(self, t: float, text: str) -> float:
        """A note (``!``) at ``t``; returns the time as recorded."""
        with deferred():
            t = self._time(t)
            text = text.replace("\n", " ").replace("\r", " ")
            n = self._write(format_record(t, NOTE, note=text))
            self.records += 1
            ev = WireEvent(t, NOTE, b"", text, n)
            for o in self.observers:
                o.feed(ev)
        return t

    def close(self) -> None:
        if self._f is not None:
            try:
                self._f.close()
            except OSError as e:
                self.write_error = self.write_error or f"{getattr(e, 'strerror', None) or e}"
            self._f = None
