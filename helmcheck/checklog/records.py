"""What a log reader yields, and what it learns about the log as it reads.

* a record: the :class:`~helmcheck.grammar.wirelog.WireEvent` the observers are fed, or an
  :class:`~helmcheck.grammar.wirelog.Unreadable` line (:data:`Chunk` is either) — the wire log's
  own record types (:mod:`helmcheck.grammar.wirelog`), re-exported here for the socat reader;
* :class:`LogMeta`: what the log says about itself (header, time scale, baud, timestamp unit);
* :func:`header_comment`: a ``#`` header line read into the :class:`LogMeta`.

Shared by the format dispatch (:mod:`.readers`) and the socat reader (:mod:`.socat`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable, Optional

from ..grammar.wirelog import NOTE, UNREADABLE, Record, Unreadable

__all__ = ["Chunk", "Unreadable", "LogMeta", "Progress", "header_comment", "decimals_resolution", "UNREADABLE",
           "NOTE", "HEAD_BYTES"]

#: How much of a file decides its format and timestamp unit (the checker reads as much first).
HEAD_BYTES = 64 * 1024
#: Called with the size of each line read (a progress display).
Progress = Optional[Callable[[int], None]]

#: What a reader yields: a record as the :class:`~helmcheck.grammar.wirelog.WireEvent` the
#: observers are fed (bytes ``>`` to or ``<`` from the vehicle at ``t`` seconds since the log
#: began, or a ``!`` note), or an :class:`~helmcheck.grammar.wirelog.Unreadable` line.
Chunk = Record


@dataclass
class LogMeta:
    """What the log says about itself; filled in as the header is read."""

    format: str = "wirelog"
    time_scale: Optional[float] = None
    baud: Optional[int] = None
    resolution: float = 1e-6  #: finest timestamp step the log can show, seconds
    header: list = None  # type: ignore[assignment]
    #: How the digits after the seconds' dot are read: ``us``, ``ns``, ``ms``, ``decimal``
    #: (a decimal fraction of a second) or ``none`` (whole seconds); None until reading begins.
    time_unit: Optional[str] = None
    time_digits: Optional[int] = None  #: width of the fraction as written (9 for socat 1.7.4)
    time_unit_basis: str = ""  #: the evidence for ``time_unit``, one sentence
    time_unit_ambiguous: bool = False  #: both readings of nine digits fitted the head

    def __post_init__(self) -> None:
        if self.header is None:
            self.header = []


_SCALE = re.compile(r"\btime_scale[ =:]+([0-9.]+(?:[eE][-+]?\d+)?)")
_BAUD = re.compile(r"\bbaud[ =:]+(\d+)")

def header_comment(text: str, meta: LogMeta) -> None:
    if len(meta.header) < 8:
        meta.header.append(text[1:].strip())
    m = _SCALE.search(text)
    if m:
        try:
            v = float(m.group(1))
            if v > 0:
                meta.time_scale = v
        except ValueError:
            pass
    m = _BAUD.search(text)
    if m:
        meta.baud = int(m.group(1))


def decimals_resolution(frac: Optional[bytes]) -> float:
    """The step of a decimal fraction as written: ``b"250"`` is 0.001 s, ``b"500000"`` 0.1 s."""
    if not frac:
        return 1.0
    stripped = frac.rstrip(b"0")
    return 10.0 ** -len(stripped) if stripped else 1.0
