"""What a line-fault relay's notes say the line did, for a judge reading a record that carries them.

``helmcheck relay`` writes every fault it injects to its wire log as a note (``line fault DIR
KIND: DETAIL``, :mod:`helmcheck.grammar.faultnote`), before the record of the line whose byte it
touched (a line's record is written at its LF, the note when the byte was delivered). A judge
reading such a record (``check-log`` of the relay's log) need not guess from a broken line's form
(:mod:`.spoil`): :class:`LineFaults` tells it exactly —

* :meth:`LineFaults.take` — the fault notes of one direction since the last run of bytes framed
  that way: they touched the next run framed (a line, or bytes the framer set aside). Every run
  takes them, clean or not, so a note never reaches past the run it touched;
* :meth:`LineFaults.held_between` — a stall or a cut of the line overlapping a span of time (an
  answer late or lost across it);
* :attr:`LineFaults.instrumented` — the record carries a relay's notes (its start note, or any
  fault note), or states a clean link (:mod:`.linemodel`, :meth:`LineFaults.clean_link`): what no
  note touched, the line did not do (a receiver at another baud, ``reframe``, touches every byte
  of its direction).

In a relay's log the bytes each way are what the *receiver* got: a fault in the direction a
sender sent excuses what that sender's line became, and is exactly what the receiver was given
(and is judged on). Pure: no clock, no I/O.
"""

from __future__ import annotations

import re
from typing import Optional

from ..grammar.faultnote import BOTH, FaultNote
from ..grammar.wirelog import FROM_VEHICLE, TO_VEHICLE

__all__ = ["LineFaults"]

_OVER = re.compile(r"^over after ")


class LineFaults:
    """The relay's notes read so far (module docstring)."""

    def __init__(self):
        self.instrumented = False
        #: the record states a clean link (no relay): nothing on it damages or delays bytes, but
        #: the implementation shares this host's CPU, whose stalls can still make an answer late
        self.clean = False
        self._pending: dict[str, list[str]] = {TO_VEHICLE: [], FROM_VEHICLE: []}
        self._reframed: dict[str, str] = {}
        self._open: dict[tuple[str, str], float] = {}  #: (kind, direction) -> start
        self._windows: list[tuple[float, float, str]] = []  #: (start, end, text), the latest few

    def relay_started(self) -> None:
        self.instrumented = True

    def clean_link(self) -> None:
        """The record states a link that cannot damage bytes (a pty, TCP on this host): nothing
        the line did goes unnoted, because it does nothing (:mod:`.linemodel`)."""
        self.instrumented = True
        self.clean = True

    def note(self, t: float, fault: FaultNote) -> None:
        """A line-fault note at ``t``."""
        self.instrumented = True
        dirs = (TO_VEHICLE, FROM_VEHICLE) if fault.direction == BOTH else (fault.direction,)
        text = fault.text
        if fault.kind in ("flip", "drop", "noise"):
            for d in dirs:
                if len(self._pending[d]) < 16:
                    self._pending[d].append(text)
        elif fault.kind == "reframe":
            for d in dirs:
                self._reframed[d] = text
        elif fault.kind in ("stall", "cut"):
            key = (fault.kind, fault.direction)
            if _OVER.match(fault.detail):
                start = self._open.pop(key, None)
                if start is not None:
                    self._windows.append((start, t, text))
                    del self._windows[:-32]
            else:
                self._open[key] = t
                for d in dirs:  # what is on the line in a cut is lost
                    if fault.kind == "cut" and len(self._pending[d]) < 16:
                        self._pending[d].append(text)

    def take(self, direction: str) -> Optional[str]:
        """The faults that touched the run of bytes now framed going ``direction`` (None: none)."""
        got = self._pending[direction]
        if got:
            self._pending[direction] = []
            return "; ".join(got[:3]) + (f" and {len(got) - 3} more" if len(got) > 3 else "")
        return self._reframed.get(direction)

    def held_between(self, t0: float, t1: float) -> Optional[str]:
        """A stall or cut of the line (either way) overlapping ``[t0, t1]``, as its note says."""
        for (kind, d), start in self._open.items():
            if start <= t1:
                return f"line fault {d} {kind} since {start:.3f} s"
        for start, end, text in reversed(self._windows):
            if start <= t1 and end >= t0:
                return text
        return None
