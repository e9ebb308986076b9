"""The line-fault relay's wire log: what each side was given, as lines, and every fault as a note.

:class:`RelayLog` is written by the relay's thread (:mod:`.relay`, with an impairment stage):
the bytes delivered to each side (``>`` what the vehicle's side got, ``<`` what the backseat's
side got — after the faults, as a receiver there saw them) and the notes (the faults,
:mod:`helmcheck.grammar.faultnote`; the ports unplugged and back). Records are written by the
one wire-log writer (:class:`helmcheck.grammar.wirelog.WireLogWriter`), flushed one by one.

A paced line arrives a byte at a time; the log joins what one direction delivered into one
record per line, at the time its LF was delivered. Bytes with no LF yet are written as a run
(``>~``/``<~``) once that direction has been quiet for :data:`RUN_QUIET_S`, when they reach
:data:`RUN_MAX` bytes, or when the log closes; such a run's time is its last byte's, or the
latest record's if that is later (the log's time never goes back). A lock keeps records whole
when the owner writes a note from another thread.
"""

from __future__ import annotations

import threading
from typing import IO, Iterable, Optional

from ..grammar.wirelog import FROM_VEHICLE, TO_VEHICLE, WireLogWriter

__all__ = ["RelayLog", "RUN_QUIET_S", "RUN_MAX"]

RUN_QUIET_S = 0.1  #: a direction quiet this long has its bytes without LF written as a run
RUN_MAX = 4096  #: bytes without LF written as a run once this many


class RelayLog:
    """The relay's wire log (module docstring); times are seconds since ``t0`` on the relay's clock."""

    def __init__(self, stream: Optional[IO[str]], meta: Iterable[str], t0: float):
        self.t0 = t0
        self._w = WireLogWriter(stream, list(meta))
        self._lock = threading.Lock()
        self._run = {TO_VEHICLE: bytearray(), FROM_VEHICLE: bytearray()}
        self._run_t = {TO_VEHICLE: 0.0, FROM_VEHICLE: 0.0}
        self.notes: list[tuple[float, str]] = []  #: every note written: (relay clock time, text)

    @property
    def write_error(self) -> Optional[str]:
        return self._w.write_error

    def bytes(self, t: float, direction: str, data: bytes) -> None:
        """``data`` delivered going ``direction`` at ``t`` (the relay's clock)."""
        with self._lock:
            run = self._run[direction]
            while data:
                nl = data.find(b"\n")
                piece, data = (data, b"") if nl < 0 else (data[:nl + 1], data[nl + 1:])
                run += piece
                self._run_t[direction] = t
                if nl >= 0 or len(run) >= RUN_MAX:
                    self._write_run(direction)

    def note(self, t: float, text: str) -> None:
        """A note at ``t`` (the relay's clock)."""
        with self._lock:
            self.notes.append((t, text))
            self._w.note(t - self.t0, text)

    def idle(self, now: float) -> None:
        """Write the runs of directions quiet for :data:`RUN_QUIET_S` (called once per relay turn)."""
        if not (self._run[TO_VEHICLE] or self._run[FROM_VEHICLE]):
            return
        with self._lock:
            for d, run in self._run.items():
                if run and now - self._run_t[d] >= RUN_QUIET_S:
                    self._write_run(d)

    def _write_run(self, direction: str) -> None:
        run = self._run[direction]
        self._w.bytes(self._run_t[direction] - self.t0, direction, bytes(run))
        run.clear()

    def close(self) -> None:
        with self._lock:
            for d, run in self._run.items():
                if run:
                    self._write_run(d)
            self._w.close()
